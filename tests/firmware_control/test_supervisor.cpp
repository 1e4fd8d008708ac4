// The supervisor on its own: no bus, no node, no plant. Each case feeds it cycle inputs as the node
// would and checks what it asks of the state machine and of the bus (stop frames, events).
#include <doctest/doctest.h>

#include <cstring>
#include <string>

#include "model/machine_reader.hpp"
#include "safety/supervisor.hpp"

using namespace exc;
using namespace exc::safety;

namespace {

constexpr double kPeriod = 1e-3;

std::uint8_t bit(hal::SupervisorCommand c) { return static_cast<std::uint8_t>(1u << static_cast<unsigned>(c)); }

// A supervisor and a clock: cycle k at t = k x period, a mode the test sets.
struct Bench {
  explicit Bench(SupervisorSettings s = SupervisorSettings{}) : supervisor(reference_machine(), s, 1e-3) {}
  CycleInputs next(Mode m, bool complete = true) {
    ++cycle;
    mode = m;
    return CycleInputs{static_cast<double>(cycle) * kPeriod, cycle, complete, m};
  }
  // One read phase with these SUPERVISOR bits and sensors; returns whether a stop along the path began.
  bool read(Mode m, std::uint8_t pending = 0, bool path_moving = false, const hal::SensorState& s = hal::SensorState{}) {
    const CycleInputs in = next(m);
    const bool begin = supervisor.take_operator(in, pending, path_moving);
    supervisor.take_signals(in, s, path_moving || begin);  // a stop begun now moves the path
    return begin;
  }
  // The state machine's step into the safe state, as the node reports it.
  Supervisor::StopAction enter(Mode to, Mode from) {
    const CycleInputs in{static_cast<double>(cycle) * kPeriod, cycle, true, from};
    return supervisor.on_transition(Transition{true, from, to, "test"}, in, in.t);
  }
  Supervisor supervisor;
  std::uint64_t cycle = 0;
  Mode mode = Mode::init;
};

std::string text_of(const Supervisor& s) { return s.last_fault_text(); }

}  // namespace

TEST_CASE("firmware/supervisor: the first fault of a cycle is latched with its text and detection time when the safe state begins") {
  Bench b;
  b.read(Mode::track);
  const Vec4 e(0, 0.5, 0, 0);  // the boom 0.5 m off: over any limit
  b.supervisor.check_law(b.cycle * kPeriod, true, e, false);
  CHECK(b.supervisor.fault_pending());
  b.supervisor.check_law(b.cycle * kPeriod, false, Vec4::Zero(), false);  // a second fault the same cycle
  const double raised = b.cycle * kPeriod;
  b.read(Mode::track);
  CHECK(b.enter(Mode::safe_stop, Mode::track) == Supervisor::StopAction::send_stop);
  CHECK(b.supervisor.last_fault() == FirmwareFault::tracking_error);
  CHECK(b.supervisor.fault_detected_time() == doctest::Approx(raised));
  CHECK(text_of(b.supervisor).find("tracking error: boom 0.5000 m > limit 0.2000") == 0);
  CHECK(b.supervisor.safe_stops() == 1);
  // A tracking error takes the controlled stop: FW_EMERGENCY without EmergencyStop.
  const StopFrame f = b.supervisor.stop_frame();
  CHECK_FALSE(f.emergency);
  CHECK(f.code == FirmwareFault::tracking_error);
  CHECK_FALSE(b.supervisor.emergency_sent());
}

TEST_CASE("firmware/supervisor: an acknowledge clears the latched fault only in the safe state and not beside a stop frame") {
  Bench b;
  b.read(Mode::track);
  b.supervisor.check_law(b.cycle * kPeriod, false, Vec4::Zero(), false);
  b.enter(Mode::safe_stop, Mode::track);
  // Acknowledged with a stop in the same frame set: the stop stands.
  b.read(Mode::safe_stop, bit(hal::SupervisorCommand::acknowledge) | bit(hal::SupervisorCommand::stop));
  CHECK_FALSE(b.supervisor.acknowledged());
  CHECK(b.supervisor.fault_pending());
  b.read(Mode::safe_stop, bit(hal::SupervisorCommand::acknowledge));
  CHECK(b.supervisor.acknowledged());
  CHECK_FALSE(b.supervisor.fault_pending());
  CHECK(b.enter(Mode::hold, Mode::safe_stop) == Supervisor::StopAction::release);
  // In hold an acknowledge is spent and means nothing.
  b.supervisor.acknowledge();
  b.read(Mode::hold);
  CHECK_FALSE(b.supervisor.acknowledged());
}

TEST_CASE("firmware/supervisor: an operator's stop decelerates a tracking machine along its path and latches once the path is at rest") {
  Bench b;
  b.read(Mode::track);
  const double frame_time = (b.cycle + 1) * kPeriod;
  CHECK(b.read(Mode::track, bit(hal::SupervisorCommand::stop), false));  // a stop along the path begins
  CHECK_FALSE(b.supervisor.fault_pending());  // the path moves: not yet
  for (int k = 0; k < 300; ++k) CHECK_FALSE(b.read(Mode::track, 0, true));
  CHECK_FALSE(b.supervisor.fault_pending());
  b.read(Mode::track, 0, false);  // the path came to rest
  CHECK(b.supervisor.fault_pending());
  b.enter(Mode::safe_stop, Mode::track);
  CHECK(b.supervisor.last_fault() == FirmwareFault::operator_stop);
  CHECK(b.supervisor.fault_detected_time() == doctest::Approx(frame_time));  // when the frame came
  CHECK(text_of(b.supervisor).find("operator stop: SUPERVISOR stop in track") == 0);
  // Held, not tracking: the stop latches in the cycle its frame arrives, no path to slow.
  Bench h;
  h.read(Mode::hold);
  CHECK_FALSE(h.read(Mode::hold, bit(hal::SupervisorCommand::stop)));
  CHECK(h.supervisor.fault_pending());
}

TEST_CASE("firmware/supervisor: the operator link is armed by a keep-alive and lost after its timeout of silence") {
  SupervisorSettings s;
  s.supervisor_timeout = 0.05;
  Bench b(s);
  // Never heard: silence is no fault.
  for (int k = 0; k < 200; ++k) b.read(Mode::hold);
  CHECK_FALSE(b.supervisor.fault_pending());
  b.read(Mode::hold, bit(hal::SupervisorCommand::none));
  for (int k = 0; k < 50; ++k) b.read(Mode::hold);  // 50 ms: at the timeout, not past it
  CHECK_FALSE(b.supervisor.fault_pending());
  b.read(Mode::hold);
  CHECK(b.supervisor.fault_pending());
  b.enter(Mode::safe_stop, Mode::hold);
  CHECK(b.supervisor.last_fault() == FirmwareFault::operator_link_lost);
  CHECK(text_of(b.supervisor).find("operator link lost: no SUPERVISOR frame for 0.050 s") == 0);
}

TEST_CASE("firmware/supervisor: the machine's own signals raise their faults, a holding machine only after five sets") {
  hal::SensorState s;
  Bench e;
  s.plant_emergency = true;
  s.plant_fault_code = 7;
  e.read(Mode::track, 0, false, s);
  e.enter(Mode::safe_stop, Mode::track);
  CHECK(e.supervisor.last_fault() == FirmwareFault::plant_emergency);
  CHECK(e.supervisor.last_stop() == StopKind::emergency);

  Bench f;
  s = hal::SensorState{};
  s.plant_faults = 0x04;
  {
    const CycleInputs in = f.next(Mode::track, false);  // an incomplete set: its PlantFaults are not read
    f.supervisor.take_operator(in, 0, false);
    f.supervisor.take_signals(in, s, false);
  }
  CHECK_FALSE(f.supervisor.fault_pending());
  f.read(Mode::track, 0, false, s);
  CHECK(f.supervisor.fault_pending());

  Bench h;
  s = hal::SensorState{};
  s.plant_state = hal::kPlantStateHolding;
  for (int k = 0; k < kPlantHoldCycles - 1; ++k) h.read(Mode::track, 0, false, s);
  CHECK_FALSE(h.supervisor.fault_pending());
  h.read(Mode::track, 0, false, s);
  CHECK(h.supervisor.fault_pending());
  h.enter(Mode::safe_stop, Mode::track);
  CHECK(h.supervisor.last_fault() == FirmwareFault::plant_holding);
  // In the safe state the machine holds as it should: no new count.
  Bench w;
  for (int k = 0; k < 50; ++k) w.read(Mode::safe_stop, 0, false, s);
  CHECK_FALSE(w.supervisor.fault_pending());
}

TEST_CASE("firmware/supervisor: a controlled stop whose cylinder creeps on escalates to the emergency stop, one at rest does not") {
  for (const double creep : {0.0, 0.005}) {  // m/s of boom motion with the valves centred
    CAPTURE(creep);
    Bench b;
    b.read(Mode::track);
    b.supervisor.check_law(b.cycle * kPeriod, true, Vec4(0, 0.5, 0, 0), false);
    b.read(Mode::track);
    b.enter(Mode::safe_stop, Mode::track);
    const std::uint64_t stop_cycle = b.cycle;
    bool escalated = false;
    std::uint64_t at = 0;
    for (int k = 0; k < 3000 && !escalated; ++k) {
      b.read(Mode::safe_stop);
      FlowMeasurement m;
      m.position = Vec4(0, 2.0 + creep * static_cast<double>(b.cycle - stop_cycle) * kPeriod, 2.5, 1.9);
      escalated = b.supervisor.check_standstill(Mode::safe_stop, b.cycle, true, m, false);
      at = b.cycle - stop_cycle;
    }
    CHECK(escalated == (creep > 0));
    CHECK(b.supervisor.stop_escalated() == (creep > 0));
    CHECK((b.supervisor.last_stop() == StopKind::emergency) == (creep > 0));
    if (creep > 0) {
      // From kStandstillDelay on, two windows: the first has no window before it to slow against.
      CHECK(static_cast<double>(at) * kPeriod <= kStandstillDelay + 2 * kStandstillWindow + 2 * kPeriod);
      FaultEvent event;
      REQUIRE(b.supervisor.next_event(event));
      CHECK(event.severity == 2);
      CHECK(std::string(event.text).find("controlled stop escalated to the emergency stop") == 0);
      CHECK(std::string(event.text).find("boom takes 0.0050 m/s") != std::string::npos);
      CHECK(b.supervisor.stop_frame().emergency);
      CHECK(b.supervisor.emergency_sent());
    }
  }
}

TEST_CASE("firmware/supervisor: the pump warning is raised after 20 cycles short of flow and cleared after 20 within it") {
  Bench b;
  FaultEvent event;
  for (int k = 0; k < kPumpWarningCycles - 1; ++k) b.supervisor.update_pump_warning(k * kPeriod, true, 0.01);
  CHECK_FALSE(b.supervisor.next_event(event));
  b.supervisor.update_pump_warning(0.019, true, 0.01);
  REQUIRE(b.supervisor.next_event(event));
  CHECK(event.code == FirmwareFault::pump_limited);
  CHECK(event.active);
  CHECK(event.severity == 1);
  CHECK(std::string(event.text).find("pumps short of flow: the valves ask 600 L/min of their 439 L/min") == 0);
  CHECK(b.supervisor.pump_warnings() == 1);
  CHECK(b.supervisor.pump_limited_cycles() == static_cast<std::uint64_t>(kPumpWarningCycles));
  CHECK_FALSE(b.supervisor.fault_pending());  // a warning, no stop
  for (int k = 0; k < kPumpWarningCycles; ++k) b.supervisor.update_pump_warning(0.02 + k * kPeriod, false, 0.005);
  REQUIRE(b.supervisor.next_event(event));
  CHECK_FALSE(event.active);
  CHECK(std::string(event.text).find("pumps within their flow again") == 0);
}

TEST_CASE("firmware/supervisor: missed deadlines in a row while commanding are a fault at the next cycle, none while not commanding") {
  SupervisorSettings s;
  s.max_missed_deadlines = 3;
  Bench b(s);
  for (std::uint64_t k = 1; k <= 10; ++k) b.supervisor.record_wakeup(k, 0, Mode::wait_sensors, 0.1);
  CHECK_FALSE(b.supervisor.fault_pending());
  Bench t(s);
  t.supervisor.record_wakeup(1, 0, Mode::track, 0.001);
  t.supervisor.record_wakeup(2, 0, Mode::track, 0.002);
  t.supervisor.record_wakeup(2, 0, Mode::track, 0.003);  // kept: the run starts again
  t.supervisor.record_wakeup(3, 0, Mode::track, 0.004);
  t.supervisor.record_wakeup(3, 1, Mode::track, 0.005);
  CHECK_FALSE(t.supervisor.fault_pending());
  t.supervisor.record_wakeup(4, 1, Mode::track, 0.006);
  CHECK(t.supervisor.fault_pending());
  CHECK(t.supervisor.missed_deadlines_in_a_row() == 3);
  t.cycle = 6;
  t.enter(Mode::safe_stop, Mode::track);
  CHECK(t.supervisor.last_fault() == FirmwareFault::deadline_overrun);
  CHECK(t.supervisor.fault_detected_time() == doctest::Approx(0.006));
}

TEST_CASE("firmware/supervisor: the exit frame keeps a standing stop's fault and takes the emergency stop for a fatal error") {
  Bench b;
  StopFrame f = b.supervisor.exit_frame(FirmwareFault::exited, Mode::track);
  CHECK(f.code == FirmwareFault::exited);
  CHECK_FALSE(f.emergency);
  f = b.supervisor.exit_frame(FirmwareFault::fatal_error, Mode::track);
  CHECK(f.emergency);
  Bench s;
  s.read(Mode::track);
  s.supervisor.check_law(s.cycle * kPeriod, true, Vec4(0.2, 0, 0, 0), false);
  s.enter(Mode::safe_stop, Mode::track);
  f = s.supervisor.exit_frame(FirmwareFault::exited, Mode::safe_stop);
  CHECK(f.code == FirmwareFault::tracking_error);
  CHECK_FALSE(f.emergency);
  // The watchdog's own stop: a sensor timeout, detected at the first cycle without a set.
  Bench w;
  w.read(Mode::track);
  w.cycle = 30;
  const CycleInputs in{0.030, 30, false, Mode::track};
  w.supervisor.on_transition(Transition{true, Mode::track, Mode::safe_stop, "watchdog"}, in, 0.009);
  CHECK(w.supervisor.last_fault() == FirmwareFault::sensor_timeout);
  CHECK(w.supervisor.fault_detected_time() == doctest::Approx(0.010));
  CHECK(text_of(w.supervisor) == "sensor timeout: no valid sensor set for 21 ms at t = 0.030 s");
  CHECK(w.supervisor.stop_frame().emergency);
}
