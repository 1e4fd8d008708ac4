// The chamber pressures' plausibility monitor (firmware/safety/pressure_plausibility.hpp,
// docs/safety.md H4) against the plant's pressure sensor faults, firmware and plant in lockstep: a
// stuck, a jumping and a drifting (out of range) transmitter are each found, by their own test, within
// a bound in sensor sets stated from the monitor's settings; and without a fault the monitor never
// trips on the shipped hydraulic scenes under every law they run, its margins printed.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "app/firmware_node.hpp"
#include "sim_plant/plant_node.hpp"
#include "harness/lockstep_run.hpp"
#include "plant_scenes.hpp"

using namespace exc;

namespace {

const char* const kLaws[] = {"pid", "adaptive",
                                             "slotine_li", "flow"};

// The sensor sets from the fault's start to its detection: the plant applies it from the set of the
// cycle after the start.
int sets_to_detection(const sim::RunRecord& r, double start, double cycle) {
  return static_cast<int>(std::lround((r.first_fault_detected_time - start) / cycle));
}

}  // namespace

TEST_CASE("firmware/pressure plausibility: a stuck, a jumping and a drifting chamber pressure are found by their test within their bound in sensor sets, the controlled stop taken") {
  const sim::SceneBundle b = sim::load_scene_bundle(EXC_SOURCE_DIR "/scenes/dig.yaml");
  const safety::PressurePlausibilitySettings& s = b.firmware.controller.supervisor.pressure_plausibility;
  const double dt = b.scene.cycle;
  const double start = 2.0;  // s: the dig's bucket and arm are in the soil and moving
  int worst_stuck = 0, worst_jump = 0, worst_drift = 0, escalations = 0, found_cases = 0, skipped_cases = 0, found_by_motion = 0;
  for (const std::string law : {"pid", "adaptive"}) {
    for (int joint = 1; joint < 4; ++joint) {
      for (int chamber = 0; chamber < 2; ++chamber) {
        for (const sim::FaultSchedule::Kind kind : {sim::FaultSchedule::Kind::pressure_stuck, sim::FaultSchedule::Kind::pressure_jump,
                                                    sim::FaultSchedule::Kind::pressure_drift}) {
          sim::LockstepOptions o;
          o.controller = law;
          o.duration = start + 1.5;
          o.fault.kind = kind;
          o.fault.start = start;
          o.fault.duration = 1e9;
          o.fault.joint = joint;
          o.fault.chamber = chamber;
          // A jump far beyond what the oil makes in a few sets; a drift far below it per set, so only
          // the range test can find it.
          o.fault.magnitude = kind == sim::FaultSchedule::Kind::pressure_jump ? 15e6 : 60e6;
          double p0 = 0, allowed = 0;
          bool sampled = false;
          int crossed = -1;  // drift: the first faulty set whose reading, truth plus drift, is past the top
          int moving_sets = 0, moving_complete = -1;  // stuck: faulty sets in which the function moves
          bool escalated = false;
          const double top = s.range_margin + b.scene.machine.hydraulics.relief_override +
                             std::max(b.scene.machine.hydraulics.port_relief_pressure, b.scene.machine.hydraulics.pump_pressure_limit());
          o.node_observer = [&](std::int64_t, const plant::PlantNode& plant, const app::FirmwareNode& node) {
            escalated = escalated || node.supervisor().stop_escalated();
            if (!sampled && node.time() >= start - 1e-9) {
              sampled = true;
              p0 = (chamber == 0 ? node.sensors().pressure_a : node.sensors().pressure_b)[static_cast<std::size_t>(joint)];
              allowed = node.supervisor().pressure_plausibility().step_allowed(2 * joint + chamber);
            }
            const long n = std::lround((node.time() - start) / dt);
            const double truth = (chamber == 0 ? plant.plant().state().pressure_a : plant.plant().state().pressure_b)[joint];
            const double moving_speed = s.moving_share * b.scene.machine.speed_max()[joint];
            if (n >= 1 && std::abs(node.sensors().velocity[static_cast<std::size_t>(joint)]) > moving_speed &&
                ++moving_sets == s.frozen_sets)
              moving_complete = static_cast<int>(n);
            if (kind == sim::FaultSchedule::Kind::pressure_drift && n >= 1 && crossed < 0 &&
                truth + o.fault.magnitude * static_cast<double>(n) * dt > top)
              crossed = static_cast<int>(n);
          };
          const sim::RunRecord r = sim::run_lockstep(b.scene, b.firmware, o);
          const std::string name = law + ", " + kActiveNames[static_cast<std::size_t>(joint)] +
                                   (chamber == 0 ? " A" : " B") + ", " + sim::to_string(kind);
          INFO(name << ": " << r.failure);
          // A return side at the tank's level is where the circuit itself holds a chamber: a reading
          // stuck there is plausible (and misstates the force by at most that level times the area).
          const double clamp_low = b.scene.machine.hydraulics.tank_pressure;
          if (kind == sim::FaultSchedule::Kind::pressure_stuck && p0 <= clamp_low) {
            MESSAGE(name << ": at the tank's level (" << p0 * 1e-6 << " MPa) when it stuck: "
                         << (r.first_safe_stop_time >= 0 ? r.failure : std::string("not found")));
            ++skipped_cases;
            continue;
          }
          // A jump the oil could make within the debounce is no fault by the step test (a stiff, small
          // chamber: a cylinder near its end).
          if (kind == sim::FaultSchedule::Kind::pressure_jump && !(o.fault.magnitude > s.debounce * allowed + 1e3)) {
            MESSAGE(name << ": " << o.fault.magnitude * 1e-6 << " MPa is within " << s.debounce << " sets' allowance of "
                         << allowed * 1e-6 << " MPa: " << (r.first_safe_stop_time >= 0 ? r.failure : std::string("not found")));
            ++skipped_cases;
            continue;
          }
          REQUIRE(r.first_safe_stop_time >= 0);
          // A drifting reading feeds the valve stage's orifice map, so the function can move off its
          // path before the reading leaves the range: then the flow monitor finds the motion first
          // and takes its emergency stop. Allowed only if it came before the range test's bound.
          if (kind == sim::FaultSchedule::Kind::pressure_drift &&
              r.first_fault_code == static_cast<int>(safety::FirmwareFault::velocity_implausible)) {
            REQUIRE(crossed > 0);
            const int sets = sets_to_detection(r, start, dt);
            MESSAGE(name << ": the motion it caused found by the flow monitor after " << sets << " sensor sets, before the range test's "
                         << crossed + s.debounce - 1 << " (" << r.failure << ")");
            CHECK(sets < crossed + s.debounce - 1);
            CHECK(r.estop);
            ++found_by_motion;
            ++found_cases;
            continue;
          }
          CHECK(r.first_fault_code == static_cast<int>(safety::FirmwareFault::pressure_implausible));
          // The controlled stop: the valves obey and the position sensors watch the stop; the standstill
          // monitor escalates it when the machine does not stand still (printed, counted).
          CHECK(safety::stop_of(static_cast<safety::FirmwareFault>(r.first_fault_code)) == safety::StopKind::controlled);
          CHECK(r.estop == escalated);
          escalations += escalated ? 1 : 0;
          ++found_cases;
          const int sets = sets_to_detection(r, start, dt);
          MESSAGE(name << ": found after " << sets << " sensor sets" << std::string(escalated ? ", the stop escalated" : "") << " ("
                       << r.failure << ")");
          if (kind == sim::FaultSchedule::Kind::pressure_stuck) {
            // Bound: the set in which the function has moved (the test's own count of the sensed
            // velocity) in frozen_sets sets since the fault's start.
            CHECK(r.failure.find("frozen") != std::string::npos);
            REQUIRE(moving_complete > 0);
            CHECK(sets >= s.frozen_sets);
            CHECK(std::abs(sets - moving_complete) <= 1);
            worst_stuck = std::max(worst_stuck, sets);
          } else if (kind == sim::FaultSchedule::Kind::pressure_jump) {
            // Bound: the debounce, as long as the jump exceeds debounce x the step allowance (and the
            // bus's 1 kPa quantum).
            CHECK(r.failure.find("jumped") != std::string::npos);
            CHECK(sets == s.debounce);
            worst_jump = std::max(worst_jump, sets);
          } else {
            // Bound: the sets the drift needs to carry the reading from p0 past the top, then the
            // debounce (the bus's 1 kPa quantum aside).
            // Bound: the set the reading (the plant's true pressure plus the drift) passes the top,
            // then the debounce; one set either way for the bus's 1 kPa quantum.
            CHECK(r.failure.find("out of range") != std::string::npos);
            REQUIRE(crossed > 0);
            CHECK(std::abs(sets - (crossed + s.debounce - 1)) <= 1);
            worst_drift = std::max(worst_drift, sets - crossed + 1);
          }
        }
      }
    }
  }
  CHECK(found_cases >= 24);  // of 36: the skipped ones printed above
  CHECK(found_by_motion <= 2);  // a drift is the range test's to find: the motion's monitor is the exception
  MESSAGE(found_cases << " found (" << found_by_motion << " by the motion it caused), " << skipped_cases << " not judged (printed above), " << escalations << " stops escalated");
  MESSAGE("pressure faults on the dig (PID, adaptive; boom, arm, bucket; both chambers): stuck found after at most "
          << worst_stuck << " sets (frozen_sets " << s.frozen_sets << "), a 15 MPa jump after at most " << worst_jump
          << " (debounce " << s.debounce << "), a 60 MPa/s drift at most " << worst_drift << " sets after crossing the top");
}

TEST_CASE("firmware/pressure plausibility: without a fault the pressure monitor never trips on the shipped hydraulic scenes under every law they run, its margins printed") {
  for (const auto& sc : plant::test::kShippedHydraulicScenes) {
    const sim::SceneBundle b = sim::load_scene_bundle(std::string(EXC_SOURCE_DIR "/scenes/") + sc.scene);
    REQUIRE(b.firmware.controller.command_interface == control::CommandInterface::valve);
    for (const std::string law : kLaws) {
      // Flow-based control lags a moving swing past its tracking limit: not run there.
      if (law == "flow" && sc.swing_moves) continue;
      double worst_step = 0;
      int longest_frozen = 0;
      sim::LockstepOptions o;
      o.controller = law;
      o.node_observer = [&](std::int64_t, const plant::PlantNode&, const app::FirmwareNode& node) {
        for (int c = 0; c < safety::PressurePlausibility::kChambers; ++c) {
          worst_step = std::max(worst_step, node.supervisor().pressure_plausibility().worst_step_ratio(c));
          longest_frozen = std::max(longest_frozen, node.supervisor().pressure_plausibility().longest_frozen(c));
        }
      };
      const sim::RunRecord r = sim::run_lockstep(b.scene, b.firmware, o);
      const std::string what = std::string(sc.scene) + ", " + law;
      INFO(what << ": " << r.failure);
      const auto& limits = b.firmware.controller.supervisor.pressure_plausibility;
      MESSAGE(what << ": largest step / allowance " << worst_step << ", longest frozen run while moving " << longest_frozen
                   << " sets (of " << limits.frozen_sets << "), chamber pressures " << r.min_pressure * 1e-6 << " .. "
                   << r.peak_pressure * 1e-6 << " MPa" << (r.safe_stops ? " (safe stop: " + r.failure + ")" : ""));
      CHECK(r.first_fault_code != static_cast<int>(safety::FirmwareFault::pressure_implausible));
      CHECK(worst_step < 1);
      CHECK(longest_frozen < limits.frozen_sets);
    }
  }
}

TEST_CASE("firmware/pressure plausibility: with 5 kPa of noise on the readings a stuck transmitter is still found frozen in frozen_sets moving sets, and the healthy run never trips") {
  // Noise moves every live reading off its last value; a stuck transmitter sends one value however
  // the truth moves, so the frozen test finds it as without noise (docs/safety.md, H4's failure
  // region: slow paths).
  sim::SceneBundle b = sim::load_scene_bundle(EXC_SOURCE_DIR "/scenes/dig.yaml");
  b.scene.sensors.pressure_noise = 5e3;
  const safety::PressurePlausibilitySettings& s = b.firmware.controller.supervisor.pressure_plausibility;
  const double dt = b.scene.cycle, start = 2.0;
  {
    sim::LockstepOptions o;
    o.controller = "pid";
    int longest = 0;
    o.node_observer = [&](std::int64_t, const plant::PlantNode&, const app::FirmwareNode& node) {
      for (int c = 0; c < safety::PressurePlausibility::kChambers; ++c)
        longest = std::max(longest, node.supervisor().pressure_plausibility().longest_frozen(c));
    };
    const sim::RunRecord r = sim::run_lockstep(b.scene, b.firmware, o);
    INFO(r.failure);
    CHECK(r.safe_stops == 0);
    MESSAGE("dig with 5 kPa of pressure noise, PID: longest bit-identical reading while moving " << longest << " sets");
    // Two readings with 5 quanta of noise are equal about once in 18: twenty in a row, once in 10^24.
    CHECK(longest < 20);
  }
  int judged = 0;
  for (const int joint : {1, 2, 3}) {
    for (const int chamber : {0, 1}) {
      sim::LockstepOptions o;
      o.controller = "pid";
      o.duration = start + 1.5;
      o.fault.kind = sim::FaultSchedule::Kind::pressure_stuck;
      o.fault.start = start;
      o.fault.duration = 1e9;
      o.fault.joint = joint;
      o.fault.chamber = chamber;
      int moving_sets = 0, moving_complete = -1;
      double p0 = -1;
      o.node_observer = [&](std::int64_t, const plant::PlantNode&, const app::FirmwareNode& node) {
        if (p0 < 0 && node.time() >= start - 1e-9)
          p0 = (chamber == 0 ? node.sensors().pressure_a : node.sensors().pressure_b)[static_cast<std::size_t>(joint)];
        const long n = std::lround((node.time() - start) / dt);
        if (n >= 1 && std::abs(node.sensors().velocity[static_cast<std::size_t>(joint)]) >
                          s.moving_share * b.scene.machine.speed_max()[joint] &&
            ++moving_sets == s.frozen_sets)
          moving_complete = static_cast<int>(n);
      };
      const sim::RunRecord r = sim::run_lockstep(b.scene, b.firmware, o);
      CAPTURE(joint);
      CAPTURE(chamber);
      INFO(r.failure);
      // At the tank's level the circuit holds a chamber: a reading stuck within the noise of it is
      // plausible (as without noise: the boom's rod side in the dig).
      if (p0 <= b.scene.machine.hydraulics.tank_pressure + 4 * b.scene.sensors.pressure_noise) {
        MESSAGE(std::string(kActiveNames[static_cast<std::size_t>(joint)]) << (chamber == 0 ? " A" : " B") << " stuck at " << p0 * 1e-6
                                                            << " MPa, the tank's level: not judged");
        continue;
      }
      ++judged;
      REQUIRE(r.first_safe_stop_time >= 0);
      CHECK(r.failure.find("frozen") != std::string::npos);
      REQUIRE(moving_complete > 0);
      CHECK(std::abs(sets_to_detection(r, start, dt) - moving_complete) <= 1);
    }
  }
  CHECK(judged >= 4);
}
