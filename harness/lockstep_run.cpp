#include "harness/lockstep_run.hpp"

#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "app/allocation_counter.hpp"
#include "app/firmware_node.hpp"
#include "harness/firmware_end.hpp"
#include "harness/target_firmware.hpp"
#include "app/tracking_metrics.hpp"
#include "hal/fault_injecting_bus.hpp"
#include "hal/memory_bus.hpp"
#include "settings/section_reader.hpp"
#include "sim_plant/plant.hpp"
#include "sim_plant/plant_node.hpp"
#include "telemetry/lcm_output.hpp"
#include "telemetry/telemetry_publisher.hpp"

namespace exc::sim {
namespace {

// The bus is stamped with simulated time, so the codec's timing rules never see wall-clock jitter.
struct SimClock {
  std::int64_t now_ns = 0;
  static std::int64_t read(void* self) { return static_cast<SimClock*>(self)->now_ns; }
};

Timing timing_of(const control::PerfCounter& c) { return Timing{c.median_us(), c.p99_us(), c.max_us(), c.count()}; }

// The timing of the samples `after` recorded since it was `before` (a copy of the same counter taken
// earlier), from the histograms: the upper edge of the bucket that holds the fraction.
Timing timing_between(const control::PerfCounter& before, const control::PerfCounter& after) {
  std::array<std::uint64_t, control::PerfCounter::kBuckets> h{};
  Timing t;
  int last = -1;
  for (int b = 0; b < control::PerfCounter::kBuckets; ++b) {
    h[static_cast<std::size_t>(b)] = after.histogram()[static_cast<std::size_t>(b)] - before.histogram()[static_cast<std::size_t>(b)];
    t.count += h[static_cast<std::size_t>(b)];
    if (h[static_cast<std::size_t>(b)] > 0) last = b;
  }
  if (t.count == 0) return t;
  auto percentile = [&](double fraction) {
    const double target = fraction * static_cast<double>(t.count);
    std::uint64_t seen = 0;
    for (int b = 0; b <= last; ++b) {
      seen += h[static_cast<std::size_t>(b)];
      if (static_cast<double>(seen) >= target && seen > 0) return control::PerfCounter::upper_edge_us(b);
    }
    return control::PerfCounter::upper_edge_us(last);
  };
  t.median_us = percentile(0.5);
  t.p99_us = percentile(0.99);
  t.max_us = control::PerfCounter::upper_edge_us(last);
  return t;
}

Vec6 theta_of(const plant::SoilParameters& s) {
  Vec6 t;
  t << s.mass[0], s.damping[0], s.stiffness[0], s.mass[1], s.damping[1], s.stiffness[1];
  return t;
}

double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// The bus of one node end: frames go out through a fault injector while a burst is on.
class BurstBus final : public hal::CanBus {
 public:
  BurstBus(hal::CanBus& inner, const hal::FaultInjection& faults) : inner_(inner), faulty_(inner, faults) {}
  bool send(const hal::CanFrame& frame) override { return on_ ? faulty_.send(frame) : inner_.send(frame); }
  bool receive(hal::CanFrame& frame) override { return inner_.receive(frame); }
  bool wait_readable(std::int64_t timeout_ns) override { return inner_.wait_readable(timeout_ns); }
  void set(bool on) {
    if (on_ && !on) faulty_.release_delayed();
    on_ = on;
  }

 private:
  hal::CanBus& inner_;
  hal::FaultInjectingBus faulty_;
  bool on_ = false;
};

app::InjectedFault plant_fault_of(const FaultSchedule& f) {
  app::InjectedFault p;
  p.joint = f.joint;
  p.magnitude = f.magnitude;
  p.chamber = f.chamber;
  switch (f.kind) {
    case FaultSchedule::Kind::sensor_freeze: p.kind = app::InjectedFault::Kind::sensor_freeze; break;
    case FaultSchedule::Kind::sensor_jump: p.kind = app::InjectedFault::Kind::sensor_jump; break;
    case FaultSchedule::Kind::actuator_loss: p.kind = app::InjectedFault::Kind::actuator_loss; break;
    case FaultSchedule::Kind::actuator_jam: p.kind = app::InjectedFault::Kind::actuator_jam; break;
    case FaultSchedule::Kind::spool_stuck: p.kind = app::InjectedFault::Kind::valve_stuck; break;
    case FaultSchedule::Kind::machine_fault: p.kind = app::InjectedFault::Kind::machine_fault; break;
    case FaultSchedule::Kind::pressure_stuck: p.kind = app::InjectedFault::Kind::pressure_stuck; break;
    case FaultSchedule::Kind::pressure_jump: p.kind = app::InjectedFault::Kind::pressure_jump; break;
    case FaultSchedule::Kind::pressure_drift: p.kind = app::InjectedFault::Kind::pressure_drift; break;
    default: break;
  }
  return p;
}

}  // namespace

std::string fault_misfit(FaultSchedule::Kind kind, const plant::Scene& scene) {
  const bool needs_hydraulics = kind == FaultSchedule::Kind::pump_loss || kind == FaultSchedule::Kind::spool_stuck ||
                                kind == FaultSchedule::Kind::pressure_stuck || kind == FaultSchedule::Kind::pressure_jump ||
                                kind == FaultSchedule::Kind::pressure_drift;
  if (!needs_hydraulics || plant::fidelity_of(scene.actuators).has(plant::kHydraulicCircuit)) return "";
  return std::string(to_string(kind)) + " needs the hydraulic machine; " + scene.file + " has actuators " +
         scene.actuators.fidelity;
}

std::int64_t lockstep_cycles(const plant::Scene& scene, double duration) {
  return static_cast<std::int64_t>(std::llround((duration > 0 ? duration : scene.duration) / scene.cycle));
}

app::FirmwareImageSettings lockstep_image_settings(const plant::Scene& scene, const app::FirmwareSettings& firmware,
                                                   const LockstepOptions& options) {
  app::FirmwareNodeConfig fc;
  fc.controller = firmware.controller;
  fc.controller.law = options.controller;
  fc.site_map = firmware.terrain;
  fc.theta_known = true;  // simulation: the true soil goes into telemetry and the Lyapunov value
  fc.theta_true = theta_of(scene.soil);
  fc.wait_for_start = options.wait_for_start;
  return app::image_settings(firmware, fc, options.duration > 0 ? options.duration : scene.duration);
}

RunRecord run_lockstep(const plant::Scene& scene, const app::FirmwareSettings& firmware, const LockstepOptions& options) {
  return run_lockstep(scene, lockstep_image_settings(scene, firmware, options), options);
}

RunRecord run_lockstep(const plant::Scene& scene, const app::FirmwareImageSettings& firmware, const LockstepOptions& options) {
  RunRecord result;
  result.controller = firmware.node.controller.law;
  // This thread runs the loop and starts the telemetry thread: subnormals flushed from here on, the
  // caller's mode back at the end (docs/floating-point.md).
  const app::LoopFloatModeScope float_mode(options.float_mode);

  plant::Plant plant(scene);
  SimClock clock;
  hal::MemoryBusHub hub(&SimClock::read, &clock);
  hal::MemoryBusNode* firmware_bus = hub.attach();
  hal::MemoryBusNode* plant_bus = hub.attach();
  // Both ends' frames pass through a burst injector (idle unless the fault schedule says so).
  hal::FaultInjection burst;
  const double share = options.fault.kind == FaultSchedule::Kind::bus_burst ? options.fault.magnitude / 3 : 0;
  burst.drop_fraction = burst.corrupt_fraction = burst.delay_fraction = share;
  burst.seed = options.fault.seed;
  BurstBus firmware_end(*firmware_bus, burst);
  burst.seed = options.fault.seed + 1;
  BurstBus plant_end(*plant_bus, burst);
  hal::FirmwareCanPort firmware_port(firmware_end);
  hal::PlantCanPort plant_port(plant_end);
  // The operator station is outside the burst: its frames are what the fault campaign never damages.
  // An operator_stop fault is the operator station's stop frame at the fault's start; an
  // operator_link_lost fault its keep-alives every 0.1 s up to the fault's start, then silence.
  std::vector<SupervisorFrameAt> supervisor = options.supervisor;
  if (options.fault.kind == FaultSchedule::Kind::operator_stop)
    supervisor.push_back({options.fault.start, hal::SupervisorCommand::stop});
  if (options.fault.kind == FaultSchedule::Kind::operator_link_lost) {
    // Counted, not compared: 0.1 * 30 is above 3.0, and a start on the grid keeps its own frame.
    const int last = static_cast<int>(std::floor(options.fault.start / 0.1 + 1e-9));
    for (int k = 1; k <= last; ++k) supervisor.push_back({0.1 * k, hal::SupervisorCommand::none});
  }
  std::stable_sort(supervisor.begin(), supervisor.end(), [](const SupervisorFrameAt& a, const SupervisorFrameAt& b) { return a.time < b.time; });
  hal::MemoryBusNode* operator_bus = supervisor.empty() ? nullptr : hub.attach();
  hal::OperatorCanPort operator_port(operator_bus != nullptr ? *operator_bus : *firmware_bus);
  std::size_t next_supervisor = 0;

  std::unique_ptr<telemetry::TelemetryPublisher> publisher;
  if (options.telemetry) {
    telemetry::TelemetryConfig tc;
    tc.shared_output = options.telemetry;
    tc.channel_suffix = "/" + result.controller;
    tc.overflow = telemetry::OverflowPolicy::block;  // no deadline here: every message is recorded
    tc.per_cycle_every = options.log_every;
    result.telemetry_per_cycle_every = options.log_every;
    publisher = std::make_unique<telemetry::TelemetryPublisher>(tc);
    std::string error;
    if (!publisher->start(&error)) throw std::runtime_error("telemetry: " + error);
  }

  const double duration = options.duration > 0 ? options.duration : scene.duration;
  const std::int64_t cycles = lockstep_cycles(scene, options.duration);
  const Model firmware_model = build_model(firmware.machine);
  std::unique_ptr<FirmwareEnd> firmware_end_node;
  if (options.firmware_target.empty()) {
    firmware_end_node = std::make_unique<HostFirmware>(
        std::make_unique<app::FirmwareNode>(firmware_model, firmware.task, firmware.node, firmware_port, publisher.get()));
  } else {
    if (options.observer || options.node_observer)
      throw std::invalid_argument("a run on " + options.firmware_target + " takes no observer of the in-process node");
    const std::string image = options.firmware_image.empty() ? firmware_target_image(options.firmware_target) : options.firmware_image;
    if (image.empty())
      throw std::invalid_argument("--firmware-target " + options.firmware_target +
                                  ": this build made no firmware image (the test build makes it; another build with "
                                  "-DEXC_TARGET_IMAGES=ON, after tools/install-deps test; or set EXC_FIRMWARE_IMAGE)");
    firmware_end_node = std::make_unique<TargetFirmware>(image, firmware, firmware_end, publisher.get());
  }
  FirmwareEnd& fw = *firmware_end_node;
  const app::FirmwareNode* const host_node = fw.node();  // null on a target
  app::PlantNode plant_node(plant, plant_port, publisher.get());

  const auto period_ns = static_cast<std::int64_t>(std::llround(scene.cycle * 1e9));
  TrackingMetrics metrics;
  app::RunPhases phases;  // tracking, settle, hold, stop: on the plant's truth
  const auto wall_start = std::chrono::steady_clock::now();
  const std::int64_t progress_every = std::max<std::int64_t>(1, cycles / 10);
  const bool interactive = isatty(STDERR_FILENO) != 0;
  std::uint64_t allocations = 0;
  // Per work cycle: sized before the loop, so the loop allocates nothing.
  const std::vector<double>& starts = firmware.task.cycle_starts;
  std::vector<CycleRecord> cycles_acc(std::max<std::size_t>(1, starts.size()));
  std::vector<std::array<double, 4>> cycle_sum_sq(cycles_acc.size(), std::array<double, 4>{});
  const bool hydraulic = plant.fidelity().has(plant::kHydraulicCircuit);
  result.hydraulic = hydraulic;
  if (const std::string why = fault_misfit(options.fault.kind, scene); !why.empty())
    throw std::invalid_argument("fault: " + why);
  if (hydraulic) result.min_pressure = result.peak_pressure = plant.state().hydraulics.min_pressure;
  // The first and the last simulated second: counter copies at their edges (the loop's own copies, no
  // allocation). The last second is left empty when the run stops before it begins.
  const std::int64_t per_second = std::max<std::int64_t>(1, std::llround(1.0 / scene.cycle));
  const std::int64_t first_end = std::min(cycles, per_second), last_begin = std::max<std::int64_t>(0, cycles - per_second);
  const control::PerfCounter empty_counter;
  control::PerfCounter control_first_end, plant_first_end, control_last_begin, plant_last_begin;
  bool first_taken = false, last_taken = false;
  std::int64_t cycles_run = 0;
  // The stop's judge records the plant's truth from the fault's start (its ring reserved here).
  std::optional<StopJudge> judge;
  if (options.fault.kind != FaultSchedule::Kind::none) judge.emplace(scene.machine, options.fault.start, scene.cycle);
  const double cpu_start = thread_cpu_seconds();
  {
    // Counted from the first cycle on: everything before is start-up. The telemetry thread's own
    // allocations (LCM) are on another thread and not counted.
    app::AllocationCounter counter;
    const FaultSchedule& fault = options.fault;
    bool fault_on = false;
    // The machine's truth: the last cycle any function moved faster than "at rest" (docs/safety.md).
    double last_moving = -1;
    bool moving_now = false;
    // A stopped run may run on past the scene's end, to see the machine come to rest (rest_horizon).
    const std::int64_t horizon_cycles = options.rest_horizon > 0 ? static_cast<std::int64_t>(std::ceil(options.rest_horizon / scene.cycle)) : 0;
    for (std::int64_t k = 0; k < cycles + horizon_cycles; ++k) {
      if (k >= cycles) {
        const double now_s = static_cast<double>(k) * scene.cycle;
        if (result.first_safe_stop_time < 0 || now_s >= result.first_safe_stop_time + options.rest_horizon) break;
        // At rest for kRestSettle, and a judged stop's drift fit covered (kStopJudgeSpan from the
        // onset, at the earliest the fault's start or 0.1 s before its detection).
        const double onset = result.first_safe_stop_time >= 0 ? std::max(fault.start, result.first_fault_detected_time - 0.1) : fault.start;
        const bool judged = !judge || now_s >= onset + kStopJudgeSpan + scene.cycle;
        if (!moving_now && now_s - std::max(last_moving, 0.0) >= kRestSettle && judged) break;
      }
      clock.now_ns = k * period_ns;
      const double now = static_cast<double>(k) * scene.cycle;
      const bool want_fault = fault.kind != FaultSchedule::Kind::none && now >= fault.start && now < fault.start + fault.duration;
      if (want_fault != fault_on) {
        fault_on = want_fault;
        firmware_end.set(fault_on && fault.kind == FaultSchedule::Kind::bus_burst);
        plant_end.set(fault_on && fault.kind == FaultSchedule::Kind::bus_burst);
        plant_node.set_fault(fault_on ? plant_fault_of(fault) : app::InjectedFault{});
        if (fault.kind == FaultSchedule::Kind::rock) plant.set_soil_stiffness_scale(fault_on ? fault.magnitude : 1.0);
        if (fault.kind == FaultSchedule::Kind::pump_loss) plant.set_pump_flow_scale(fault_on ? 1 - fault.magnitude : 1.0);
      }
      if (k == last_begin && host_node != nullptr) {
        control_last_begin = host_node->control_timing();
        plant_last_begin = plant_node.step_timing();
        last_taken = true;
      }
      while (next_supervisor < supervisor.size() && supervisor[next_supervisor].time <= now + 1e-9) {
        if (!operator_port.send(supervisor[next_supervisor].command))
          throw std::runtime_error("lockstep: the operator station's SUPERVISOR frame did not go out");
        ++next_supervisor;
      }
      fw.begin_cycle();
      if (!plant_node.poll()) plant_node.coast();  // a SYNC lost in a burst: the machine moves on
      fw.end_cycle();
      const app::CycleStatus& st = fw.status();
      const Vec4 q_desired(st.q_desired[0], st.q_desired[1], st.q_desired[2], st.q_desired[3]);
      cycles_run = k + 1;
      if (cycles_run == first_end && host_node != nullptr) {
        control_first_end = host_node->control_timing();
        plant_first_end = plant_node.step_timing();
        first_taken = true;
      }
      const plant::PlantState& s = plant.state();
      moving_now = std::abs(s.qd_a[0]) >= kRestSwingRate;
      for (int j = 1; j < 4; ++j) moving_now = moving_now || std::abs(s.qd_a[j]) >= kRestCylinderRate;
      if (moving_now) last_moving = s.time;
      if (judge) judge->record(s.time, s.q_a, s.qd_a, hydraulic && s.hydraulics.swing_brake_applied);
      result.peak_soil_force = std::max(result.peak_soil_force, s.soil_force.norm());
      if (hydraulic) {
        result.peak_pressure = std::max(result.peak_pressure, s.hydraulics.max_pressure);
        result.min_pressure = std::min(result.min_pressure, s.hydraulics.min_pressure);
      }
      const auto mode = static_cast<safety::Mode>(st.mode);
      phases.add(s.time, scene.cycle, mode, st.tracking, s.q_a, q_desired);
      if (st.tracking) {
        metrics.add(s.q_a, q_desired);
        const double tt = st.task_time;
        const std::size_t c = starts.empty() ? 0
            : static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, std::upper_bound(starts.begin(), starts.end(), tt) - starts.begin() - 1));
        CycleRecord& rec = cycles_acc[c];
        if (rec.samples == 0) rec.start = s.time;
        rec.end = s.time;
        ++rec.samples;
        for (int j = 0; j < 4; ++j) {
          const double e = s.q_a[j] - q_desired[j];
          cycle_sum_sq[c][j] += e * e;
          rec.max_error[j] = std::max(rec.max_error[j], std::abs(e));
        }
        rec.peak_soil_force = std::max(rec.peak_soil_force, s.soil_force.norm());
        for (int i = 0; i < 6; ++i) rec.theta_hat[i] = st.theta_hat[i];
      }
      if (result.first_safe_stop_time < 0 && st.safe_stops > 0) {
        // The firmware's clock (the schedule's): the plant's lags it by every SYNC a burst dropped.
        result.first_safe_stop_time = static_cast<double>(st.cycle) * scene.cycle;
        result.first_fault_detected_time = st.fault_detected_time;
        result.first_fault_code = st.last_fault;
      }
      if (options.observer) options.observer(k, plant, *host_node);
      if (options.node_observer) options.node_observer(k, plant_node, *host_node);
      if (plant_node.failed()) break;
      if (options.stop_at_safe_state && st.safe_stops > 0) break;
      if (options.interrupt != nullptr && options.interrupt->load(std::memory_order_relaxed) != 0) {
        result.interrupted = true;
        break;
      }
      if (options.progress && (k + 1) % progress_every == 0) {
        // On a terminal the line is redrawn in place; in a log, one line per tenth of the run.
        std::fprintf(stderr, interactive ? "\r  %-10s %5.1f / %.1f s simulated" : "  %-10s %5.1f / %.1f s simulated\n",
                     result.controller.c_str(), s.time, duration);
        std::fflush(stderr);
      }
    }
    allocations = counter.count();
    // At rest from the first sample after the last that moved; never, if the last one moved.
    if (!moving_now) result.machine_at_rest_time = last_moving < 0 ? 0.0 : last_moving + scene.cycle;
  }
  result.cpu_seconds = thread_cpu_seconds() - cpu_start;
  if (options.progress && interactive) std::fprintf(stderr, "\n");
  const app::RunSummaryRecord outcome = fw.finish();
  const app::CycleStatus& last = fw.status();
  result.estop = outcome.emergency_sent;
  if (judge && result.first_safe_stop_time >= 0) {
    // The emergency stop's figures (the solenoids' closing, the brake) for a fault that takes it at
    // once; a controlled stop escalated later is judged as the controlled stop it began as.
    const bool emergency = safety::stop_of(static_cast<safety::FirmwareFault>(result.first_fault_code)) == safety::StopKind::emergency;
    result.stop_judgement = judge->judge(result.first_fault_detected_time, result.first_safe_stop_time, scene.cycle, emergency);
    if (!result.stop_judgement->judged) result.stop_judgement.reset();
  }
  plant_node.publish_counters();
  if (publisher) {
    publisher->stop();
    const telemetry::TelemetryCounters c = publisher->counters();
    result.telemetry_enqueued = c.enqueued;
    result.telemetry_published = c.published;
    result.telemetry_dropped = c.dropped_full_total + c.dropped_overflow + c.dropped_too_large;
    result.telemetry_ring_high_water = c.ring_high_water;
  }

  result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  result.simulated_seconds = plant.state().time;
  result.tracking_samples = metrics.samples();
  for (int j = 0; j < 4; ++j) {
    result.rms_error[j] = metrics.rms(j);
    result.max_error[j] = metrics.max_abs(j);
    result.measured_rms_error[j] = outcome.measured_rms[j];
    result.measured_max_error[j] = outcome.measured_max[j];
  }
  result.tracking = phases.tracking();
  result.settle = phases.settle();
  result.hold = phases.hold();
  result.stop = phases.stop();
  const Vec6 truth = theta_of(scene.soil);
  for (int i = 0; i < 6; ++i) {
    result.theta_hat[i] = last.theta_hat[i];
    result.theta_true[i] = truth[i];
  }
  result.reanchor_count = plant.state().reanchor_count;
  const control::PerfCounter control_timing = host_node != nullptr ? host_node->control_timing() : empty_counter;
  result.control_step = timing_of(control_timing);
  if (!first_taken) {
    control_first_end = control_timing;
    plant_first_end = plant_node.step_timing();
  }
  const double period = scene.cycle;
  result.first_second = TimingWindow{0, static_cast<double>(std::min(cycles_run, first_end)) * period,
                                     timing_between(empty_counter, control_first_end),
                                     timing_between(empty_counter, plant_first_end)};
  if (last_taken)
    result.last_second = TimingWindow{static_cast<double>(last_begin) * period, static_cast<double>(cycles_run) * period,
                                      timing_between(control_last_begin, control_timing),
                                      timing_between(plant_last_begin, plant_node.step_timing())};
  result.firmware_cycle = host_node != nullptr ? timing_of(host_node->cycle_timing()) : Timing{};
  result.target = fw.target_figures();
  result.heap_allocations_in_loop = result.target ? result.target->heap_calls_after_start_up : allocations;
  result.safe_stops = last.safe_stops;
  result.rx_rejected = (host_node != nullptr ? firmware_port.rx_stats().rejected() : outcome.rx_rejected) + plant_port.rx_stats().rejected();
  for (std::size_t c = 0; c < cycles_acc.size(); ++c) {
    CycleRecord& rec = cycles_acc[c];
    for (int j = 0; j < 4; ++j)
      rec.rms_error[j] = rec.samples ? std::sqrt(cycle_sum_sq[c][j] / static_cast<double>(rec.samples)) : 0;
    if (rec.samples > 0) result.cycles.push_back(rec);
  }
  if (hydraulic) {
    const plant::HydraulicReport& h = plant.state().hydraulics;
    const double step = scene.integrator.step;
    result.flow_saturated_seconds = static_cast<double>(h.saturated_substeps) * step;
    result.relief_seconds = static_cast<double>(h.relief_substeps) * step;
    result.cavitation_seconds = static_cast<double>(h.cavitation_substeps) * step;
    result.pump_limited_cycles = outcome.pump_limited_cycles;
  }
  result.task_finished = outcome.trajectory_finished;
  result.task_finish_time = outcome.finish_time;
  const char* const mode = safety::to_string(static_cast<safety::Mode>(outcome.mode));
  if (result.interrupted) {
    result.ok = false;
    char text[96];
    std::snprintf(text, sizeof text, "interrupted (SIGINT) at %.3f s of %.3f s", result.simulated_seconds,
                  static_cast<double>(cycles) * scene.cycle);
    result.failure = text;
  } else if (plant_node.failed()) {
    result.ok = false;
    result.failure = std::string("plant stopped: ") + plant.status().text();
  } else if (last.safe_stops > 0) {
    result.ok = false;
    result.failure = "the firmware went to its safe state " + std::to_string(last.safe_stops) + " time(s), the last for " +
                     outcome.last_fault_text + " (mode " + mode + " at the end)";
  } else if (metrics.samples() == 0) {
    result.ok = false;
    result.failure = std::string("the firmware never tracked (mode ") + mode + ")";
  } else {
    // The hold is part of the task: a machine told to hold still that moves past the holding
    // tolerance failed it, however well it tracked.
    result.failure = app::hold_failure(result.hold);
    result.ok = result.failure.empty();
  }
  return result;
}

}  // namespace exc::sim
