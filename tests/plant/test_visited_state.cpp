// The plant's state types each show every double they hold to a state visitor, once (visit_state
// beside each declaration: PlantNode::scan_state's subnormal scan is fed by them,
// docs/floating-point.md). A double member added to one of them and not to its visit_state fails
// here (tests/support/visited_doubles.hpp says how).
#include <doctest/doctest.h>

#include "sim_plant/hydraulics.hpp"
#include "sim_plant/plant.hpp"
#include "sim_plant/sensors.hpp"
#include "visited_doubles.hpp"

using namespace exc;

namespace exc::test {

// Doubles only: every 8 bytes.
template <>
struct NestedFill<plant::HydraulicEnergy> {
  static void fill(SubnormalFill& f, plant::HydraulicEnergy& e) { f.every_slot("HydraulicEnergy", e); }
};

template <>
struct NestedFill<plant::HydraulicReport> {
  static void fill(SubnormalFill& f, plant::HydraulicReport& h) {
    EXC_FILL_EVERY_MEMBER(f, h, pump_pressure, pump_flow, flow_scale, opening, meter_in_flow, meter_out_flow, makeup_flow,
                          relief_flow, leakage_flow, piston_leakage_flow, relief_substeps, saturated_substeps,
                          cavitation_substeps, min_pressure, max_pressure, solver_iterations, pilot_supply, engine_flow,
                          pump_line_open, holding_valves_closed, bucket_holding_valve_closed, swing_brake_applied, energy);
  }
};

}  // namespace exc::test

TEST_CASE("plant/visit_state visits every double of HydraulicEnergy once") {
  plant::HydraulicEnergy e;
  test::SubnormalFill fill;
  fill.every_slot("HydraulicEnergy", e);
  const test::VisitAudit audit = test::audit_visit(e, fill);
  INFO(audit.text());
  CHECK(audit.set > 0);
  CHECK(audit.complete());
}

TEST_CASE("plant/visit_state visits every double of HydraulicReport once") {
  plant::HydraulicReport h;
  test::SubnormalFill fill;
  test::NestedFill<plant::HydraulicReport>::fill(fill, h);
  const test::VisitAudit audit = test::audit_visit(h, fill);
  INFO(audit.text());
  CHECK(audit.complete());
}

TEST_CASE("plant/visit_state visits every double of SensorReading once") {
  plant::SensorReading r;
  test::SubnormalFill fill;
  EXC_FILL_EVERY_MEMBER(fill, r, position, velocity, pressure_a, pressure_b, swing_pressure, pump_pressure, spool, cycle);
  const test::VisitAudit audit = test::audit_visit(r, fill);
  INFO(audit.text());
  CHECK(audit.complete());
}

TEST_CASE("plant/visit_state visits every double of PlantState once") {
  plant::PlantState s;
  test::SubnormalFill fill;
  EXC_FILL_EVERY_MEMBER(fill, s, time, cycle, q_a, qd_a, qdd_a, q, qd, tip_world, rho, rhod, soil_force, soil_anchor, in_soil, depth,
                        reanchor_count, effort, spool, pressure_a, pressure_b, hydraulics, kinetic_energy, potential_energy,
                        energy_error, actuator_work, soil_work, constraint_residual, end_stop_events, end_stop_loss,
                        friction_loss, friction_stuck, friction_sweeps, implicit_iterations);
  const test::VisitAudit audit = test::audit_visit(s, fill);
  INFO(audit.text());
  CHECK(audit.complete());
}
