// FirmwareNode's own cycle, closed over the in-memory CAN bus with the model plant on the other end
// (firmware side only: no sim_plant code). What a user sees of the node: the task ends in hold at
// its final pose, a stop from outside brings it to hold, faults carry their codes, and the real
// cycle allocates nothing.
#include <doctest/doctest.h>
#include <yaml-cpp/yaml.h>

#include <atomic>
#include <cmath>
#include <map>
#include <vector>

#include "app/allocation_counter.hpp"
#include "app/firmware_node.hpp"
#include "app/firmware_runner.hpp"
#include "app/run_summary.hpp"
#include "closed_loop.hpp"
#include "dbc_reader.hpp"
#include "hal/can_bus_load.hpp"
#include "hal/can_protocol.hpp"
#include "hal/clock.hpp"
#include "hal/memory_bus.hpp"
#include "model/closed_chain.hpp"
#include "scenes.hpp"
#include "model/machine_reader.hpp"
#include "control/task/task_reader.hpp"

using namespace exc;
using namespace exc::control;
using namespace exc::safety;

namespace {

struct SimClock {
  std::int64_t now_ns = 0;
  static std::int64_t read(void* self) { return static_cast<SimClock*>(self)->now_ns; }
};

// Firmware node and model plant on one memory bus; the plant answers each SYNC with its state and
// applies the latest effort command, as the simulated machine does.
struct Loop {
  const Model& model;
  Task task;
  SimClock clock;
  hal::MemoryBusHub hub{&SimClock::read, &clock};
  hal::MemoryBusNode* fw_bus = hub.attach();
  hal::MemoryBusNode* plant_bus = hub.attach();
  hal::FirmwareCanPort fw_port{*fw_bus};
  hal::PlantCanPort plant_port{*plant_bus};
  sim::ModelPlant plant;
  app::FirmwareNode node;
  hal::CommandState command;
  bool answer = true;  // false: the plant goes silent (sensor loss)
  std::uint8_t plant_state = 0, plant_faults = 0;  // what SENS_MACHINE says of the machine

  Loop(const Model& m, const char* task_yaml, app::FirmwareNodeConfig cfg)
      : model(m),
        task(read_task(settings::Document::parse(task_yaml, "test"), m.machine)),
        plant(m, sim::SoilTruth{}),
        node(m, task, cfg, fw_port, nullptr) {
    Vec4 q0, qd0, qdd0;
    task.trajectory.evaluate(task.start_time(), q0, qd0, qdd0);
    plant.reset(q0, Vec4::Zero());
  }

  void cycle() {
    node.begin_cycle();
    plant_answer();
    node.end_cycle();
  }

  // The plant's side of one cycle: a SYNC waiting is answered, the machine moves on by a period.
  void plant_answer() {
    std::uint64_t k = 0;
    if (plant_port.poll_sync(k)) {
      clock.now_ns += 1'000'000;
      plant_port.read(command);
      const TipLoad load = plant.soil_load();
      Vec4 tau = Vec4::Zero();
      // Valve commands (the firmware's safe state: valves centred) hold the machine where it is, as
      // the simulated machine's hold does.
      if (command.valid && command.mode == hal::CommandMode::effort) {
        for (int j = 0; j < 4; ++j) tau[j] = command.value[j];
        plant.step(tau, load, 1e-3);
      } else if (command.valid) {
        plant.reset(plant.q(), Vec4::Zero());
      } else {
        plant.step(tau, load, 1e-3);
      }
      if (answer) {
        hal::SensorState s;
        s.cycle = k;
        s.motion_valid = true;
        s.plant_state = plant_state;
        s.plant_faults = plant_faults;
        for (int j = 0; j < 4; ++j) {
          s.position[j] = plant.q()[j];
          s.velocity[j] = plant.qd()[j];
        }
        plant_port.write(s);
      }
    }
  }
};

// The bus as excavator-firmware's runner waits on it: while the firmware waits for sensors, the
// plant answers (as the plant process would meanwhile). stall_ns makes the wait at one cycle last
// that long in real time, a stalled bus or a descheduled thread.
struct AnsweringBus final : hal::CanBus {
  Loop& loop;
  std::atomic<int>* stop_requests = nullptr;
  std::uint64_t stop_at_cycle = 0, stall_at_cycle = 0;  // 0: never
  std::int64_t stall_ns = 0;
  std::uint64_t hold_from = 0;  // the first cycle after stop_at_cycle the node was seen in hold (0: never)
  std::uint64_t throw_at_cycle = 0;  // the machine's pose jumps by `thrown` here (0: never)
  Vec4 thrown = Vec4::Zero();
  explicit AnsweringBus(Loop& l) : loop(l) {}
  bool send(const hal::CanFrame& frame) override { return loop.fw_bus->send(frame); }
  bool receive(hal::CanFrame& frame) override { return loop.fw_bus->receive(frame); }
  bool wait_readable(std::int64_t) override {
    const std::uint64_t k = loop.node.cycle();
    if (hold_from == 0 && stop_requests && k > stop_at_cycle && loop.node.mode() == Mode::hold) hold_from = k;
    if (stop_requests && k == stop_at_cycle) stop_requests->fetch_add(1);
    if (k == stall_at_cycle && stall_ns > 0) {
      const std::int64_t until = hal::monotonic_now_ns() + stall_ns;
      while (hal::monotonic_now_ns() < until) {
      }
    }
    if (throw_at_cycle > 0 && k == throw_at_cycle) loop.plant.reset(loop.plant.q() + thrown, Vec4::Zero());
    loop.plant_answer();
    return loop.fw_bus->pending() > 0;
  }
};

Vec2 tip_of(const Model& model, const Vec4& q) {
  Workspace ws(model);
  update_closed_chain(model, ws, q, Vec4::Zero());
  return ws.rho;
}

}  // namespace

TEST_CASE("firmware/node: after its task the machine holds the final pose, the path never restarts and the command never jumps") {
  const Model model = build_model(reference_machine());
  app::FirmwareNodeConfig cfg;
  cfg.controller.law = "adaptive";
  Loop loop(model, sim::kDigTask, cfg);
  const double end = loop.task.end_time();  // 10 s
  Vec4 q_final, qd_end, qdd_end;
  loop.task.trajectory.evaluate(end, q_final, qd_end, qdd_end);

  const int cycles = static_cast<int>(4 * end / 1e-3);  // four times the task's length
  double largest_step_tracking = 0, largest_step_after = 0, worst_tip_after = 0;
  int track_entries = 0;
  const Vec4 limits = model.machine.effort_max().cwiseMax(-model.machine.effort_min());
  Vec4 last_cmd = Vec4::Zero();
  bool have_last = false;
  for (int k = 0; k < cycles; ++k) {
    loop.cycle();
    const auto& tr = loop.node.last_transition();
    if (tr.changed && tr.to == Mode::track) ++track_entries;
    Vec4 cmd;
    for (int j = 0; j < 4; ++j) cmd[j] = loop.node.last_command().value[j];
    // Command change per cycle, per joint, as a fraction of the joint's effort limit.
    if (have_last) {
      const double step = ((cmd - last_cmd).cwiseAbs().array() / limits.array()).maxCoeff();
      if (loop.node.mode() == Mode::track && loop.node.time() > 1.0) largest_step_tracking = std::max(largest_step_tracking, step);
      if (loop.node.trajectory_finished()) largest_step_after = std::max(largest_step_after, step);
    }
    last_cmd = cmd;
    have_last = true;
    if (loop.node.trajectory_finished()) {
      REQUIRE(loop.node.mode() == Mode::hold);
      // The desired pose is the path's final point, exactly, every cycle after the end.
      CHECK((loop.node.q_desired() - q_final).cwiseAbs().maxCoeff() == 0.0);
      if (loop.node.time() > loop.node.finish_time() + 2.0)
        worst_tip_after = std::max(worst_tip_after, (loop.plant.rho() - tip_of(model, q_final)).norm());
    }
  }
  MESSAGE("finished at " << loop.node.finish_time() << " s; largest command step (fraction of the effort limit) while tracking "
                         << largest_step_tracking << ", after the end " << largest_step_after
                         << "; worst tip distance from the final pose (2 s after the end on) " << worst_tip_after * 1e3 << " mm");
  CHECK(loop.node.trajectory_finished());
  CHECK(track_entries == 1);
  // The task ends when its path ends (plus the start delay), to the cycle.
  CHECK(std::abs(loop.node.finish_time() - (end + cfg.track_delay)) <= 1.5e-3);
  CHECK(worst_tip_after < 1e-3);
  // Ending the task is no bigger a change of command than a cycle of tracking.
  CHECK(largest_step_after <= largest_step_tracking);
}

TEST_CASE("firmware/node: a stop request decelerates a tracking machine along its path, no faster than its top speed per ramp time, and holds where the path came to rest") {
  const Model model = build_model(reference_machine());
  app::FirmwareNodeConfig cfg;
  cfg.controller.law = "pid";
  Loop loop(model, sim::kFreeMotionTask, cfg);
  while (loop.node.time() < 3.0) loop.cycle();
  REQUIRE(loop.node.mode() == Mode::track);
  const double t_stop = loop.node.time() + 1e-3;  // the request is taken on the next cycle
  const double tau0 = loop.node.task_time() + 1e-3;
  Vec4 q0, v0, a0;
  loop.task.trajectory.evaluate(tau0, q0, v0, a0);
  const Vec4 vmax = model.machine.speed_max();
  const double ramp = cfg.controller.path_clock.stop_ramp_time;
  // The closed form of path_stop.hpp: T = (pi / 2) ramp max_j |v_j| / v_max_j.
  const double T = 0.5 * M_PI * ramp * (v0.cwiseAbs().array() / vmax.array()).maxCoeff();
  REQUIRE(T > 0.05);  // the path moves at 3 s: there is a deceleration to see
  // The path's own largest speed and acceleration over the stretch the stop covers.
  Vec4 v_seg = Vec4::Zero(), a_seg = Vec4::Zero();
  for (int i = 0; i <= 200; ++i) {
    Vec4 q, v, a;
    loop.task.trajectory.evaluate(tau0 + 0.5 * T * i / 200.0, q, v, a);
    v_seg = v_seg.cwiseMax(v.cwiseAbs());
    a_seg = a_seg.cwiseMax(a.cwiseAbs());
  }
  loop.node.request_stop();
  Vec4 q_prev = loop.node.q_desired(), step_prev = Vec4::Zero();
  bool have_step = false;
  double last_tau = -1;
  int hold_at = -1;
  for (int k = 0; k < 3000; ++k) {
    loop.cycle();
    const Vec4 q_d = loop.node.q_desired();
    if (loop.node.mode() == Mode::track) {
      REQUIRE(loop.node.stopping_on_path());
      const double tau = loop.node.task_time();
      CHECK(tau >= last_tau);  // the path's clock never runs back
      last_tau = tau;
      // On the path: the desired pose is the trajectory's point at the slowed clock.
      Vec4 q, v, a;
      loop.task.trajectory.evaluate(tau, q, v, a);
      CHECK((q_d - q).cwiseAbs().maxCoeff() < 1e-12);
    } else if (hold_at < 0) {
      hold_at = k;
      CHECK(loop.node.last_transition().changed);
      CHECK(std::string(loop.node.last_transition().reason) == "stop requested");
    }
    // The desired motion never runs faster than the path, and decelerates by at most each function's
    // top speed per ramp time on top of the path's own acceleration.
    const Vec4 step = q_d - q_prev;
    for (int j = 0; j < 4; ++j) {
      CHECK(std::abs(step[j]) <= v_seg[j] * 1e-3 + 1e-12);
      if (have_step) CHECK(std::abs(step[j] - step_prev[j]) / 1e-6 <= vmax[j] / ramp + a_seg[j] + 1e-6);
    }
    q_prev = q_d;
    step_prev = step;
    have_step = true;
    if (hold_at >= 0) REQUIRE(loop.node.mode() == Mode::hold);
  }
  REQUIRE(hold_at >= 0);
  // In hold once the path's clock has stopped: T after the request, to the cycle.
  CHECK(std::abs(t_stop + hold_at * 1e-3 - (t_stop + T)) <= 2e-3);
  // Where it holds: the path's point T / 2 of path time on (the half-cosine's travel), to within the
  // last tracking cycle's creep (the rate's cube: nanometres).
  Vec4 q_rest, v, a;
  loop.task.trajectory.evaluate(tau0 + 0.5 * T, q_rest, v, a);
  CHECK((loop.node.q_desired() - q_rest).cwiseAbs().maxCoeff() < 1e-6);
  CHECK_FALSE(loop.node.trajectory_finished());
  // Held, the machine settles where the path stopped (within 1 mm / 1 mrad).
  CHECK((loop.plant.q() - q_rest).cwiseAbs().maxCoeff() < 1e-3);
  MESSAGE("stop along the path at " << t_stop << " s: " << T << " s to rest (ramp " << ramp << " s)");
}

TEST_CASE("firmware/node: with stop_ramp_time 0 a stop request holds at the desired pose of that moment") {
  const Model model = build_model(reference_machine());
  app::FirmwareNodeConfig cfg;
  cfg.controller.law = "pid";
  cfg.controller.path_clock.stop_ramp_time = 0;
  Loop loop(model, sim::kFreeMotionTask, cfg);
  while (loop.node.time() < 3.0) loop.cycle();
  REQUIRE(loop.node.mode() == Mode::track);
  const Vec4 q_at_stop = loop.node.q_desired();
  loop.node.request_stop();
  loop.cycle();
  CHECK(loop.node.mode() == Mode::hold);
  CHECK(std::string(loop.node.last_transition().reason) == "stop requested");
  for (int k = 0; k < 3000; ++k) {
    loop.cycle();
    REQUIRE(loop.node.mode() == Mode::hold);
    CHECK((loop.node.q_desired() - q_at_stop).cwiseAbs().maxCoeff() == 0.0);
  }
  CHECK((loop.plant.q() - q_at_stop).cwiseAbs().maxCoeff() < 1e-3);
}

TEST_CASE("firmware/node: losing the sensor frames raises the sensor-timeout fault the watchdog's time after the first missing set and sends it on the bus") {
  const Model model = build_model(reference_machine());
  app::FirmwareNodeConfig cfg;
  Loop loop(model, sim::kFreeMotionTask, cfg);
  while (loop.node.time() < 1.0) loop.cycle();
  REQUIRE(loop.node.mode() == Mode::track);
  loop.answer = false;
  int cycles_to_stop = 0;
  while (loop.node.mode() != Mode::safe_stop && cycles_to_stop < 1000) {
    loop.cycle();
    ++cycles_to_stop;
  }
  CHECK(loop.node.mode() == Mode::safe_stop);
  // The watchdog's timeout is 20 ms: the safe state comes on the first cycle past it.
  CHECK(cycles_to_stop == static_cast<int>(std::lround(cfg.controller.watchdog_timeout / 1e-3)) + 1);
  // Detected on the gap's first cycle: the safe state follows the watchdog's time later.
  const double silent_from = loop.node.time() - (cycles_to_stop - 1) * 1e-3;
  CHECK(loop.node.supervisor().fault_detected_time() == doctest::Approx(silent_from));
  CHECK(loop.node.time() - loop.node.supervisor().fault_detected_time() == doctest::Approx(cfg.controller.watchdog_timeout));
  // The plant's end reads the fault frame with its code (on its next SYNC).
  loop.cycle();
  CHECK(loop.command.fault_code == static_cast<std::uint16_t>(safety::FirmwareFault::sensor_timeout));
}

TEST_CASE("firmware/node: zero heap allocations in FirmwareNode's own cycle over 20000 cycles of the dig task") {
  REQUIRE(exc::app::allocation_counting_works());
  const Model model = build_model(reference_machine());
  for (const std::string kind : {"pid", "adaptive", "slotine_li"}) {
    app::FirmwareNodeConfig cfg;
    cfg.controller.law = kind;
    cfg.controller.actuation.actuator_lag = 0.02;
    Loop loop(model, sim::kDigTask, cfg);
    loop.cycle();  // start-up cycle outside the count (first touch)
    std::size_t allocations = 0;
    {
      exc::app::AllocationCounter counter;
      exc::app::EigenNoMallocScope no_eigen_malloc;
      for (int k = 0; k < 20000; ++k) loop.cycle();
      allocations = counter.count();
    }
    INFO(kind);
    CHECK(allocations == 0);
    CHECK(loop.node.trajectory_finished());  // the run crossed track -> hold too
  }
}

TEST_CASE("firmware/node: zero heap allocations through a stop along the path (request, deceleration, hold) in the dig task, its clock paced to the pumps or not") {
  REQUIRE(exc::app::allocation_counting_works());
  const Model model = build_model(reference_machine());
  for (const bool paced : {false, true})
  for (const std::string kind : {"pid", "adaptive", "slotine_li"}) {
    app::FirmwareNodeConfig cfg;
    cfg.controller.law = kind;
    cfg.controller.path_clock.pump_pacing = paced;  // control/task/pump_pacing.hpp: the clock a state stepped each cycle
    Loop loop(model, sim::kDigTask, cfg);
    loop.cycle();  // start-up cycle outside the count (first touch)
    std::size_t allocations = 0;
    int slowing = 0;
    {
      exc::app::AllocationCounter counter;
      exc::app::EigenNoMallocScope no_eigen_malloc;
      for (int k = 0; k < 6000; ++k) {
        if (k == 4000) loop.node.request_stop();
        loop.cycle();
        slowing += loop.node.stopping_on_path() ? 1 : 0;
      }
      allocations = counter.count();
    }
    INFO(kind << (paced ? ", paced" : ""));
    CHECK(allocations == 0);
    CHECK(slowing > 0);  // the path was slowed, not cut
    CHECK(loop.node.mode() == Mode::hold);
    CHECK_FALSE(loop.node.trajectory_finished());
  }
}

TEST_CASE("firmware/node: every frame the firmware sends keeps the DBC's cycle time in a capture, FW_EMERGENCY repeating while the safe state lasts") {
  // The schedule comes from the DBC file (read by the tests' own reader), the frames from a listener
  // on the bus, as candump would see them.
  const std::vector<exc::test::DbcMessage> dbc = exc::test::read_dbc(EXC_CAN_DBC_FILE);
  const Model model = build_model(reference_machine());
  app::FirmwareNodeConfig cfg;
  Loop loop(model, sim::kFreeMotionTask, cfg);
  hal::MemoryBusNode* listener = loop.hub.attach(4096);
  std::map<std::uint32_t, std::vector<int>> seen;  // id -> cycles it was sent in
  const int silent_from = 2000, silent_to = 2500, cycles = 4000;
  for (int k = 1; k <= cycles; ++k) {
    loop.answer = k < silent_from || k >= silent_to;
    if (k == silent_to) loop.node.acknowledge();  // the stop latches until an operator acknowledges it
    loop.cycle();
    hal::CanFrame f;
    while (listener->receive(f)) seen[f.id].push_back(k);
  }
  int checked = 0;
  for (const auto& m : dbc) {
    if (m.sender != "Firmware") continue;
    const std::vector<int>& at = seen[m.id];
    INFO(m.name);
    if (m.if_active) {
      // Active from the watchdog's trip (21 cycles into the silence) to the acknowledge, on the first
      // answered cycle, which sends one more frame: the release (EmergencyStop = 0, no fault).
      REQUIRE(m.cycle_fast_ms == hal::kEmergencyRepeatCycles);
      REQUIRE(at.size() >= 3);
      const int first = silent_from + static_cast<int>(std::lround(cfg.controller.watchdog_timeout / 1e-3));
      CHECK(at.front() == first);
      for (std::size_t i = 1; i + 1 < at.size(); ++i) CHECK(at[i] - at[i - 1] == m.cycle_fast_ms);
      CHECK(at.back() == silent_to);
      // The last repeat falls on the acknowledged cycle: its SYNC goes out before the answer.
      CHECK(at.size() == static_cast<std::size_t>((silent_to - first) / m.cycle_fast_ms + 2));
      ++checked;
    } else if (m.cycle_ms > 0 && m.command_set <= 1) {
      // The effort set is sent; valves only in the safe state, pilots not yet (the valve inner loop).
      REQUIRE(at.size() >= 2);
      int largest_gap = 0;
      for (std::size_t i = 1; i < at.size(); ++i) largest_gap = std::max(largest_gap, at[i] - at[i - 1]);
      const bool commands = m.command_set == 1;
      // Commands pause while the safe state sends valves instead; everything else keeps its period.
      if (commands)
        CHECK(at.size() + (silent_to - silent_from) >= static_cast<std::size_t>(cycles / m.cycle_ms) - 30);
      else
        CHECK(largest_gap == m.cycle_ms);
      ++checked;
    }
  }
  CHECK(checked == 4);  // SYNC, CMD_EFFORT, FW_HEARTBEAT, FW_EMERGENCY
}

TEST_CASE("firmware/node: a swing that cannot keep up (2 rad in 2.5 s, saturated) trips the tracking-error fault within one cycle's motion past the limit") {
  const Model model = build_model(reference_machine());
  app::FirmwareNodeConfig cfg;
  cfg.controller.law = "pid";
  Loop loop(model, sim::kFastSwingTask, cfg);
  const double limit = cfg.controller.supervisor.tracking_error_limit[0];
  double error_before = 0, desired_step = 0;
  Vec4 last_qd = loop.node.q_desired();
  int cycles = 0;
  while (loop.node.mode() != Mode::safe_stop && cycles < 5000) {
    loop.cycle();
    ++cycles;
    if (loop.node.mode() == Mode::track) {
      error_before = std::abs(loop.plant.q()[0] - loop.node.q_desired()[0]);
      desired_step = std::max(desired_step, std::abs(loop.node.q_desired()[0] - last_qd[0]));
    }
    last_qd = loop.node.q_desired();
  }
  REQUIRE(loop.node.mode() == Mode::safe_stop);
  CHECK(loop.node.supervisor().last_fault() == safety::FirmwareFault::tracking_error);
  const std::string text = loop.node.supervisor().last_fault_text();
  MESSAGE(text << "; error at the last tracking cycle " << error_before << " rad");
  CHECK(text.rfind("tracking error: swing ", 0) == 0);
  // Stopped before the error passed the limit by more than one cycle of the path's motion.
  CHECK(error_before <= limit + desired_step + 1e-9);
  CHECK(loop.node.time() < 2.5 + cfg.track_delay);  // long before the path's end
  // Detected on the last tracking cycle, the safe state on the next.
  CHECK(loop.node.time() - loop.node.supervisor().fault_detected_time() == doctest::Approx(1e-3));
  // The plant hears it: FW_EMERGENCY carries the code.
  loop.cycle();
  CHECK(loop.command.fault_code == static_cast<std::uint16_t>(safety::FirmwareFault::tracking_error));
}

TEST_CASE("firmware/node: the reference dig and free-motion tasks on the force-actuated model never trip the tracking-error fault with any effort law") {
  const Model model = build_model(reference_machine());
  for (const char* task : {sim::kDigTask, sim::kFreeMotionTask}) {
    for (const std::string kind : {"pid", "adaptive", "slotine_li"}) {
      app::FirmwareNodeConfig cfg;
      cfg.controller.law = kind;
      Loop loop(model, task, cfg);
      for (int k = 0; k < 11000; ++k) loop.cycle();
      INFO(kind << ": " << loop.node.supervisor().last_fault_text());
      CHECK(loop.node.supervisor().safe_stops() == 0);
      CHECK(loop.node.trajectory_finished());
    }
  }
}

TEST_CASE("firmware/node: the port counts every frame on the bus once, at its exact on-wire time, between the unstuffed and the worst-case frame") {
  const Model model = build_model(reference_machine());
  app::FirmwareNodeConfig cfg;
  Loop loop(model, sim::kFreeMotionTask, cfg);
  hal::MemoryBusNode* listener = loop.hub.attach(4096);
  std::uint64_t frames = 0, unstuffed_ns = 0, worst_ns = 0;
  constexpr int cycles = 2000;
  for (int k = 0; k < cycles; ++k) {
    loop.cycle();
    hal::CanFrame f;
    while (listener->receive(f)) {
      ++frames;
      REQUIRE(f.fd);
      REQUIRE(f.brs);
      // No stuff bits: 17 + 13 nominal bits, ESI, DLC, data and the fixed-stuffed CRC field fast.
      unstuffed_ns += 30 * hal::kNominalBitNs + (5 + 8 * f.len + hal::canfd_crc_field_bits(f.len)) * hal::kDataBitNs;
      worst_ns += static_cast<std::uint64_t>(hal::canfd_frame_bits_worst(f.len).duration_ns());
    }
  }
  const std::uint64_t counted = loop.fw_port.tx_stats().bus_ns + loop.fw_port.rx_bus_ns();
  const double load = static_cast<double>(counted) * 1e-9 / (cycles * 1e-3);
  MESSAGE(frames << " frames, " << counted / 1000 << " us on the bus (unstuffed " << unstuffed_ns / 1000 << ", worst case "
                 << worst_ns / 1000 << "): bus load " << load * 100 << " %");
  CHECK(loop.fw_port.tx_stats().frames_sent + loop.fw_port.rx_stats().ok == frames);
  CHECK(counted > unstuffed_ns);
  CHECK(counted < worst_ns);
  // SYNC, CMD_EFFORT and SENS_MACHINE every cycle, a heartbeat every 50: 21-26 % of the bus.
  CHECK(load > 0.21);
  CHECK(load < 0.26);
  diagnostics::BusLoadWindow window;
  CHECK(window.update(counted, cycles * 1e-3) == doctest::Approx(load));
}

TEST_CASE("firmware/node: a sensor timeout takes the emergency stop (EmergencyStop = 1) and the stop latches until acknowledged") {
  const Model model = build_model(reference_machine());
  app::FirmwareNodeConfig cfg;
  cfg.controller.law = "pid";
  Loop loop(model, sim::kFreeMotionTask, cfg);
  while (loop.node.time() < 1.0) loop.cycle();
  REQUIRE(loop.node.mode() == Mode::track);
  CHECK_FALSE(loop.node.supervisor().emergency_sent());
  loop.answer = false;
  for (int k = 0; k < 50; ++k) loop.cycle();
  REQUIRE(loop.node.mode() == Mode::safe_stop);
  CHECK(loop.node.supervisor().last_fault() == safety::FirmwareFault::sensor_timeout);
  CHECK(loop.node.supervisor().last_stop() == safety::StopKind::emergency);
  CHECK(loop.node.supervisor().emergency_sent());
  // The frames come back; for 2 s nobody acknowledges: the firmware stays stopped, the machine's
  // end keeps reading the emergency stop with its code.
  loop.answer = true;
  for (int k = 0; k < 2000; ++k) {
    loop.cycle();
    REQUIRE(loop.node.mode() == Mode::safe_stop);
  }
  CHECK(loop.command.emergency_stop);
  CHECK(loop.command.fault_code == static_cast<std::uint16_t>(safety::FirmwareFault::sensor_timeout));
  CHECK(loop.command.mode == hal::CommandMode::valve);
  CHECK(loop.node.supervisor().safe_stops() == 1);
  // Acknowledged: hold where the machine is, the machine's latch released, the task not restarted.
  loop.node.acknowledge();
  loop.cycle();
  CHECK(loop.node.mode() == Mode::hold);
  CHECK(std::string(loop.node.last_transition().reason) == "acknowledged, sensor frames fresh, no fault");
  loop.cycle();
  CHECK_FALSE(loop.command.emergency_stop);
  CHECK(loop.command.fault_code == 0);
  for (int k = 0; k < 1000; ++k) {
    loop.cycle();
    REQUIRE(loop.node.mode() == Mode::hold);
  }
}

TEST_CASE("firmware/node: an acknowledge while the frames are still missing is spent, the stop stays") {
  const Model model = build_model(reference_machine());
  app::FirmwareNodeConfig cfg;
  cfg.controller.law = "pid";
  Loop loop(model, sim::kFreeMotionTask, cfg);
  while (loop.node.time() < 1.0) loop.cycle();
  loop.answer = false;
  for (int k = 0; k < 50; ++k) loop.cycle();
  REQUIRE(loop.node.mode() == Mode::safe_stop);
  loop.node.acknowledge();
  loop.cycle();
  CHECK(loop.node.mode() == Mode::safe_stop);
  loop.answer = true;  // back, but the acknowledge came before: still stopped
  for (int k = 0; k < 100; ++k) loop.cycle();
  CHECK(loop.node.mode() == Mode::safe_stop);
}

TEST_CASE("firmware/node: the machine's own signals are heard and named: PLANT_EMERGENCY, PlantFaults, PlantState hold") {
  const Model model = build_model(reference_machine());
  app::FirmwareNodeConfig cfg;
  cfg.controller.law = "pid";
  SUBCASE("PLANT_EMERGENCY") {
    Loop loop(model, sim::kFreeMotionTask, cfg);
    while (loop.node.time() < 1.0) loop.cycle();
    REQUIRE(loop.node.mode() == Mode::track);
    loop.plant_port.send_fault(true, 3);
    loop.cycle();  // read in this cycle, before the state machine steps: the safe state at once
    CHECK(loop.node.mode() == Mode::safe_stop);
    CHECK(loop.node.supervisor().last_fault() == safety::FirmwareFault::plant_emergency);
    CHECK(std::string(loop.node.supervisor().last_fault_text()).find("PLANT_EMERGENCY code 3") != std::string::npos);
    CHECK(loop.node.supervisor().last_stop() == safety::StopKind::emergency);
    loop.cycle();
    CHECK(loop.command.emergency_stop);
  }
  SUBCASE("PlantFaults") {
    Loop loop(model, sim::kFreeMotionTask, cfg);
    while (loop.node.time() < 1.0) loop.cycle();
    loop.plant_faults = 0x02;
    loop.cycle();
    loop.cycle();
    CHECK(loop.node.mode() == Mode::safe_stop);
    CHECK(loop.node.supervisor().last_fault() == safety::FirmwareFault::plant_fault);
    CHECK(std::string(loop.node.supervisor().last_fault_text()).find("PlantFaults 0x02") != std::string::npos);
    // Latched: the plant's fault bits clear, the firmware stays stopped until acknowledged; an
    // acknowledge while the bits stand is refused.
    loop.plant_faults = 0x02;
    loop.node.acknowledge();
    for (int k = 0; k < 10; ++k) loop.cycle();
    CHECK(loop.node.mode() == Mode::safe_stop);
    loop.plant_faults = 0;
    for (int k = 0; k < 10; ++k) loop.cycle();
    CHECK(loop.node.mode() == Mode::safe_stop);
    loop.node.acknowledge();
    loop.cycle();
    CHECK(loop.node.mode() == Mode::hold);
  }
  SUBCASE("PlantState hold while commanded") {
    Loop loop(model, sim::kFreeMotionTask, cfg);
    while (loop.node.time() < 1.0) loop.cycle();
    // Four sets saying hold are what entering hold/track looks like: no fault.
    loop.plant_state = 1;
    for (int k = 0; k < 4; ++k) loop.cycle();
    loop.plant_state = 0;
    for (int k = 0; k < 10; ++k) loop.cycle();
    REQUIRE(loop.node.mode() == Mode::track);
    loop.plant_state = 1;
    int cycles = 0;
    while (loop.node.mode() == Mode::track && cycles < 100) {
      loop.cycle();
      ++cycles;
    }
    CHECK(cycles == 5);  // the fifth set; the plant's signals are read before the state machine steps
    CHECK(loop.node.supervisor().last_fault() == safety::FirmwareFault::plant_holding);
    CHECK(loop.node.supervisor().last_stop() == safety::StopKind::emergency);
  }
}

TEST_CASE("firmware/node: consecutive missed deadlines in real time are a fault (controlled stop), scattered ones are not") {
  const Model model = build_model(reference_machine());
  app::FirmwareNodeConfig cfg;
  cfg.controller.law = "pid";
  Loop loop(model, sim::kFreeMotionTask, cfg);
  while (loop.node.time() < 1.0) loop.cycle();
  const int limit = cfg.controller.supervisor.max_missed_deadlines;
  REQUIRE(limit == 5);
  std::uint64_t overruns = 0;
  // limit - 1 late wake-ups, one on time, again: never limit in a row.
  for (int round = 0; round < 20; ++round) {
    for (int k = 0; k < limit - 1; ++k) {
      loop.node.record_wakeup(1'500'000, ++overruns, 0);
      loop.cycle();
    }
    loop.node.record_wakeup(1'000'000, overruns, 0);
    loop.cycle();
  }
  REQUIRE(loop.node.mode() == Mode::track);
  for (int k = 0; k < limit; ++k) {
    loop.node.record_wakeup(1'500'000, ++overruns, 0);
    loop.cycle();
  }
  loop.cycle();
  CHECK(loop.node.mode() == Mode::safe_stop);
  CHECK(loop.node.supervisor().last_fault() == safety::FirmwareFault::deadline_overrun);
  CHECK(loop.node.supervisor().last_stop() == safety::StopKind::controlled);
  loop.cycle();
  CHECK_FALSE(loop.command.emergency_stop);
  CHECK(loop.command.fault_code == static_cast<std::uint16_t>(safety::FirmwareFault::deadline_overrun));
}

TEST_CASE("firmware/node: the last command of a program that leaves centres the valves and says why, an error takes the emergency stop") {
  const Model model = build_model(reference_machine());
  for (const safety::FirmwareFault why : {safety::FirmwareFault::exited, safety::FirmwareFault::fatal_error}) {
    app::FirmwareNodeConfig cfg;
    cfg.controller.law = "pid";
    Loop loop(model, sim::kFreeMotionTask, cfg);
    while (loop.node.time() < 1.0) loop.cycle();
    REQUIRE(loop.node.mode() == Mode::track);
    REQUIRE(loop.command.mode == hal::CommandMode::effort);
    loop.node.send_safe_command(why);
    std::uint64_t k = 0;
    loop.plant_port.poll_sync(k);  // no SYNC follows: the frames are latched as they come
    loop.plant_port.read(loop.command);
    INFO(safety::to_string(why));
    CHECK(loop.command.mode == hal::CommandMode::valve);
    for (int j = 0; j < 4; ++j) CHECK(loop.command.value[j] == 0.0);
    CHECK(loop.command.fault_code == static_cast<std::uint16_t>(why));
    CHECK(loop.command.emergency_stop == (why == safety::FirmwareFault::fatal_error));
    CHECK(loop.node.safe_command_sent());
  }
}

TEST_CASE("firmware/node: a node set to wait for the operator holds until a SUPERVISOR start frame, then tracks, and without the setting it starts by itself") {
  const Model model = build_model(reference_machine());
  app::FirmwareNodeConfig cfg;
  cfg.controller.law = "pid";
  SUBCASE("waits for start") {
    cfg.wait_for_start = true;
    Loop loop(model, sim::kFreeMotionTask, cfg);
    hal::OperatorCanPort station(*loop.hub.attach());
    while (loop.node.time() < 1.0) {
      loop.cycle();
      REQUIRE(loop.node.mode() != Mode::track);
    }
    CHECK(loop.node.mode() == Mode::hold);
    // A stop before the start withdraws nothing yet given, and an acknowledge outside a stop does nothing.
    REQUIRE(station.send(hal::SupervisorCommand::acknowledge));
    for (int k = 0; k < 10; ++k) loop.cycle();
    CHECK(loop.node.mode() == Mode::hold);
    REQUIRE(station.send(hal::SupervisorCommand::start));
    loop.cycle();
    CHECK(loop.node.supervisor().start_received());
    CHECK(loop.node.mode() == Mode::track);
  }
  SUBCASE("starts by itself") {
    Loop loop(model, sim::kFreeMotionTask, cfg);
    while (loop.node.time() < 0.2) loop.cycle();
    CHECK(loop.node.mode() == Mode::track);
    CHECK_FALSE(loop.node.supervisor().start_received());
  }
}

TEST_CASE("firmware/node: SUPERVISOR stop and acknowledge in one cycle: the stop stands until an acknowledge of its own") {
  const Model model = build_model(reference_machine());
  app::FirmwareNodeConfig cfg;
  cfg.controller.law = "pid";
  Loop loop(model, sim::kFreeMotionTask, cfg);
  hal::MemoryBusNode* station_bus = loop.hub.attach();
  hal::OperatorCanPort station(*station_bus);
  while (loop.node.time() < 1.0) loop.cycle();
  REQUIRE(loop.node.mode() == Mode::track);
  REQUIRE(station.send(hal::SupervisorCommand::stop));
  // The machine decelerates along its path (at most (pi / 2) stop_ramp_time), then the stop latches.
  for (int k = 0; k < 700 && loop.node.mode() == Mode::track; ++k) loop.cycle();
  REQUIRE(loop.node.mode() == Mode::safe_stop);
  CHECK(loop.node.supervisor().last_fault() == safety::FirmwareFault::operator_stop);
  CHECK(loop.node.supervisor().last_stop() == safety::StopKind::controlled);
  loop.cycle();
  CHECK_FALSE(loop.command.emergency_stop);
  CHECK(loop.command.fault_code == static_cast<std::uint16_t>(safety::FirmwareFault::operator_stop));
  REQUIRE(station.send(hal::SupervisorCommand::acknowledge));
  REQUIRE(station.send(hal::SupervisorCommand::stop));
  for (int k = 0; k < 20; ++k) loop.cycle();
  CHECK(loop.node.mode() == Mode::safe_stop);
  REQUIRE(station.send(hal::SupervisorCommand::acknowledge));
  loop.cycle();
  CHECK(loop.node.mode() == Mode::hold);
}

TEST_CASE("firmware/faults: every fault kind names its stop, those the valves or sensors cannot be trusted in take the emergency stop") {
  using safety::FirmwareFault;
  using safety::StopKind;
  CHECK(safety::stop_of(safety::FirmwareFault::none) == safety::StopKind::none);
  CHECK(safety::stop_of(safety::FirmwareFault::pump_limited) == safety::StopKind::none);
  for (safety::FirmwareFault f : {safety::FirmwareFault::sensor_timeout, safety::FirmwareFault::plant_emergency, safety::FirmwareFault::plant_fault,
                          safety::FirmwareFault::plant_holding, safety::FirmwareFault::velocity_implausible, safety::FirmwareFault::fatal_error})
    CHECK(safety::stop_of(f) == safety::StopKind::emergency);
  // A wrong pressure reading: the valves obey and the position sensors watch the stop (docs/safety.md, H4).
  for (safety::FirmwareFault f : {safety::FirmwareFault::model, safety::FirmwareFault::tracking_error, safety::FirmwareFault::no_pressures,
                          safety::FirmwareFault::deadline_overrun, safety::FirmwareFault::exited, safety::FirmwareFault::operator_stop,
                          safety::FirmwareFault::pressure_implausible})
    CHECK(safety::stop_of(f) == safety::StopKind::controlled);
  for (int code = 0; code <= 14; ++code) CHECK(std::string(safety::to_string(static_cast<safety::FirmwareFault>(code))) != "unknown");
}

// excavator-firmware's cycle (app/firmware_runner), run here over the memory bus with the model plant
// answering while the runner waits: what the process does at its end, on a stop and when it is late.
TEST_CASE("firmware/runner: a lockstep run does its cycles, tracks, and leaves the valves centred with the exit's code") {
  const Model model = build_model(reference_machine());
  app::FirmwareNodeConfig cfg;
  cfg.controller.law = "pid";
  Loop loop(model, sim::kFreeMotionTask, cfg);
  AnsweringBus bus(loop);
  app::RunnerOptions run;
  run.cycles = 1500;
  const std::atomic<int> no_stop{0};
  const app::RunnerOutcome out = app::run_firmware(loop.node, bus, run, no_stop, nullptr);
  INFO(out.failure);
  CHECK(out.ok);
  CHECK(out.cycles == 1500);
  CHECK(loop.node.measured_tracking().samples() > 1000);
  CHECK(loop.node.mode() == Mode::track);
  // The last frames on the bus: valves centred, the exit named, no emergency.
  std::uint64_t k = 0;
  loop.plant_port.poll_sync(k);
  loop.plant_port.read(loop.command);
  CHECK(loop.command.mode == hal::CommandMode::valve);
  for (int j = 0; j < 4; ++j) CHECK(loop.command.value[j] == 0.0);
  CHECK(loop.command.fault_code == static_cast<std::uint16_t>(safety::FirmwareFault::exited));
  CHECK_FALSE(loop.command.emergency_stop);
}

// excavator-firmware's summary splits the run into phases as excavator-sim's does (app/run_phases):
// on the old summary only the tracking phase was counted and a hold thrown off its pose passed.
TEST_CASE("firmware/run summary: the errors per phase, and a hold thrown past the holding tolerance fails the run") {
  const Model model = build_model(reference_machine());
  app::FirmwareNodeConfig cfg;
  cfg.controller.law = "pid";
  for (const double throw_mm : {0.0, 6.0}) {
    CAPTURE(throw_mm);
    Loop loop(model, sim::kFreeMotionTask, cfg);
    AnsweringBus bus(loop);
    const double end = loop.task.end_time();  // 8 s; the hold settles within kHoldSettleLimit
    const auto thrown_at = static_cast<std::uint64_t>((end + app::kHoldSettleLimit + 1) / 1e-3);
    if (throw_mm > 0) {
      bus.throw_at_cycle = thrown_at;
      bus.thrown = Vec4(0, 0, throw_mm * 1e-3, 0);  // the arm
    }
    app::RunnerOptions run;
    run.cycles = static_cast<std::int64_t>(thrown_at + 2000);
    const std::atomic<int> no_stop{0};
    const app::RunnerOutcome out = app::run_firmware(loop.node, bus, run, no_stop, nullptr);
    INFO(out.failure);
    // The phases: the tracking phase is the firmware's measured tracking, the hold follows the task.
    REQUIRE(out.tracking.samples == static_cast<std::uint64_t>(loop.node.measured_tracking().samples()));
    for (int j = 0; j < 4; ++j) CHECK(out.tracking.max_error[j] == doctest::Approx(loop.node.measured_tracking().max_abs(j)));
    REQUIRE(out.hold.samples > 0);
    CHECK(out.settle.seconds <= app::kHoldSettleLimit + 1e-9);
    CHECK(out.stop.samples == 0);
    const app::RunContext context{loop.node, out, "pid", false, 1e-3, 0, nullptr, telemetry::OverflowPolicy::block};
    const nlohmann::json j = app::run_summary_json(context);
    REQUIRE(j.contains("phases"));
    CHECK(j["phases"]["stop"].is_null());
    CHECK(j["phases"]["hold"]["max_error"]["arm"].get<double>() == doctest::Approx(out.hold.max_error[2]));
    CHECK(j["phases"]["tracking"]["samples"].get<std::uint64_t>() == out.tracking.samples);
    CHECK(j["holding_tolerance"]["arm"].get<double>() == app::kHoldingTolerance[2]);
    if (throw_mm > 0) {
      // The arm's error in the hold is at least the throw less what one cycle corrects.
      CHECK(out.hold.max_error[2] > 0.9 * throw_mm * 1e-3);
      CHECK(out.hold.excursions[2] >= 1);
      CHECK_FALSE(out.ok);
      CHECK(out.failure.find("the arm left its held pose") != std::string::npos);
      CHECK_FALSE(j["hold_ok"].get<bool>());
      CHECK_FALSE(j["ok"].get<bool>());
    } else {
      for (int k = 0; k < 4; ++k) CHECK(out.hold.max_error[k] < app::kHoldingTolerance[k]);
      CHECK(out.ok);
      CHECK(j["hold_ok"].get<bool>());
    }
  }
}

TEST_CASE("firmware/runner: a stop request decelerates a tracking machine along its path, holds it for the hold time, then ends, and before tracking ends at once") {
  const Model model = build_model(reference_machine());
  app::FirmwareNodeConfig cfg;
  cfg.controller.law = "pid";
  {
    Loop loop(model, sim::kFreeMotionTask, cfg);
    AnsweringBus bus(loop);
    std::atomic<int> stops{0};
    bus.stop_requests = &stops;
    bus.stop_at_cycle = 2000;
    app::RunnerOptions run;
    run.cycles = 20000;
    run.stop_hold_s = 0.5;
    const app::RunnerOutcome out = app::run_firmware(loop.node, bus, run, stops, nullptr);
    INFO(out.failure);
    CHECK(out.stop_requested);
    CHECK(out.ok);
    CHECK(loop.node.mode() == Mode::hold);
    // The request came while cycle 2000 waited: seen at the next cycle's start; the machine slows
    // along its path (at most (pi / 2) stop_ramp_time) and holds, and the run ends stop_hold_s after
    // the hold began, so the machine stands for all of it.
    REQUIRE(bus.hold_from > 2001);
    CHECK(static_cast<double>(bus.hold_from - 2001) * 1e-3 <= 0.5 * M_PI * cfg.controller.path_clock.stop_ramp_time + 2e-3);
    CHECK(out.cycles >= bus.hold_from + 500);
    CHECK(out.cycles <= bus.hold_from + 503);
    MESSAGE("stop requested at cycle 2000: in hold from " << bus.hold_from << ", run ended at " << out.cycles);
  }
  {
    Loop loop(model, sim::kFreeMotionTask, cfg);
    AnsweringBus bus(loop);
    const std::atomic<int> stops{1};
    app::RunnerOptions run;
    run.cycles = 20000;
    run.stop_hold_s = 0.5;
    const app::RunnerOutcome out = app::run_firmware(loop.node, bus, run, stops, nullptr);
    CHECK(out.stop_requested);
    CHECK(out.cycles == 0);
    CHECK_FALSE(out.ok);
    CHECK(out.failure.find("never tracked") != std::string::npos);
  }
}

TEST_CASE("firmware/runner: a second stop request while holding ends the run at once") {
  const Model model = build_model(reference_machine());
  app::FirmwareNodeConfig cfg;
  cfg.controller.law = "pid";
  Loop loop(model, sim::kFreeMotionTask, cfg);
  struct TwoStops final : hal::CanBus {
    AnsweringBus inner;
    std::atomic<int> stops{0};
    explicit TwoStops(Loop& l) : inner(l) {}
    bool send(const hal::CanFrame& f) override { return inner.send(f); }
    bool receive(hal::CanFrame& f) override { return inner.receive(f); }
    bool wait_readable(std::int64_t t) override {
      const std::uint64_t k = inner.loop.node.cycle();
      if (k == 1000 || k == 1100) stops.fetch_add(1);
      return inner.wait_readable(t);
    }
  } bus(loop);
  app::RunnerOptions run;
  run.cycles = 20000;
  run.stop_hold_s = 5.0;
  const app::RunnerOutcome out = app::run_firmware(loop.node, bus, run, bus.stops, nullptr);
  CHECK(out.stop_requested);
  CHECK(out.cycles >= 1100);
  CHECK(out.cycles <= 1102);
  // Ended while the first stop was still slowing the path, or already holding.
  CHECK((loop.node.stopping_on_path() || loop.node.mode() == Mode::hold));
}

TEST_CASE("firmware/runner: a plant that never answers fails the run as never tracked, after the start-up wait of each cycle") {
  const Model model = build_model(reference_machine());
  app::FirmwareNodeConfig cfg;
  cfg.controller.law = "pid";
  Loop loop(model, sim::kFreeMotionTask, cfg);
  loop.answer = false;
  AnsweringBus bus(loop);
  app::RunnerOptions run;
  run.cycles = 5;
  run.startup_wait_ns = 2'000'000;
  const std::atomic<int> no_stop{0};
  const std::int64_t t0 = hal::monotonic_now_ns();
  const app::RunnerOutcome out = app::run_firmware(loop.node, bus, run, no_stop, nullptr);
  CHECK(hal::monotonic_now_ns() - t0 >= 5 * run.startup_wait_ns);  // each cycle waited its start-up time
  CHECK(out.cycles == 5);
  CHECK_FALSE(out.ok);
  CHECK(out.failure.find("never tracked") != std::string::npos);
}

TEST_CASE("firmware/runner: in real time a stalled cycle is a late wake-up, and a run allowed none fails naming its period first") {
  const Model model = build_model(reference_machine());
  app::FirmwareNodeConfig cfg;
  cfg.controller.law = "pid";
  for (const double allowed : {0.0, 1.0}) {
    Loop loop(model, sim::kFreeMotionTask, cfg);
    AnsweringBus bus(loop);
    bus.stall_at_cycle = 100;
    bus.stall_ns = 5'000'000;  // five periods: the next wake-up is late whatever the machine's load
    app::RunnerOptions run;
    run.cycles = 300;
    run.realtime = true;
    run.max_overrun_fraction = allowed;
    const std::atomic<int> no_stop{0};
    const app::RunnerOutcome out = app::run_firmware(loop.node, bus, run, no_stop, nullptr);
    INFO(out.failure);
    CHECK(out.cycles == 300);
    CHECK(out.overruns >= 1);
    CHECK(out.skipped_periods >= 4);
    // The lateness is named first, whatever else a loaded machine adds after it.
    const std::size_t late = out.failure.find(" of 300 cycles woke after their deadline");
    if (allowed == 0.0) {
      CHECK_FALSE(out.ok);
      CHECK(late != std::string::npos);
      CHECK(late < out.failure.find("; then "));
      CHECK(out.failure.find("cannot hold its 1 ms period") != std::string::npos);
    } else {
      CHECK(late == std::string::npos);
    }
  }
}

TEST_CASE("firmware/hold verdict names the function furthest past its tolerance, in multiples of it, and counts the others") {
  app::PhaseErrors hold;
  CHECK(app::hold_failure(hold).empty());  // every function within its tolerance
  // The swing 1.2 x its tolerance, first in order; the arm 3 x its own, later in order: the arm is named.
  hold.max_error[0] = 1.2 * app::kHoldingTolerance[0];
  hold.worst_time[0] = 4.0;
  hold.max_error[2] = 3.0 * app::kHoldingTolerance[2];
  hold.worst_time[2] = 7.5;
  hold.excursions[2] = 2;
  const std::string two = app::hold_failure(hold);
  CHECK(two.find("the arm left its held pose by 7.50 mm at 7.50 s") == 0);
  CHECK(two.find("2 excursion(s)") != std::string::npos);
  CHECK(two.find("and 1 other function left its own") != std::string::npos);
  // The bucket past its tolerance too, 1.5 x: the arm is still the furthest, two others counted.
  hold.max_error[3] = 1.5 * app::kHoldingTolerance[3];
  const std::string three = app::hold_failure(hold);
  CHECK(three.find("the arm left") == 0);
  CHECK(three.find("and 2 other functions left their own") != std::string::npos);
  // The swing alone: named, no others.
  app::PhaseErrors swing;
  swing.max_error[0] = 2 * app::kHoldingTolerance[0];
  swing.worst_time[0] = 1.0;
  const std::string one = app::hold_failure(swing);
  CHECK(one.find("the swing left its held pose by 5.00 mrad at 1.00 s") == 0);
  CHECK(one.find("other") == std::string::npos);
}
