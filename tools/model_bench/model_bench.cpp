// model-bench: timings of the closed-chain model over random valid states of the reference machine.
// Targets (2-core development machine, Release build): inverse dynamics <= 2 us, forward dynamics
// <= 4 us. Medians of 10 repetitions:
//   model-bench --benchmark_repetitions=10 --benchmark_report_aggregates_only=true
// Each iteration takes the next of 1024 pre-drawn states, so the branch predictor and the caches see a
// realistic mix rather than one repeated state.
#include <benchmark/benchmark.h>

#include "app/float_environment.hpp"

#include <array>
#include <cstdio>
#include <string_view>
#include <random>
#include <vector>

#include "model/closed_chain.hpp"
#include "model/forward_dynamics.hpp"
#include "model/machine_reader.hpp"

namespace {

struct State {
  exc::Vec4 q_a, qd_a, qdd_a, tau_a;
};

// The reference machine with each closed-chain path: planar (the straight-line pass, now) and general
// (the Lie-group passes it replaced), benchmarked side by side in one run.
struct Fixture {
  exc::Model model = exc::build_model(exc::reference_machine());
  exc::Model general = model;
  std::vector<State> states;
  const exc::Model& with(exc::ClosedChainPath path) const { return path == exc::ClosedChainPath::planar ? model : general; }
  Fixture() {
    general.closed_chain_path = exc::ClosedChainPath::general;
    std::mt19937 rng(1);
    auto u = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
    const exc::Vec4 lo = model.machine.q_min(), hi = model.machine.q_max();
    exc::Workspace ws(model);
    while (states.size() < 1024) {
      State s;
      s.q_a << u(-3.14, 3.14), u(lo[1], hi[1]), u(lo[2], hi[2]), u(lo[3], hi[3]);
      s.qd_a << u(-1, 1), u(-0.3, 0.3), u(-0.4, 0.4), u(-0.5, 0.5);
      s.qdd_a << u(-2, 2), u(-1, 1), u(-1, 1), u(-1, 1);
      if (!exc::update_closed_chain(model, ws, s.q_a, s.qd_a).ok()) continue;
      exc::inverse_dynamics(model, ws, s.qdd_a, exc::Vec2::Zero(), s.tau_a);
      states.push_back(s);
    }
  }
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

// Closed-chain inverse dynamics from the active state: loop closure, Psi, gamma, Newton-Euler, Psi^T.
void BM_InverseDynamics(benchmark::State& st, exc::ClosedChainPath path) {
  Fixture& f = fixture();
  const exc::Model& model = f.with(path);
  exc::Workspace ws(model);
  exc::Vec4 tau;
  std::size_t k = 0;
  for (auto _ : st) {
    const State& s = f.states[k++ & 1023];
    exc::update_closed_chain(model, ws, s.q_a, s.qd_a);
    exc::inverse_dynamics(model, ws, s.qdd_a, exc::Vec2(1e3, -2e3), tau);
    benchmark::DoNotOptimize(tau);
  }
}
BENCHMARK_CAPTURE(BM_InverseDynamics, planar, exc::ClosedChainPath::planar);
BENCHMARK_CAPTURE(BM_InverseDynamics, general, exc::ClosedChainPath::general);

// Forward dynamics in independent coordinates (update, M_a, h_a, 4x4 Cholesky), with soil.
void BM_ForwardDynamics(benchmark::State& st, exc::ClosedChainPath path) {
  Fixture& f = fixture();
  const exc::Model& model = f.with(path);
  exc::Workspace ws(model);
  exc::TipLoad load;
  load.force = exc::Vec2(1e4, -2e4);
  load.added_mass = exc::Vec2(200, 200);
  exc::Vec4 qdd;
  std::size_t k = 0;
  for (auto _ : st) {
    const State& s = f.states[k++ & 1023];
    exc::forward_dynamics(model, ws, s.q_a, s.qd_a, s.tau_a, load, qdd);
    benchmark::DoNotOptimize(qdd);
  }
}
BENCHMARK_CAPTURE(BM_ForwardDynamics, planar, exc::ClosedChainPath::planar);
BENCHMARK_CAPTURE(BM_ForwardDynamics, general, exc::ClosedChainPath::general);

// M_a alone (after update_closed_chain, which is outside the timed region): Psi^T M_r Psi (general),
// or the links' Jacobians and energies (planar).
void BM_MassMatrix(benchmark::State& st, exc::ClosedChainPath path) {
  Fixture& f = fixture();
  const exc::Model& model = f.with(path);
  std::vector<exc::Workspace> ws;
  ws.reserve(64);
  for (int i = 0; i < 64; ++i) {
    ws.emplace_back(model);
    exc::update_closed_chain(model, ws.back(), f.states[i].q_a, f.states[i].qd_a);
  }
  exc::Mat4 M;
  std::size_t k = 0;
  for (auto _ : st) {
    exc::Workspace& w = ws[k++ & 63];
    w.planar.jacobians_valid = false;  // the planar path's links' Jacobians are part of M_a's cost
    exc::mass_matrix(model, w, M);
    benchmark::DoNotOptimize(M);
  }
}
BENCHMARK_CAPTURE(BM_MassMatrix, planar, exc::ClosedChainPath::planar);
BENCHMARK_CAPTURE(BM_MassMatrix, general, exc::ClosedChainPath::general);

// The position/velocity update alone (closed-form closure, H, Psi, gamma, tip, tree kinematics).
void BM_UpdateClosedChain(benchmark::State& st, exc::ClosedChainPath path) {
  Fixture& f = fixture();
  const exc::Model& model = f.with(path);
  exc::Workspace ws(model);
  std::size_t k = 0;
  for (auto _ : st) {
    const State& s = f.states[k++ & 1023];
    benchmark::DoNotOptimize(exc::update_closed_chain(model, ws, s.q_a, s.qd_a));
  }
}
BENCHMARK_CAPTURE(BM_UpdateClosedChain, planar, exc::ClosedChainPath::planar);
BENCHMARK_CAPTURE(BM_UpdateClosedChain, general, exc::ClosedChainPath::general);

// The augmented form (eq. 8, 20x20 LU) for comparison.
void BM_ForwardDynamicsAugmented(benchmark::State& st, exc::ClosedChainPath path) {
  Fixture& f = fixture();
  const exc::Model& model = f.with(path);
  exc::Workspace ws(model);
  std::vector<std::pair<exc::Vec12, exc::Vec12>> tree(64);
  for (int i = 0; i < 64; ++i) {
    exc::update_closed_chain(model, ws, f.states[i].q_a, f.states[i].qd_a);
    tree[i] = {ws.q, ws.qd};
  }
  exc::Vec12 qdd;
  exc::Vec8 lambda;
  std::size_t k = 0;
  for (auto _ : st) {
    const std::size_t i = k++ & 63;
    exc::forward_dynamics_augmented(model, ws, tree[i].first, tree[i].second, f.states[i].tau_a, exc::TipLoad{},
                                    0.0, 0.0, qdd, lambda);
    benchmark::DoNotOptimize(qdd);
  }
}
BENCHMARK_CAPTURE(BM_ForwardDynamicsAugmented, planar, exc::ClosedChainPath::planar);
BENCHMARK_CAPTURE(BM_ForwardDynamicsAugmented, general, exc::ClosedChainPath::general);

}  // namespace

// The model as the loop evaluates it: in the loop's floating-point mode (docs/floating-point.md).
// Google Benchmark's main, but an argument it does not know exits 2 (bad input), as every program's does.
int main(int argc, char** argv) {
  exc::app::set_loop_float_mode();
  // Google Benchmark's --help lists its own flags only: what this program times comes first.
  for (int i = 1; i < argc; ++i)
    if (std::string_view(argv[i]) == "--help")
      std::printf("model-bench: timings of the closed-chain model (inverse and forward dynamics, the augmented form, the\n"
                  "mass matrix, the closed-chain update; planar and general paths) over random\n"
                  "valid states of the reference machine; medians of 10 repetitions:\n"
                  "  model-bench --benchmark_repetitions=10 --benchmark_report_aggregates_only=true\n\n");
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 2;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
