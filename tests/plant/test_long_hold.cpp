// A cycle's cost must not depend on the run's history (docs/floating-point.md). The dig
// scene's path ends at 10.05 s and the machine then holds; in a long hold the decaying states of the
// firmware and the plant fell into the subnormal range, which this processor computes many times
// slower. Counted, not timed: every value either node carries from one cycle to the next is looked
// at after every cycle of a 150 s run, for each law, in the loop's mode (none may be subnormal), and
// with gradual underflow (the scan must find the decayed states: it can see them). The instruction
// count per cycle late in a hold against early in it is in test_hold_instructions.cpp.
#include <doctest/doctest.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "app/firmware_node.hpp"
#include "app/float_environment.hpp"
#include "diagnostics/subnormal_scan.hpp"
#include "harness/lockstep_run.hpp"
#include "sim_plant/plant_node.hpp"

using namespace exc;

namespace {

struct HoldScan {
  sim::RunRecord run;
  diagnostics::SubnormalScan firmware, plant;
  std::uint64_t underflow_cycles = 0;  // cycles in which the FPU flushed (or rounded) a tiny result
  std::uint64_t cycles_not_in_mode = 0;  // cycles the loop's thread was not in the run's mode
};

HoldScan hold(const std::string& law, double duration, app::FloatMode mode) {
  const sim::SceneBundle b = sim::load_scene_bundle(std::string(EXC_SOURCE_DIR) + "/scenes/dig.yaml");
  HoldScan h;
  sim::LockstepOptions o;
  o.controller = law;
  o.duration = duration;
  o.float_mode = mode;
  o.node_observer = [&h, &b, mode](std::int64_t k, const plant::PlantNode& plant, const app::FirmwareNode& firmware) {
    const double t = static_cast<double>(k + 1) * b.scene.cycle;
    if (app::take_underflow_flag()) ++h.underflow_cycles;
    if (app::float_mode_of_thread() != mode) ++h.cycles_not_in_mode;
    h.firmware.set_time(t);
    h.plant.set_time(t);
    firmware.scan_state(h.firmware);
    plant.scan_state(h.plant);
  };
  app::take_underflow_flag();
  h.run = sim::run_lockstep(b.scene, b.firmware, o);
  return h;
}

// Each state found subnormal: where, its first value, when, how many values in all.
std::string where(const diagnostics::SubnormalScan& s) {
  if (s.found() == 0) return "none";
  std::string out = std::to_string(s.found()) + " subnormal values:";
  char b[200];
  for (const diagnostics::SubnormalScan::Finding* f = s.names_begin(); f != s.names_end(); ++f) {
    std::snprintf(b, sizeof b, "\n    %s[%zu] = %g from t = %.3f s (%llu values)", f->name, f->index, f->value, f->time,
                  static_cast<unsigned long long>(f->count));
    out += b;
  }
  return out;
}

void check_no_subnormal_in_hold(const std::string& law) {
  const app::FloatMode caller = app::float_mode_of_thread();
  const HoldScan h = hold(law, 150, app::FloatMode::flush_subnormals);
  CHECK(app::float_mode_of_thread() == caller);  // the run's mode was the run's only
  INFO("law ", law, ": ", h.run.failure);
  REQUIRE(h.run.ok);
  REQUIRE(h.run.task_finished);  // the path ended at 10.05 s: the rest of the run is a hold
  CHECK(h.run.simulated_seconds == doctest::Approx(150));
  CHECK(h.cycles_not_in_mode == 0);
  CHECK(h.firmware.scanned() > 150000 * 100);  // every cycle, every visited value
  CHECK(h.plant.scanned() > 150000 * 100);
  // The scans ran after every cycle inside the run's allocation count, and allocate nothing there.
  CHECK(h.run.heap_allocations_in_loop == 0);
  INFO("firmware: ", where(h.firmware));
  INFO("plant: ", where(h.plant));
  CHECK(h.firmware.found() == 0);
  CHECK(h.plant.found() == 0);
  const double cycles = h.run.simulated_seconds * 1000;
  MESSAGE(law, ": ", static_cast<double>(h.firmware.scanned()) / cycles, " firmware and ",
          static_cast<double>(h.plant.scanned()) / cycles, " plant values scanned per cycle; the FPU flushed a tiny result to zero in ",
          h.underflow_cycles, " of ", cycles, " cycles; control step median ", h.run.first_second.control_step.median_us,
          " us in the first second, ", h.run.last_second.control_step.median_us, " us in the last");
}

}  // namespace

TEST_CASE("firmware/a 150 s hold on the dig scene leaves no subnormal in the firmware's or the plant's state (pid)") {
  check_no_subnormal_in_hold("pid");
}

TEST_CASE("firmware/a 150 s hold on the dig scene leaves no subnormal in the firmware's or the plant's state (adaptive)") {
  check_no_subnormal_in_hold("adaptive");
}

TEST_CASE("firmware/a 150 s hold on the dig scene leaves no subnormal in the firmware's or the plant's state (flow)") {
  check_no_subnormal_in_hold("flow");
}

// The control: the same hold with the processor's default (gradual underflow) leaves the states that
// decay there subnormal, and the scan names them. A scan that missed them would pass above for nothing.
TEST_CASE("firmware/with gradual underflow a 60 s hold leaves subnormals in both nodes' state, and the scan finds them (adaptive)") {
  const HoldScan h = hold("adaptive", 60, app::FloatMode::ieee);
  REQUIRE(h.run.ok);
  CHECK(h.cycles_not_in_mode == 0);
  MESSAGE("firmware: ", where(h.firmware));
  MESSAGE("plant: ", where(h.plant));
  CHECK(h.firmware.found() > 0);
  CHECK(h.plant.found() > 0);
  CHECK(h.firmware.first().time > 10.05);  // in the hold, not while tracking
  CHECK(h.plant.first().time > 10.05);
}
