#include "model_evaluations.hpp"

#include <limits>
#include <random>
#include <stdexcept>

#include "model/closed_chain.hpp"

namespace exc::bench {
namespace {

double evaluations(const Model& model, ClosedChainPath path, Workspace& ws, const std::vector<ActiveState>& states,
                   PassiveAngles angles) {
  if (model.closed_chain_path != path) throw std::logic_error("model evaluations: the model takes the other path");
  Mat4 M;
  Vec4 h;
  double sum = 0;
  for (const ActiveState& s : states) {
    if (!update_closed_chain(model, ws, s.q_a, s.qd_a, angles).ok()) return std::numeric_limits<double>::quiet_NaN();
    mass_matrix(model, ws, M);
    bias_forces(model, ws, h);
    sum += M(1, 1) + h[1];
  }
  return sum;
}

}  // namespace

std::vector<ActiveState> random_valid_states(const Model& model, std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  auto u = [&rng](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
  const Vec4 lo = model.machine.q_min(), hi = model.machine.q_max();
  Workspace ws(model);
  std::vector<ActiveState> states;
  states.reserve(n);
  while (states.size() < n) {
    ActiveState s;
    s.q_a[0] = u(-3.14, 3.14);
    for (int k = 1; k < 4; ++k) s.q_a[k] = u(lo[k] + 0.05 * (hi[k] - lo[k]), hi[k] - 0.05 * (hi[k] - lo[k]));
    s.qd_a << u(-1, 1), u(-0.5, 0.5), u(-0.5, 0.5), u(-0.5, 0.5);
    if (update_closed_chain(model, ws, s.q_a, s.qd_a).ok()) states.push_back(s);
  }
  return states;
}

__attribute__((noinline)) double firmware_evaluations_planar(const Model& model, Workspace& ws,
                                                             const std::vector<ActiveState>& states) {
  return evaluations(model, ClosedChainPath::planar, ws, states, PassiveAngles::skipped);
}
__attribute__((noinline)) double firmware_evaluations_general(const Model& model, Workspace& ws,
                                                              const std::vector<ActiveState>& states) {
  return evaluations(model, ClosedChainPath::general, ws, states, PassiveAngles::skipped);
}
__attribute__((noinline)) double plant_evaluations_planar(const Model& model, Workspace& ws,
                                                          const std::vector<ActiveState>& states) {
  return evaluations(model, ClosedChainPath::planar, ws, states, PassiveAngles::computed);
}
__attribute__((noinline)) double plant_evaluations_general(const Model& model, Workspace& ws,
                                                           const std::vector<ActiveState>& states) {
  return evaluations(model, ClosedChainPath::general, ws, states, PassiveAngles::computed);
}

}  // namespace exc::bench
