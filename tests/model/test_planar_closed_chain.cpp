// The planar closed-chain pass (model/planar_closed_chain.hpp) against the general path it replaces
// for this machine (the loop Jacobian, Psi^T M_r Psi, Newton-Euler over the tree): the same
// workspace, M_a, h_a, inverse dynamics and loop forces, to round-off, over many random states of
// the reference machine and of one with its front off the swing's plane (out-of-plane offsets, the
// terms the reference machine leaves zero), and the structure check that sends any other tree to the
// general path.
#include <doctest/doctest.h>

#include <algorithm>
#include <string>

#include "model/newton_euler.hpp"
#include "model/planar_closed_chain.hpp"
#include "model_fixture.hpp"

using namespace exc;

namespace {

// Largest |a - b| over the largest |b| (or 1): the round-off of a result of that size.
template <typename A, typename B>
double relative_difference(const A& a, const B& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

struct Worst {
  double kinematics = 0, twists = 0, mass = 0, bias = 0, tau = 0, loop_forces = 0;
};

// Both paths at the same states; the worst relative differences.
Worst compare_paths(const Model& planar, int states, unsigned seed) {
  REQUIRE(planar.closed_chain_path == ClosedChainPath::planar);
  Model general = planar;
  general.closed_chain_path = ClosedChainPath::general;
  Workspace wp(planar), wg(general);
  test::RandomStates rs(seed);
  Worst w;
  for (int trial = 0; trial < states; ++trial) {
    const Vec4 q_a = rs.q_a(planar), qd_a = 3 * rs.qd_a(), qdd_a = rs.qdd_a();
    CAPTURE(trial);
    const ModelReport rp = update_closed_chain(planar, wp, q_a, qd_a);
    const ModelReport rg = update_closed_chain(general, wg, q_a, qd_a);
    REQUIRE(rg.ok());
    REQUIRE(rp.ok());
    CHECK(rp.conditioning == rg.conditioning);
    w.kinematics = std::max({w.kinematics, relative_difference(wp.q, wg.q), relative_difference(wp.qd, wg.qd),
                             relative_difference(wp.Psi, wg.Psi), relative_difference(wp.gamma, wg.gamma),
                             relative_difference(wp.rho, wg.rho), relative_difference(wp.rhod, wg.rhod),
                             relative_difference(wp.J_t, wg.J_t), relative_difference(wp.rhodd_bias, wg.rhodd_bias),
                             relative_difference(wp.tip_world, wg.tip_world)});
    for (int i = 0; i < kNumJoints; ++i)
      w.twists = std::max({w.twists, relative_difference(wp.V[i], wg.V[i]),
                           relative_difference(wp.f_parent[i], wg.f_parent[i]), relative_difference(wp.origin[i], wg.origin[i]),
                           relative_difference(wp.origin_d[i], wg.origin_d[i])});
    CHECK(wp.pin_valid == wg.pin_valid);
    tree_world_poses(planar, wp);
    tree_world_poses(general, wg);
    for (int i = 0; i < kNumJoints; ++i) w.twists = std::max(w.twists, relative_difference(wp.X_Wi[i], wg.X_Wi[i]));
    Mat4 Mp, Mg;
    Vec4 hp, hg, tp, tg;
    mass_matrix(planar, wp, Mp);
    mass_matrix(general, wg, Mg);
    bias_forces(planar, wp, hp);
    bias_forces(general, wg, hg);
    CHECK(Mp == Mp.transpose());
    w.mass = std::max(w.mass, relative_difference(Mp, Mg));
    w.bias = std::max(w.bias, relative_difference(hp, hg));
    inverse_dynamics(planar, wp, qdd_a, Vec2(1e4, -2e4), tp);
    inverse_dynamics(general, wg, qdd_a, Vec2(1e4, -2e4), tg);
    w.tau = std::max(w.tau, relative_difference(tp, tg));
    w.loop_forces = std::max(w.loop_forces, relative_difference(wp.F_c, wg.F_c));
  }
  return w;
}

void check_round_off(const Worst& w) {
  MESSAGE("worst relative differences, planar against general: kinematics ", w.kinematics, ", twists and poses ",
          w.twists, ", M_a ", w.mass, ", h_a ", w.bias, ", tau_a ", w.tau, ", F_c ", w.loop_forces);
  CHECK(w.kinematics < 1e-12);
  CHECK(w.twists < 1e-12);
  CHECK(w.mass < 1e-12);
  CHECK(w.bias < 1e-12);
  CHECK(w.tau < 1e-12);
  CHECK(w.loop_forces < 1e-11);
}

}  // namespace

TEST_CASE("model/the planar closed-chain pass equals the general path to round-off over 2000 random states") {
  const Model& m = test::reference_model();
  check_round_off(compare_paths(m, 2000, 41));
}

TEST_CASE("model/the planar pass equals the general path with the front off the swing's plane (out-of-plane offsets)") {
  // A barrel pinned beside the boom and centres of mass off the links' planes: the swing couples to
  // the cylinders through them (M_a's first row, h_a's Coriolis terms), which the reference machine
  // leaves zero.
  Machine shifted = test::reference_model().machine;
  for (int i = 0; i < kNumJoints; ++i) shifted.bodies[i].com.y() += 0.02 * (i % 3 - 1);
  Model m = build_model(shifted);
  m.home[kBoomBarrel](1, 3) += 0.15;
  m.home[kBucket](1, 3) -= 0.05;
  const Worst w = compare_paths(m, 500, 43);
  check_round_off(w);
}

TEST_CASE("model/only this machine's tree takes the planar path: another tree, or a process that asks, takes the general one") {
  const Model& m = test::reference_model();
  CHECK(m.closed_chain_path == ClosedChainPath::planar);
  CHECK(has_planar_closed_chain_structure(m));
  Model other = m;
  other.parent[kBucket] = kBoom;  // the bucket hung from the boom: not the tree the pass is written for
  CHECK_FALSE(has_planar_closed_chain_structure(other));
  Model swapped = m;
  std::swap(swapped.loops[2], swapped.loops[3]);
  CHECK_FALSE(has_planar_closed_chain_structure(swapped));
  Model tilted = m;
  tilted.planar_front = false;  // a joint out of the plane
  CHECK_FALSE(has_planar_closed_chain_structure(tilted));
  set_closed_chain_path_preference(ClosedChainPath::general);
  const Model asked = build_model(m.machine);
  set_closed_chain_path_preference(ClosedChainPath::planar);
  CHECK(asked.closed_chain_path == ClosedChainPath::general);
  CHECK(build_model(m.machine).closed_chain_path == ClosedChainPath::planar);
}
