#include "in_process_run.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <stdexcept>

#include <unistd.h>

#include "allocation_counter.hpp"
#include "app/firmware_node.hpp"
#include "app/tracking_metrics.hpp"
#include "hal/memory_bus.hpp"
#include "model/model.hpp"
#include "plant_node.hpp"
#include "sim_plant/plant.hpp"
#include "telemetry/lcm_output.hpp"
#include "telemetry/telemetry_publisher.hpp"

namespace exc::sim {
namespace {

control::ControllerKind parse_kind(const std::string& name) {
  if (name == "pid") return control::ControllerKind::pid;
  if (name == "adaptive") return control::ControllerKind::adaptive;
  if (name == "slotine_li") return control::ControllerKind::slotine_li;
  throw std::invalid_argument("--controller: unknown controller '" + name +
                              "' (allowed: pid, adaptive, slotine_li)");
}

// The bus is stamped with simulated time, so the codec's timing rules never see wall-clock jitter.
struct SimClock {
  std::int64_t now_ns = 0;
  static std::int64_t read(void* self) { return static_cast<SimClock*>(self)->now_ns; }
};

Timing timing_of(const control::PerfCounter& c) {
  return Timing{c.median_us(), c.p99_us(), c.max_us(), c.count()};
}

Vec6 theta_of(const plant::SoilParameters& s) {
  Vec6 t;
  t << s.mass[0], s.damping[0], s.stiffness[0], s.mass[1], s.damping[1], s.stiffness[1];
  return t;
}

RunResult run_one(const SceneBundle& bundle, control::ControllerKind kind, const RunOptions& options,
                  const std::shared_ptr<telemetry::LcmOutput>& output) {
  RunResult result;
  result.controller = control::to_string(kind);

  plant::Plant plant(bundle.scene);
  SimClock clock;
  hal::MemoryBusHub hub(&SimClock::read, &clock);
  hal::MemoryBusNode* firmware_bus = hub.attach();
  hal::MemoryBusNode* plant_bus = hub.attach();
  hal::FirmwareCanPort firmware_port(*firmware_bus);
  hal::PlantCanPort plant_port(*plant_bus);

  std::unique_ptr<telemetry::TelemetryPublisher> publisher;
  if (output) {
    telemetry::TelemetryConfig tc;
    tc.shared_output = output;
    tc.channel_suffix = "/" + result.controller;
    publisher = std::make_unique<telemetry::TelemetryPublisher>(tc);
    std::string error;
    if (!publisher->start(&error)) throw std::runtime_error("telemetry: " + error);
  }

  app::FirmwareNodeConfig fc;
  fc.kind = kind;
  fc.controller = bundle.controller;
  fc.terrain_height = bundle.scene.terrain.height;
  fc.theta_known = true;
  fc.theta_true = theta_of(bundle.scene.soil);
  // The controller's own model: the plant's, or one with wrong masses for the robustness runs.
  std::unique_ptr<Model> wrong_model;
  if (options.controller_mass_scale != 1.0) {
    Machine m = plant.model().machine;
    for (BodyInertia& b : m.bodies) {
      b.mass *= options.controller_mass_scale;
      b.inertia *= options.controller_mass_scale;
    }
    wrong_model = std::make_unique<Model>(build_model(m));
  }
  app::FirmwareNode firmware(wrong_model ? *wrong_model : plant.model(), bundle.task, fc, firmware_port,
                             publisher.get());
  app::PlantNode plant_node(plant, plant_port, publisher.get());

  const double duration = options.duration_override > 0 ? options.duration_override : bundle.scene.duration;
  const auto cycles = static_cast<std::int64_t>(std::llround(duration / bundle.scene.cycle));
  const auto period_ns = static_cast<std::int64_t>(std::llround(bundle.scene.cycle * 1e9));
  TrackingMetrics metrics;
  const auto wall_start = std::chrono::steady_clock::now();
  const std::int64_t progress_every = std::max<std::int64_t>(1, cycles / 10);
  const bool interactive = isatty(STDERR_FILENO) != 0;
  std::uint64_t allocations = 0;
  {
    // Counted from the first cycle on: everything before is start-up. The telemetry thread's own
    // allocations (LCM) are on another thread and not counted.
    test::AllocationCounter counter;
    for (std::int64_t k = 0; k < cycles; ++k) {
      clock.now_ns = k * period_ns;
      firmware.begin_cycle();
      plant_node.poll();
      firmware.end_cycle();
      if (firmware.tracking()) metrics.add(plant.state().q_a, firmware.q_desired());
      const plant::PlantState& s = plant.state();
      result.peak_soil_force = std::max(result.peak_soil_force, s.soil_force.norm());
      if (plant_node.failed()) break;
      if (options.progress && (k + 1) % progress_every == 0) {
        // On a terminal the line is redrawn in place; in a log, one line per tenth of the run.
        std::fprintf(stderr, interactive ? "\r  %-10s %5.1f / %.1f s simulated" : "  %-10s %5.1f / %.1f s simulated\n",
                     result.controller.c_str(), s.time, duration);
        std::fflush(stderr);
      }
    }
    allocations = counter.count();
  }
  if (options.progress && interactive) std::fprintf(stderr, "\n");
  firmware.publish_counters();
  plant_node.publish_counters();
  if (publisher) publisher->stop();

  result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  result.simulated_seconds = plant.state().time;
  for (int j = 0; j < 4; ++j) {
    result.rms_error[j] = metrics.rms(j);
    result.max_error[j] = metrics.max_abs(j);
    result.measured_rms_error[j] = firmware.measured_tracking().rms(j);
    result.measured_max_error[j] = firmware.measured_tracking().max_abs(j);
  }
  const Vec6 truth = theta_of(bundle.scene.soil);
  for (int i = 0; i < 6; ++i) {
    result.theta_hat[i] = firmware.last_output().theta_hat[i];
    result.theta_true[i] = truth[i];
  }
  result.reanchor_count = plant.state().reanchor_count;
  result.control_step = timing_of(firmware.control_timing());
  result.firmware_cycle = timing_of(firmware.cycle_timing());
  result.heap_allocations_in_loop = allocations;
  result.safe_stops = firmware.safe_stops();
  result.rx_rejected = firmware_port.rx_stats().rejected() + plant_port.rx_stats().rejected();
  if (plant_node.failed()) {
    result.ok = false;
    result.failure = std::string("plant stopped: ") + plant.status().text();
  } else if (metrics.samples() == 0) {
    result.ok = false;
    result.failure = std::string("the firmware never tracked (mode ") + control::to_string(firmware.mode()) + ")";
  } else if (firmware.safe_stops() > 0) {
    result.ok = false;
    result.failure = "the firmware went to its safe state " + std::to_string(firmware.safe_stops()) + " time(s)";
  }
  return result;
}

// The run's setup as a person reads it: actuators (and their lag), the firmware's compensation of it,
// the integrator.
std::string describe_setup(const SceneBundle& bundle) {
  const plant::Scene& sc = bundle.scene;
  std::ostringstream o;
  o << "actuators " << plant::to_string(sc.actuators.fidelity);
  if (sc.actuators.fidelity == plant::ActuatorFidelity::limited) o << " (effort lag " << sc.actuators.lag * 1e3 << " ms)";
  o << ", firmware lag compensation ";
  if (bundle.controller.actuator_lag > 0)
    o << bundle.controller.actuator_lag * 1e3 << " ms -> " << bundle.controller.actuator_lag_target * 1e3 << " ms";
  else
    o << "off";
  o << "; integrator " << plant::to_string(sc.integrator.method) << " / " << plant::to_string(sc.integrator.formulation)
    << " at " << sc.integrator.step * 1e3 << " ms";
  return o.str();
}

}  // namespace

SceneBundle load_scene_bundle(const std::string& path) {
  SceneBundle b;
  b.scene = plant::load_scene(path);
  if (!b.scene.has_task) throw std::runtime_error(path + ": field 'task' is missing: the firmware needs a task");
  b.task = control::load_task(path, b.scene.machine);
  b.controller = control::load_controller_config(path);
  b.name = b.scene.name;
  return b;
}

Summary run_all(const SceneBundle& bundle, const RunOptions& options) {
  Summary summary;
  summary.scene = bundle.name;
  summary.setup = describe_setup(bundle);
  std::shared_ptr<telemetry::LcmOutput> output;
  if (!options.lcm_url.empty()) {
    std::string error;
    output = telemetry::LcmOutput::open(options.lcm_url, &error);
    if (!output) throw std::runtime_error("--lcm: " + error);
  }
  for (const std::string& name : options.controllers) {
    const control::ControllerKind kind = parse_kind(name);
    if (options.progress) std::fprintf(stderr, "excavator-sim: %s with %s\n", bundle.name.c_str(), name.c_str());
    summary.runs.push_back(run_one(bundle, kind, options, output));
    summary.all_ok = summary.all_ok && summary.runs.back().ok;
  }
  return summary;
}

}  // namespace exc::sim
