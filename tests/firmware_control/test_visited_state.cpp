// The firmware's state types each show every double they hold to a state visitor, once
// (visit_state beside each declaration; the subnormal scan of FirmwareNode::scan_state and the
// plant's is fed by them, docs/floating-point.md). A double member added to one of these types and
// not to its visit_state fails here: the pure-double types through every 8 bytes of the object, the
// mixed ones through a structured binding of every member (which stops compiling when the type gains
// a member, until the test names it). tests/support/visited_doubles.hpp says how.
#include <doctest/doctest.h>

#include <array>

#include "app/control_step.hpp"
#include "control/control_types.hpp"
#include "hal/excavator_interface.hpp"
#include "model/machine_reader.hpp"
#include "model/model.hpp"
#include "model/workspace.hpp"
#include "visited_doubles.hpp"

using namespace exc;

namespace exc::test {

template <>
struct NestedFill<ModelReport> {
  static void fill(SubnormalFill& f, ModelReport& r) { EXC_FILL_EVERY_MEMBER(f, r, status, loop, conditioning); }
};

template <>
struct NestedFill<Workspace::PlanarLinks> {
  static void fill(SubnormalFill& f, Workspace::PlanarLinks& p) {
    EXC_FILL_EVERY_MEMBER(f, p, origin_y, alpha, acceleration, com, com_y, J_angle, J_origin, J_com, jacobians_valid);
  }
};

// Not visited: the Newton loop closure forms the factor and solves with it in one call (visit_state(Workspace)).
template <>
struct NestedFill<Eigen::PartialPivLU<Mat8>> {
  static void fill(SubnormalFill&, Eigen::PartialPivLU<Mat8>&) {}
};

}  // namespace exc::test

namespace {

// The audit's own control: a visit that leaves a double out, one that shows a double twice and one
// that shows a copy are each told, by name.
struct Probe {
  double a = 0;
  std::array<double, 2> b{};
  int n = 0;
  Vec2 c = Vec2::Zero();
};
enum class ProbeVisit { complete, leaves_out_b, shows_a_twice, shows_a_copy };
ProbeVisit probe_visit = ProbeVisit::complete;

template <typename Visitor>
void visit_state(const Probe& p, Visitor& v) {
  v.visit("probe a", p.a);
  if (probe_visit != ProbeVisit::leaves_out_b) v.visit("probe b", p.b);
  v.visit("probe c", p.c);
  if (probe_visit == ProbeVisit::shows_a_twice) v.visit("probe a again", p.a);
  if (probe_visit == ProbeVisit::shows_a_copy) {
    static double copy;
    copy = p.a;
    v.visit("probe a's copy", copy);
  }
}

test::VisitAudit audit_probe(ProbeVisit how) {
  probe_visit = how;
  Probe p;
  test::SubnormalFill fill;
  EXC_FILL_EVERY_MEMBER(fill, p, a, b, n, c);
  const test::VisitAudit audit = test::audit_visit(p, fill);
  probe_visit = ProbeVisit::complete;
  return audit;
}

// 32 bytes, no padding (Eigen aligns a Vec2 to 16).
struct Triple {
  Vec2 x = Vec2::Zero();
  double y = 0, z = 0;
};
bool triple_leaves_out_z = false;

template <typename Visitor>
void visit_state(const Triple& t, Visitor& v) {
  v.visit("triple x", t.x);
  v.visit("triple y", t.y);
  if (!triple_leaves_out_z) v.visit("triple z", t.z);
}

test::VisitAudit audit_triple(bool leave_out_z) {
  triple_leaves_out_z = leave_out_z;
  Triple t;
  test::SubnormalFill fill;
  fill.every_slot("Triple", t);
  const test::VisitAudit audit = test::audit_visit(t, fill);
  triple_leaves_out_z = false;
  return audit;
}

// The same size, an int in the last 8 bytes.
struct PairWithCount {
  Vec2 x = Vec2::Zero();
  double y = 0;
  int count = 0;
};

template <typename Visitor>
void visit_state(const PairWithCount& p, Visitor& v) {
  v.visit("pair x", p.x);
  v.visit("pair y", p.y);
}

test::VisitAudit audit_pair_with_int() {
  PairWithCount p;
  test::SubnormalFill fill;
  fill.every_slot("PairWithCount", p);
  return test::audit_visit(p, fill);
}

}  // namespace

TEST_CASE("firmware/the visit audit tells a double left out, one visited twice and a value not the object's, by name") {
  const test::VisitAudit complete = audit_probe(ProbeVisit::complete);
  INFO(complete.text());
  CHECK(complete.set == 5);
  CHECK(complete.complete());

  const test::VisitAudit left_out = audit_probe(ProbeVisit::leaves_out_b);
  INFO(left_out.text());
  CHECK_FALSE(left_out.complete());
  REQUIRE(left_out.missed.size() == 1);
  CHECK(left_out.missed[0] == "b (2 of its 2 doubles)");
  CHECK(left_out.scan_found == 3);

  const test::VisitAudit twice = audit_probe(ProbeVisit::shows_a_twice);
  INFO(twice.text());
  CHECK_FALSE(twice.complete());
  CHECK(twice.missed.empty());
  REQUIRE(twice.repeated.size() == 1);
  CHECK(twice.repeated[0] == "probe a again");

  const test::VisitAudit copy = audit_probe(ProbeVisit::shows_a_copy);
  INFO(copy.text());
  CHECK_FALSE(copy.complete());
  REQUIRE(copy.foreign.size() == 1);
  CHECK(copy.foreign[0] == "probe a's copy");

  // A type of doubles only, filled slot by slot: a member left out is named by its bytes, and so is
  // a member of another type that the every-slot fill took for a double.
  const test::VisitAudit triple = audit_triple(false);
  INFO(triple.text());
  CHECK(triple.set == 4);
  CHECK(triple.complete());
  const test::VisitAudit triple_left_out = audit_triple(true);
  INFO(triple_left_out.text());
  REQUIRE(triple_left_out.missed.size() == 1);
  CHECK(triple_left_out.missed[0] == "Triple bytes 24-31 (1 of its 1 doubles)");
  const test::VisitAudit with_int = audit_pair_with_int();
  INFO(with_int.text());
  REQUIRE(with_int.missed.size() == 1);
  CHECK(with_int.missed[0] == "PairWithCount bytes 24-31 (1 of its 1 doubles)");
}

TEST_CASE("firmware/visit_state visits every double of hal::SensorState once") {
  hal::SensorState s{};
  test::SubnormalFill fill;
  EXC_FILL_EVERY_MEMBER(fill, s, position, velocity, pressure_a, pressure_b, pump_pressure, spool, pressure_valid, plant_state,
                        plant_faults, plant_heartbeat_state, cycle, motion_valid, plant_emergency, plant_fault_code, supervisor_pending);
  const test::VisitAudit audit = test::audit_visit(s, fill);
  INFO(audit.text());
  CHECK(audit.set > 0);
  CHECK(audit.complete());
}

TEST_CASE("firmware/visit_state visits every double of hal::CommandState once") {
  hal::CommandState c{};
  test::SubnormalFill fill;
  EXC_FILL_EVERY_MEMBER(fill, c, mode, value, pilot_a, pilot_b, firmware_mode, cycle, valid, emergency_stop, fault_code);
  const test::VisitAudit audit = test::audit_visit(c, fill);
  INFO(audit.text());
  CHECK(audit.set > 0);
  CHECK(audit.complete());
}

// Doubles only: every 8 bytes of it, no list of members.
TEST_CASE("firmware/visit_state visits every double of app::DesiredMotion once") {
  app::DesiredMotion d;
  test::SubnormalFill fill;
  fill.every_slot("DesiredMotion", d);
  const test::VisitAudit audit = test::audit_visit(d, fill);
  INFO(audit.text());
  CHECK(audit.set > 0);
  CHECK(audit.complete());
}

TEST_CASE("firmware/visit_state visits every double of control::ControlOutput once") {
  control::ControlOutput o;
  test::SubnormalFill fill;
  EXC_FILL_EVERY_MEMBER(fill, o, tau, tau_unsaturated, saturated, e, ed, theta_hat, lyapunov, lyapunov_tracking, in_soil, rho,
                        rho_env, disturbance, tip_force, status, velocity_command, velocity);
  const test::VisitAudit audit = test::audit_visit(o, fill);
  INFO(audit.text());
  CHECK(audit.complete());
}

TEST_CASE("model/visit_state visits every double of ModelReport once") {
  ModelReport r;
  test::SubnormalFill fill;
  EXC_FILL_EVERY_MEMBER(fill, r, status, loop, conditioning);
  const test::VisitAudit audit = test::audit_visit(r, fill);
  INFO(audit.text());
  CHECK(audit.set > 0);
  CHECK(audit.complete());
}

TEST_CASE("model/visit_state visits every double of Workspace once") {
  const Model model = build_model(reference_machine());
  Workspace w(model);
  test::SubnormalFill fill;
  EXC_FILL_EVERY_MEMBER(fill, w, q, qd, qdd, X_Wi, front_world_poses_valid, f_parent, V, Vd, pin_valid, F, tau_r, H, Psi, gamma,
                        F_c, M_r, report, rho, rhod, rhodd_bias, J_t, tip_world, cos_phi, sin_phi, omega, alpha, joint_cos,
                        joint_sin, origin, origin_d, origin_dd, Hd_qd, J_tip_tree, tip_acc_tree, Hp_inv, lu_Hp,
                        loop_jacobian_valid, planar);
  const test::VisitAudit audit = test::audit_visit(w, fill);
  INFO(audit.text());
  CHECK(audit.set > 0);
  CHECK(audit.complete());
}
