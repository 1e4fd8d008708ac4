#include "bench_runs.hpp"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "app/firmware_node.hpp"
#include "harness/lockstep_run.hpp"
#include "model/closed_chain.hpp"
#include "sim_plant/plant.hpp"
#include "sweep/sweep_knobs.hpp"

namespace exc::bench {

double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// How many plant cycles make one profile hold (both are multiples of the step).
int cycles_per_hold(double cycle) { return static_cast<int>(std::lround(kProfileHold / cycle)); }

}  // namespace

BenchScene load_bench_scene(const std::string& path, double start, double horizon) {
  // One reading of the file: the plant's sections and the firmware's (its task and controller).
  return bench_scene(sim::load_scene_bundle(path), start, horizon);
}

BenchScene bench_scene(const sim::SceneBundle& bundle, double start, double horizon) {
  BenchScene b;
  b.scene = bundle.scene;
  b.task = bundle.firmware.task;
  b.controller = bundle.firmware.controller;
  b.name = b.scene.name;
  b.start = start;
  b.horizon = horizon;
  return b;
}

EffortProfile effort_profile(const BenchScene& s, double speed) {
  const Model model = build_model(s.scene.machine);
  Workspace ws(model);
  EffortProfile p;
  Vec4 q, qd, qdd;
  s.task.trajectory.evaluate(s.task.start_time() + s.start, q, qd, qdd);
  p.q_a0 = q;
  p.qd_a0 = qd * speed;
  const int n = static_cast<int>(std::lround(s.horizon / kProfileHold));
  for (int k = 0; k < n; ++k) {
    // The effort of the interval is the feed-forward at its midpoint (a fair zero-order hold).
    s.task.trajectory.evaluate(s.task.start_time() + s.start + speed * (k + 0.5) * kProfileHold, q, qd, qdd);
    qd *= speed;
    qdd *= speed * speed;
    const ModelReport r = update_closed_chain(model, ws, q, qd);
    if (!r.ok()) throw std::runtime_error(s.name + ": the task's trajectory leaves the mechanism's assembly");
    Vec4 tau;
    inverse_dynamics(model, ws, qdd, Vec2::Zero(), tau);
    p.tau.push_back(tau);
  }
  return p;
}

OpenLoopResult run_open_loop(const BenchScene& s, const EffortProfile& profile, const OpenLoopSettings& settings,
                             bool record_states) {
  plant::Scene scene = s.scene;
  scene.integrator = settings.integrator;
  const double h = settings.integrator.step;
  scene.cycle = sim::open_loop_cycle(h);
  scene.q_a0 = profile.q_a0;
  scene.qd_a0 = profile.qd_a0;
  scene.checks.constraint_tolerance = settings.constraint_tolerance;
  if (!settings.plant_energy_check) {
    scene.checks.energy_tolerance = 1e12;
    scene.checks.energy_relative_tolerance = 1e6;
  }
  scene.actuators.fidelity = "ideal";
  scene.sensors.position_noise.setZero();
  scene.sensors.velocity_noise.setZero();
  plant::Plant plant(scene);

  OpenLoopResult r;
  const int per_hold = cycles_per_hold(scene.cycle);
  if (per_hold < 1)  // a step longer than the hold would skip efforts (and take no step at all)
    throw std::invalid_argument("excavator-bench: step " + std::to_string(h) + " s is longer than the effort profile's hold of " +
                                std::to_string(kProfileHold) + " s");
  r.tip.reserve(profile.tau.size() + 1);
  r.tip.push_back(plant.state().tip_world);
  if (record_states) {
    r.q.push_back(plant.state().q);
    r.qd.push_back(plant.state().qd);
  }
  std::vector<double> step_us;
  step_us.reserve(profile.tau.size());
  plant::ActuatorCommand command;
  command.mode = plant::ActuatorCommand::effort;
  const double cpu0 = thread_cpu_seconds();
  for (std::size_t k = 0; k < profile.tau.size() && r.ok; ++k) {
    command.value = profile.tau[k];
    // Timed per hold interval in thread CPU time: other processes on the machine do not count.
    const double block0 = thread_cpu_seconds();
    int stepped = 0;
    for (int c = 0; c < per_hold; ++c) {
      const plant::PlantStatus st = plant.step(command);
      ++stepped;
      if (!st.ok()) {
        r.ok = false;
        r.failure = st.text();
        break;
      }
      r.max_constraint_residual = std::max(r.max_constraint_residual, plant.state().constraint_residual);
      r.max_energy_error = std::max(r.max_energy_error, std::abs(plant.state().energy_error));
    }
    if (step_us.size() < step_us.capacity() && r.ok)
      step_us.push_back(1e6 * (thread_cpu_seconds() - block0) / stepped);
    if (!r.ok) break;
    r.tip.push_back(plant.state().tip_world);
    r.effort.push_back(plant.state().effort);
    if (record_states) {
      r.q.push_back(plant.state().q);
      r.qd.push_back(plant.state().qd);
    }
  }
  r.cpu_seconds = thread_cpu_seconds() - cpu0;
  r.simulated = plant.state().time;
  r.step_median_us = median(step_us);
  return r;
}

double rms_distance(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  const std::size_t n = std::min(a.size(), b.size());
  if (n == 0) return std::numeric_limits<double>::infinity();
  double sum = 0;
  for (std::size_t i = 0; i < n; ++i) sum += (a[i] - b[i]).squaredNorm();
  return std::sqrt(sum / static_cast<double>(n));
}

namespace {

constexpr std::array<int, 6> kCylinderBodies = {kBoomBarrel, kBoomRod, kArmBarrel, kArmRod, kBucketBarrel, kBucketRod};

}  // namespace

void configure_for_fidelity(control::ControllerConfig& c, const plant::ActuatorParameters& actuators, const Machine& nominal) {
  const plant::ActuatorFidelityEntry& fidelity = plant::fidelity_of(actuators);
  control::set_command_interface(c, fidelity.takes_valves() ? control::CommandInterface::valve
                                                            : control::CommandInterface::effort, nominal);
  c.actuation.actuator_lag = fidelity.effort_lag ? fidelity.effort_lag(actuators) : 0.0;
  if (c.actuation.actuator_lag > 0) c.actuation.actuator_lag_target = std::clamp(c.actuation.actuator_lag_target, c.actuation.actuator_lag / 20, c.actuation.actuator_lag);
}

app::FirmwareSettings bench_firmware(const BenchScene& s, const plant::Scene& scene) {
  app::FirmwareSettings fw;
  fw.name = s.name;
  fw.machine = s.scene.machine;  // the firmware's model: the full machine
  fw.task = s.task;
  fw.terrain = scene.terrain;
  fw.duration = scene.duration;
  fw.controller = s.controller;
  // The firmware as it is set up for the machine it drives: valves for the hydraulic machine, efforts
  // (with the lag compensated) for the force-commanded ones.
  configure_for_fidelity(fw.controller, scene.actuators, fw.machine);
  return fw;
}

ClosedLoopResult run_closed_loop(const BenchScene& s, const ClosedLoopVariant& v) {
  plant::Scene scene = s.scene;
  scene.actuators.fidelity = v.fidelity;
  if (!v.soil) {
    scene.soil = plant::SoilParameters{};
    scene.soil_preset = plant::SoilPreset::none;
  }
  if (!v.dry_friction_and_leakage) scene.machine.hydraulics = without_dry_friction_and_leakage(scene.machine.hydraulics);
  if (v.massless_cylinders)
    for (int k : kCylinderBodies) {
      scene.machine.bodies[k].mass *= 1e-3;
      scene.machine.bodies[k].inertia *= 1e-3;
    }
  // The chart compares models of the machine, not sensors: no position noise, no latency.
  scene.sensors.position_noise.setZero();
  scene.sensors.latency_cycles = 0;
  // The dig scene's file leaves the initial state to the task: start where the task starts.
  Vec4 q0, qd0, qdd0;
  s.task.trajectory.evaluate(s.task.start_time(), q0, qd0, qdd0);
  scene.q_a0 = q0;
  scene.qd_a0 = qd0;

  const app::FirmwareSettings fw = bench_firmware(s, scene);

  ClosedLoopResult r;
  const int per_hold = cycles_per_hold(scene.cycle);
  sim::LockstepOptions o;
  o.controller = v.controller;
  o.duration = v.duration;
  o.stop_at_safe_state = true;
  const double duration = v.duration > 0 ? v.duration : scene.duration;
  r.tip.reserve(static_cast<std::size_t>(std::llround(duration / kProfileHold)) + 1);
  r.effort.reserve(r.tip.capacity());
  o.observer = [&r, per_hold](std::int64_t k, const plant::Plant& plant, const app::FirmwareNode&) {
    if ((k + 1) % per_hold == 0) {
      r.tip.push_back(plant.state().tip_world);
      r.effort.push_back(plant.state().effort);
    }
  };
  const sim::RunRecord run = sim::run_lockstep(scene, fw, o);
  r.ok = run.ok;
  r.failure = run.failure;
  r.cpu_seconds = run.cpu_seconds;
  r.simulated = run.simulated_seconds;
  for (int j = 0; j < 4; ++j) {
    r.tracking_rms[j] = run.rms_error[j];
    r.tracking_max = std::max(r.tracking_max, run.max_error[j]);
  }
  return r;
}

}  // namespace exc::bench
