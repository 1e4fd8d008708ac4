#include "pressure_integration.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <limits>
#include <stdexcept>

#include "app/firmware_node.hpp"
#include "bench_common.hpp"
#include "harness/lockstep_run.hpp"
#include "output_files/output_file.hpp"
#include "sim_plant/plant.hpp"

namespace exc::bench {

namespace {

using Pressures = std::array<double, 8>;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// What the plant node hands the hydraulic plant for a command set (the firmware's safe state sends
// valve openings, centred).
plant::ActuatorCommand plant_command(const hal::CommandState& c) {
  plant::ActuatorCommand a;
  a.mode = c.mode == hal::CommandMode::pilot ? plant::ActuatorCommand::pilot : plant::ActuatorCommand::valve;
  for (int j = 0; j < 4; ++j) {
    a.value[j] = c.mode == hal::CommandMode::effort ? 0.0 : c.value[j];
    a.pilot_a[j] = c.pilot_a[j];
    a.pilot_b[j] = c.pilot_b[j];
  }
  return a;
}

struct Replay {
  bool ok = true;
  std::string failure;
  double failed_at = 0, simulated = 0, cpu_seconds = 0, iterations = 0, cavitation = 0;
  std::vector<Vec3> tip;  // every kProfileHold, the first at the start
  std::vector<Pressures> pressure;
};

// The hydraulic plant driven by the input at this substep and pressure method (the cycle is 1 ms, or
// the substep above it).
Replay replay(const ValveInput& in, plant::PressureMethod m, double step) {
  plant::Scene scene = in.scene;
  scene.cycle = std::max(step, 1e-3);
  scene.integrator.step = step;
  scene.integrator.pressure_method = m;
  plant::Plant plant(scene);
  const auto per_hold = static_cast<std::size_t>(std::lround(kProfileHold / scene.cycle));
  Replay r;
  r.tip.reserve(in.commands.size() + 1);
  r.pressure.reserve(in.commands.size() + 1);
  auto sample = [&r, &plant]() {
    const plant::PlantState& st = plant.state();
    r.tip.push_back(st.tip_world);
    Pressures p;
    for (int i = 0; i < 4; ++i) {
      p[i] = st.pressure_a[i];
      p[4 + i] = st.pressure_b[i];
    }
    r.pressure.push_back(p);
  };
  sample();
  double iterations = 0;
  const double cpu0 = thread_cpu_seconds();
  for (std::size_t k = 0; k < in.commands.size() * per_hold; ++k) {
    const plant::PlantStatus& st = plant.step(in.commands[k / per_hold]);
    if (!st.ok()) {
      r.ok = false;
      r.failure = st.text();
      r.failed_at = st.time;
      break;
    }
    iterations += plant.state().hydraulics.solver_iterations;  // the cycle's last substep
    if ((k + 1) % per_hold == 0) sample();
  }
  r.cpu_seconds = thread_cpu_seconds() - cpu0;
  r.simulated = plant.state().time;
  r.iterations = iterations / std::max(1.0, std::round(r.simulated / scene.cycle));
  r.cavitation = static_cast<double>(plant.state().hydraulics.cavitation_substeps) * step;
  return r;
}

double pressure_rms(const std::vector<Pressures>& a, const std::vector<Pressures>& b) {
  const std::size_t n = std::min(a.size(), b.size());
  double sum = 0;
  for (std::size_t k = 0; k < n; ++k)
    for (int i = 0; i < 8; ++i) sum += (a[k][i] - b[k][i]) * (a[k][i] - b[k][i]);
  return n > 0 ? std::sqrt(sum / (8.0 * static_cast<double>(n))) : kNaN;
}

}  // namespace

ValveInput recorded_dig(const BenchScene& dig, double duration) {
  if (!plant::fidelity_of(dig.scene.actuators).has(plant::kHydraulicCircuit))
    throw std::invalid_argument(dig.name + ": the pressure-integration chart needs a hydraulic scene");
  const app::FirmwareSettings fw = bench_firmware(dig, dig.scene);
  sim::LockstepOptions o;
  o.duration = duration;
  const auto n = static_cast<std::size_t>(std::llround(duration / dig.scene.cycle));
  std::vector<plant::ActuatorCommand> cycles;
  cycles.reserve(n + 1);
  // The plant steps before the firmware's first command (centred valves); each later step takes the
  // command of the cycle before it.
  cycles.push_back(plant_command(hal::CommandState{}));
  o.observer = [&cycles](std::int64_t, const plant::Plant&, const app::FirmwareNode& node) {
    if (cycles.size() < cycles.capacity()) cycles.push_back(plant_command(node.last_command()));
  };
  const sim::RunRecord run = sim::run_lockstep(dig.scene, fw, o);
  if (cycles.size() < n)
    throw std::runtime_error(dig.name + ": the closed-loop dig that records the commands stopped: " + run.failure);
  ValveInput in;
  in.name = dig.name + " (recorded)";
  in.scene = dig.scene;
  const auto per_hold = static_cast<std::size_t>(std::lround(kProfileHold / dig.scene.cycle));
  for (std::size_t k = per_hold / 2; k < n; k += per_hold) in.commands.push_back(cycles[k]);
  return in;
}

ValveInput four_functions(const BenchScene& dig, double duration) {
  ValveInput in;
  in.name = "four functions";
  in.scene = dig.scene;
  in.scene.q_a0 = Vec4(0.0, 2.4626, 2.3231, 2.1447);  // the machine's first reference pose
  in.scene.qd_a0.setZero();
  in.scene.terrain = Terrain{};
  in.scene.terrain.height = -5;  // in the air: the hydraulics alone
  const auto n = static_cast<std::size_t>(std::lround(duration / kProfileHold));
  for (std::size_t k = 0; k < n; ++k) {
    const double t = (static_cast<double>(k) + 0.5) * kProfileHold;
    plant::ActuatorCommand c;
    c.mode = plant::ActuatorCommand::valve;
    c.value = Vec4(0.6 * std::sin(2.0 * t), 0.8 * std::sin(1.3 * t + 0.5), -0.7 * std::sin(1.7 * t),
                   0.9 * std::sin(2.3 * t + 1.0));
    in.commands.push_back(c);
  }
  return in;
}

PressureChart pressure_integration(const std::vector<ValveInput>& inputs, const std::vector<double>& steps,
                                   double reference_step) {
  PressureChart chart;
  chart.reference_step = reference_step;
  const std::string fe = plant::to_string(plant::PressureMethod::forward_euler);
  for (const ValveInput& in : inputs) {
    const std::size_t first = chart.points.size();
    progress("pressure integration %s: reference (backward Euler at %s)\n", in.name, step_label(reference_step));
    const Replay ref = replay(in, plant::PressureMethod::backward_euler, reference_step);
    if (!ref.ok) throw std::runtime_error("the pressure-integration reference of " + in.name + " failed: " + ref.failure);
    auto run = [&](plant::PressureMethod m, double h) {
      const Replay r = replay(in, m, h);
      PressurePoint p;
      p.input = in.name;
      p.method = plant::to_string(m);
      p.step = h;
      p.ok = r.ok;
      p.failure = r.failure;
      p.failed_at = r.failed_at;
      p.cpu_per_s = r.simulated > 0 ? r.cpu_seconds / r.simulated : kNaN;
      p.tip_rms = r.ok ? rms_distance(r.tip, ref.tip) : kNaN;
      p.pressure_rms = r.ok ? pressure_rms(r.pressure, ref.pressure) : kNaN;
      p.iterations = r.iterations;
      p.cavitation = r.cavitation;
      chart.points.push_back(p);
      return p.ok;
    };
    for (const auto& [m, name, what] : plant::kPressureMethods.entries) {
      progress("pressure integration %s: %s\n", in.name, name);
      for (double h : steps) run(m, h);
    }
    // The explicit method's boundary: between the smallest listed substep it failed at and the
    // largest it passed below that, every 1 ms / n in between (below 1 ms; the listed ones above).
    ExplicitBoundary b;
    b.input = in.name;
    for (const PressurePoint& p : chart.points)
      if (p.input == in.name && p.method == fe && !p.ok && (b.failing == 0 || p.step < b.failing)) b.failing = p.step;
    for (const PressurePoint& p : chart.points)
      if (p.input == in.name && p.method == fe && p.ok && (b.failing == 0 || p.step < b.failing) && p.step > b.stable)
        b.stable = p.step;
    if (b.failing > 0 && b.stable > 0 && b.failing <= 1e-3) {
      const long n_fail = std::lround(1e-3 / b.failing), n_pass = std::lround(1e-3 / b.stable);
      for (long n = n_fail + 1; n < n_pass; ++n) {
        progress("pressure integration %s: forward_euler at %s (boundary)\n", in.name, step_label(1e-3 / n));
        if (run(plant::PressureMethod::forward_euler, 1e-3 / n)) {
          b.stable = 1e-3 / n;
          break;
        }
        b.failing = 1e-3 / n;
      }
    }
    for (const PressurePoint& p : chart.points)
      if (p.input == in.name && p.method == fe && p.step == b.failing) b.failure = p.failure;
    chart.boundaries.push_back(b);
    std::sort(chart.points.begin() + static_cast<long>(first), chart.points.end(),
              [](const PressurePoint& x, const PressurePoint& y) {
                return x.method != y.method ? x.method < y.method : x.step > y.step;
              });
  }
  return chart;
}

void write_pressure_csv(const std::string& path, const PressureChart& chart) {
  std::ofstream f = output::open_file(path);
  f << "input,method,step_s,ok,cpu_s_per_sim_s,tip_rms_m,pressure_rms_Pa,iterations_per_substep,cavitation_s,"
       "failed_at_s,failure\n";
  f.precision(6);
  for (const PressurePoint& p : chart.points) {
    std::string failure = p.failure;
    std::replace(failure.begin(), failure.end(), ',', ';');
    std::replace(failure.begin(), failure.end(), '"', '\'');
    f << p.input << ',' << p.method << ',' << p.step << ',' << (p.ok ? 1 : 0) << ',' << p.cpu_per_s << ','
      << p.tip_rms << ',' << p.pressure_rms << ',' << p.iterations << ',' << p.cavitation << ',' << p.failed_at
      << ",\"" << failure << "\"\n";
  }
  output::finish_file(f, path);
}

}  // namespace exc::bench
