// PlantNode, the simulated machine's end of the bus, with the firmware's port on the other end of an
// in-memory bus: what SENS_MACHINE carries of the plant's sensors (every chamber and both pumps when
// hydraulic, PressureValid), and CMD_PILOT applied to the plant as pilot commands.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "hal/memory_bus.hpp"
#include "plant_scenes.hpp"
#include "sim_plant/plant_node.hpp"

using namespace exc;
using namespace exc::plant;

namespace {

// The firmware's port and a PlantNode on one memory bus.
struct NodeBench {
  Plant plant;
  hal::MemoryBusHub hub;
  hal::MemoryBusNode* fw_bus = hub.attach();
  hal::MemoryBusNode* plant_bus = hub.attach();
  hal::FirmwareCanPort firmware{*fw_bus};
  hal::PlantCanPort port{*plant_bus};
  plant::PlantNode node{plant, port, nullptr};
  explicit NodeBench(const Scene& scene) : plant(scene) {}
  // One cycle: SYNC(k), the plant's step and answer, the firmware's read, then its command.
  bool cycle(std::uint64_t k, const hal::CommandState& command, hal::SensorState& seen) {
    firmware.send_sync(k);
    REQUIRE(node.poll());
    const bool complete = firmware.read(seen);
    hal::CommandState c = command;
    c.cycle = k;
    firmware.write(c);
    return complete;
  }
};

// plant_scenes.hpp's test scene on the hydraulic machine.
Scene hydraulic_scene_text() {
  plant::test::SceneText t;
  t.actuators = "fidelity: hydraulic";
  return t.scene();
}

hal::CommandState boom_pilots(double a, double b) {
  hal::CommandState c;
  c.mode = hal::CommandMode::pilot;
  c.pilot_a[hal::kBoom] = a;
  c.pilot_b[hal::kBoom] = b;
  return c;
}

// Cycles 0..299 with the boom raised on its pilots (3 MPa against 1): the cycle that comes next.
std::uint64_t raise_boom(NodeBench& bench, hal::SensorState& seen) {
  std::uint64_t k = 0;
  for (; k < 300; ++k) bench.cycle(k, boom_pilots(3e6, 1e6), seen);
  return k;
}

}  // namespace

TEST_CASE("plant/node: CMD_PILOT drives the hydraulic plant as pilot commands, step for step as the plant driven directly") {
  const Scene scene = hydraulic_scene_text();
  NodeBench bench(scene);
  // The same commands straight into a second plant: cycle 0 holds (no command yet: valves centred),
  // from cycle 1 on the firmware's pilots of the previous cycle. 3 MPa and 1 MPa are whole steps of
  // the 2 kPa signal, so the bus carries them exactly.
  Plant direct(scene);
  ActuatorCommand centred;
  centred.mode = ActuatorCommand::valve;
  ActuatorCommand pilots;
  pilots.mode = ActuatorCommand::pilot;
  pilots.pilot_a[1] = 3e6;
  pilots.pilot_b[1] = 1e6;
  hal::SensorState seen;
  const double l0 = scene.q_a0[1];
  for (std::uint64_t k = 0; k < 600; ++k) {
    REQUIRE(bench.cycle(k, boom_pilots(3e6, 1e6), seen));
    REQUIRE(direct.step(k == 0 ? centred : pilots).ok());
    REQUIRE_FALSE(bench.node.failed());
    REQUIRE(bench.plant.state().q_a == direct.state().q_a);  // bit for bit
  }
  const double full = scene.machine.hydraulics.pilot_full_stroke;
  MESSAGE("boom " << l0 << " -> " << bench.plant.state().q_a[1] << " m in 0.6 s; spool " << bench.plant.state().spool[1]
                  << " (pilot difference / full stroke " << 2e6 / full << ")");
  CHECK(bench.plant.state().q_a[1] > l0 + 0.01);  // A end above B end: the boom extends
  CHECK(bench.plant.state().spool[1] == doctest::Approx(2e6 / full).epsilon(1e-3));
  CHECK(bench.port.rx_stats().rejected() == 0);
}

TEST_CASE("plant/node: a jammed actuator on the hydraulic machine is a stuck spool: it stays where it was whatever the pilots or the safe state's centred valves ask, and follows them again once freed") {
  NodeBench bench(hydraulic_scene_text());
  hal::SensorState seen;
  std::uint64_t k = raise_boom(bench, seen);
  const double open = bench.plant.state().spool[1];
  REQUIRE(open > 0.1);
  plant::InjectedFault jam;
  jam.kind = plant::InjectedFault::Kind::actuator_jam;
  jam.joint = hal::kBoom;
  bench.node.set_fault(jam);
  hal::CommandState centred;
  centred.mode = hal::CommandMode::valve;  // the firmware's safe state
  for (; k < 600; ++k) {
    bench.cycle(k, k < 450 ? boom_pilots(0, 4e6) : centred, seen);
    REQUIRE(bench.plant.state().spool[1] == doctest::Approx(open).epsilon(1e-9));
  }
  bench.node.set_fault(plant::InjectedFault{});
  for (; k < 900; ++k) bench.cycle(k, boom_pilots(0, 4e6), seen);
  MESSAGE("spool stuck at " << open << ", freed: " << bench.plant.state().spool[1]);
  CHECK(bench.plant.state().spool[1] < -0.1);
}

TEST_CASE("plant/node: a cycle whose SYNC was lost coasts: the machine moves on one step with the command it holds and the node sends nothing") {
  NodeBench bench(hydraulic_scene_text());
  hal::SensorState seen;
  raise_boom(bench, seen);
  const double time = bench.plant.state().time, boom = bench.plant.state().q_a[1];
  bench.node.coast();
  CHECK(bench.plant.state().time == doctest::Approx(time + bench.plant.scene().cycle));
  CHECK(bench.plant.state().q_a[1] > boom);  // still extending
  hal::CanFrame frame;
  CHECK_FALSE(bench.fw_bus->receive(frame));
  CHECK(bench.node.steps() == 301);
}

TEST_CASE("plant/node: SENS_MACHINE carries every chamber and both pump pressures of the hydraulic plant's sensors, PressureValid 1") {
  NodeBench bench(hydraulic_scene_text());
  hal::SensorState seen;
  for (std::uint64_t k = 0; k < 300; ++k) {
    REQUIRE(bench.cycle(k, boom_pilots(4e6, 0), seen));
    const SensorReading& r = bench.plant.sensors();
    CHECK(seen.pressure_valid);
    // 1 kPa per bit: within half of it.
    CHECK(std::fabs(seen.pressure_a[hal::kSwing] - r.swing_pressure[0]) <= 500);
    CHECK(std::fabs(seen.pressure_b[hal::kSwing] - r.swing_pressure[1]) <= 500);
    for (int c = 0; c < 3; ++c) {
      CHECK(std::fabs(seen.pressure_a[c + 1] - r.pressure_a[c]) <= 500);
      CHECK(std::fabs(seen.pressure_b[c + 1] - r.pressure_b[c]) <= 500);
    }
    for (int p = 0; p < 2; ++p) CHECK(std::fabs(seen.pump_pressure[p] - r.pump_pressure[p]) <= 500);
    for (int j = 0; j < 4; ++j) CHECK(std::fabs(seen.position[j] - r.position[j]) <= (j == 0 ? 0.5e-6 : 0.5e-5));
  }
  // Pressures that mean something: the boom's bore side holds the boom up, the pumps above the load.
  CHECK(seen.pressure_a[hal::kBoom] > 5e6);
  CHECK(seen.pump_pressure[0] > seen.pressure_a[hal::kBoom]);
}

TEST_CASE("plant/node: a force-commanded plant sends PressureValid 0, and stops on pilot commands with the plant's message") {
  plant::test::SceneText t;
  t.actuators = "fidelity: ideal";
  NodeBench bench(t.scene());
  hal::SensorState seen;
  hal::CommandState effort;
  effort.mode = hal::CommandMode::effort;
  REQUIRE(bench.cycle(0, effort, seen));
  CHECK_FALSE(seen.pressure_valid);
  REQUIRE(bench.cycle(1, boom_pilots(3e6, 0), seen));
  // The pilots of cycle 1 reach the plant at SYNC(2): it stops, says why, and goes silent.
  bench.firmware.send_sync(2);
  REQUIRE(bench.node.poll());
  CHECK(bench.node.failed());
  const std::string why = bench.plant.status().text();
  MESSAGE(why);
  CHECK(why.find("pilot commands for actuators.fidelity ideal") != std::string::npos);
  CHECK_FALSE(bench.firmware.read(seen));
}

TEST_CASE("plant/node: a spool_stuck fault holds a spool at its opening whatever CMD_PILOT asks, the others follow their pilots, and its end frees it") {
  NodeBench bench(hydraulic_scene_text());
  plant::InjectedFault stuck;
  stuck.kind = plant::InjectedFault::Kind::spool_stuck;
  stuck.joint = 1;
  stuck.magnitude = -0.4;
  bench.node.set_fault(stuck);
  hal::CommandState c = boom_pilots(3e6, 0);  // the boom asked to extend ...
  c.pilot_a[hal::kArm] = 2e6;                 // ... and the arm too
  hal::SensorState seen;
  const double l0 = bench.plant.scene().q_a0[1];
  for (std::uint64_t k = 0; k < 300; ++k) REQUIRE(bench.cycle(k, c, seen));
  const PlantState& s = bench.plant.state();
  const double full = bench.plant.scene().machine.hydraulics.pilot_full_stroke;
  CHECK(s.spool[1] == -0.4);                                              // stuck, lowering the boom
  CHECK(s.q_a[1] < l0 - 0.01);
  CHECK(s.spool[2] == doctest::Approx(2e6 / full).epsilon(1e-3));         // the arm's spool follows
  bench.node.set_fault(plant::InjectedFault{});
  for (std::uint64_t k = 300; k < 600; ++k) REQUIRE(bench.cycle(k, c, seen));
  CHECK(bench.plant.state().spool[1] == doctest::Approx(3e6 / full).epsilon(1e-3));  // free again
  CHECK_FALSE(bench.node.failed());
}

TEST_CASE("plant/node: a lost link cuts the pilot supply as an autonomy kit's receiver does: a boom on a spool stuck lowering is held by its load-holding valve, the engine runs on, and the supply returns with the commands") {
  // The firmware commands, then falls silent (SYNC goes on: a firmware that hangs, a cut command
  // line). The plant's command watchdog holds after 20 cycles; centred valves alone do not stop a
  // boom whose spool is stuck lowering (it sinks on), the pilot cut closes its load-holding valve.
  NodeBench bench(hydraulic_scene_text());
  hal::SensorState seen;
  std::uint64_t k = raise_boom(bench, seen);  // raise the boom a little
  plant::InjectedFault stuck;
  stuck.kind = plant::InjectedFault::Kind::spool_stuck;
  stuck.joint = hal::kBoom;
  stuck.magnitude = -0.5;  // lowering, whatever is commanded
  bench.node.set_fault(stuck);
  hal::CommandState centred;
  centred.mode = hal::CommandMode::valve;
  for (; k < 400; ++k) bench.cycle(k, centred, seen);
  REQUIRE(bench.plant.state().qd_a[1] < -0.01);  // sinking on the stuck spool
  CHECK((seen.plant_state & hal::kPlantStatePilotCut) == 0);
  // Silent from here: SYNC and the plant's answer only.
  double q_mark = 0;
  const std::uint64_t silent_from = k;
  for (; k < silent_from + 2500; ++k) {
    bench.firmware.send_sync(k);
    REQUIRE(bench.node.poll());
    bench.firmware.read(seen);
    if (k == silent_from + 1500) q_mark = bench.plant.state().q_a[1];
    if (k == silent_from + 25) {
      CHECK((seen.plant_state & hal::kPlantStateHolding) != 0);
      CHECK((seen.plant_state & hal::kPlantStatePilotCut) != 0);
    }
  }
  const double creep = (bench.plant.state().q_a[1] - q_mark) / (1000 * bench.plant.scene().cycle);
  const plant::HydraulicReport& h = bench.plant.state().hydraulics;
  MESSAGE("link lost with the boom's spool stuck at -0.5: pilot supply " << h.pilot_supply << ", engine flow " << h.engine_flow
                                                                          << ", load-holding valves closed " << h.holding_valves_closed
                                                                          << ", boom " << creep * 1e3 << " mm/s 1.5-2.5 s after");
  CHECK(h.pilot_supply < 1e-3);
  CHECK(h.engine_flow == 1);  // the engine runs on: only the enable dropped
  CHECK(h.holding_valves_closed);
  CHECK(std::abs(creep) < 1e-3);  // at rest by the campaign's measure
  // The commands return: the supply comes back and the bit clears.
  for (std::uint64_t end = k + 500; k < end; ++k) bench.cycle(k, centred, seen);
  CHECK(bench.plant.state().hydraulics.pilot_supply > 0.99);
  CHECK((seen.plant_state & hal::kPlantStatePilotCut) == 0);
}
