#include <doctest/doctest.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>
#include <time.h>

#include <chrono>
#include <fstream>
#include <string>

#include "allocation_counter.hpp"
#include "app/realtime_setup.hpp"
#include "control/actuator_lag_compensator.hpp"
#include "control/perf_counter.hpp"
#include "control/state_machine.hpp"
#include "scenes.hpp"
#include "tracking_run.hpp"

using namespace exc;
using namespace exc::control;

namespace {

double thread_cpu_us() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e6 + static_cast<double>(ts.tv_nsec) * 1e-3;
}

// The machine's stolen time so far (ms): time the hypervisor ran something else while a guest vCPU
// had work. The kernel charges it to whichever thread was running, so it shows up as step time.
double host_steal_ms() {
  std::ifstream stat("/proc/stat");
  std::string cpu;
  long long v[8] = {};
  stat >> cpu;
  for (long long& x : v) stat >> x;
  return static_cast<double>(v[7]) * 1000.0 / static_cast<double>(sysconf(_SC_CLK_TCK));
}

long involuntary_switches() {
  rusage u{};
  getrusage(RUSAGE_THREAD, &u);
  return u.ru_nivcsw;
}

}  // namespace

TEST_CASE("firmware/zero heap allocations over 100000 control steps (estimator, trajectory, model, controller, lag compensation, plant)") {
  REQUIRE(exc::test::allocation_counting_works());
  const Model model = build_model(reference_machine());
  const Task task = parse_task(YAML::Load(sim::kDigTask)["task"], "dig", model.machine);
  struct Variant {
    ControllerKind kind;
    bool integral_action;
  };
  for (const Variant variant : {Variant{ControllerKind::pid, false}, Variant{ControllerKind::adaptive, false},
                                Variant{ControllerKind::adaptive, true}, Variant{ControllerKind::slotine_li, false}}) {
    const ControllerKind kind = variant.kind;
    ControllerConfig cfg;
    cfg.integral_action = variant.integral_action;
    cfg.actuator_lag = 0.02;  // the lag stage runs as in the dig scene (the model plant itself has no lag)
    auto ctrl = make_controller(kind, model, cfg);
    ActuatorLagCompensator lag(cfg.actuator_lag, cfg.actuator_lag_target, cfg.period, effort_limits_of(model.machine));
    sim::ModelPlant plant(model, sim::SoilTruth{});
    Vec4 q0, qd0, qdd0;
    task.trajectory.evaluate(0, q0, qd0, qdd0);
    plant.reset(q0, qd0);
    StateEstimator est(cfg.filter);
    ControlStateMachine sm(cfg.watchdog_timeout);
    CommandBlender blend(cfg.blend_time);
    PerfCounter perf("control_step", 1000);
    const int steps = kind == ControllerKind::adaptive && !variant.integral_action ? 100000 : 20000;
    std::size_t allocations = 0;
    {
      exc::test::AllocationCounter counter;
      exc::test::EigenNoMallocScope no_eigen_malloc;
      Vec4 last = Vec4::Zero();
      for (int k = 0; k < steps; ++k) {
        // Loop the 10 s dig pass so the run spends time in and out of the soil.
        const double t = (k % 11000) * cfg.period;
        if (k % 11000 == 0) plant.reset(q0, qd0);
        const auto t0 = std::chrono::steady_clock::now();
        StateMachineInputs smi;
        smi.t = k * cfg.period;
        smi.have_valid_frame = true;
        smi.last_valid_frame_time = smi.t;
        smi.track_requested = true;
        const Transition tr = sm.step(smi);
        ControlInput in = sim::estimated_input(est, plant.q(), plant.qd(), task, t);
        const TipLoad load = plant.soil_load();
        in.actuator_limited = lag.clamped();
        const ControlOutput out = ctrl->update(in);
        if (tr.changed) blend.on_switch(smi.t, last, out.tau);
        last = blend.apply(smi.t, out.tau);
        const Vec4 sent = lag.apply(last);
        perf.record_ns(std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - t0).count());
        plant.step(sent, load, cfg.period);
      }
      allocations = counter.count();
    }
    const std::string name = std::string(to_string(kind)) + (variant.integral_action ? " (integral action)" : "");
    MESSAGE(name << ": " << steps << " steps, allocations = " << allocations);
    CHECK(allocations == 0);
    CHECK(perf.count() == static_cast<std::uint64_t>(steps));
  }
}

TEST_CASE("firmware/timing budget of the adaptive control step after real-time preparation: no page fault in the loop, CPU median < 50 us, p99 < 100 us, p99.9 < 500 us, at most 10 of 100000 steps over the 1 ms cycle") {
  const Model model = build_model(reference_machine());
  const Task task = parse_task(YAML::Load(sim::kDigTask)["task"], "dig", model.machine);
  const ControllerConfig cfg;
  AdaptiveComputedTorque ctrl(model, cfg, effort_limits_of(model.machine));
  StateEstimator est(cfg.filter);
  sim::ModelPlant plant(model, sim::SoilTruth{});
  Vec4 q0, qd0, qdd0;
  task.trajectory.evaluate(0, q0, qd0, qdd0);
  plant.reset(q0, qd0);
  // The control step as the firmware runs it: estimator + trajectory + closed-chain model + law.
  PerfCounter wall("control_step_wall", 1000), cpu("control_step_cpu", 1000);
  const auto step = [&](int k, bool measure) {
    const double t = (k % 11000) * cfg.period;
    if (k % 11000 == 0) plant.reset(q0, qd0);
    const TipLoad load = plant.soil_load();
    const Vec4 q = plant.q(), qd = plant.qd();
    const double c0 = thread_cpu_us();
    const auto t0 = std::chrono::steady_clock::now();
    const ControlInput in = sim::estimated_input(est, q, qd, task, t);
    const ControlOutput out = ctrl.update(in);
    const auto t1 = std::chrono::steady_clock::now();
    const double c1 = thread_cpu_us();
    if (measure) {
      wall.record_ns(std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count());
      cpu.record_us(c1 - c0);
    }
    plant.step(out.tau, load, cfg.period);
  };
  // As real firmware starts: one whole dig pass unmeasured (first touch of every buffer and code
  // path, lazy symbol binding of libm and the clock calls), then memory locked and a stack reserve
  // touched, so the measured loop takes no page fault at all.
  for (int k = 0; k < 11000; ++k) step(k, false);
  const app::RealtimeSetup rt = app::prepare_realtime(app::RealtimeRequest{});
  if (!rt.warnings.empty()) MESSAGE("real-time preparation: " << rt.warnings);
  const long faults_before = app::thread_page_faults();
  const long switches_before = involuntary_switches();
  const double steal_before = host_steal_ms();
  for (int k = 0; k < 100000; ++k) step(k, true);
  const long faults = app::thread_page_faults() - faults_before;
  const long switches = involuntary_switches() - switches_before;
  const double steal = host_steal_ms() - steal_before;
  if (rt.memory_locked) munlockall();

  MESSAGE("control step thread CPU: median " << cpu.median_us() << " us, p99 " << cpu.p99_us() << " us, p99.9 "
                                             << cpu.percentile_us(0.999) << " us, max " << cpu.max_us()
                                             << " us, over 1 ms: " << cpu.overruns());
  MESSAGE("control step wall clock: median " << wall.median_us() << " us, p99 " << wall.p99_us() << " us, p99.9 "
                                             << wall.percentile_us(0.999) << " us, max " << wall.max_us()
                                             << " us, over 1 ms: " << wall.overruns() << "; page faults in the loop: "
                                             << faults << std::string(rt.memory_locked ? " (memory locked)" : " (memory not locked)")
                                             << "; preempted " << switches << " times; host steal " << steal << " ms");
  REQUIRE(cpu.count() == 100000);
  // A page fault in the real-time path is a defect of the path (memory touched for the first time
  // or not locked), whatever the machine's load: counted, not timed.
  if (rt.memory_locked) CHECK(faults == 0);
  // Budgets a loaded 2-core machine keeps (steps take ~4 us). The single maximum is reported, not
  // asserted: on a virtual machine an interrupt or a stolen host slice is charged to whichever
  // thread was running, up to a millisecond, and no user-space measure removes that.
  CHECK(wall.median_us() < 50);
  CHECK(cpu.median_us() < 50);
  CHECK(cpu.p99_us() < 100);
  CHECK(cpu.percentile_us(0.999) < 500);
  CHECK(cpu.overruns() <= 10);
}
