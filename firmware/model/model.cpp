// The 12-link tree of paper Table 1 and the cut pins of Table 2, built once from a Machine, with the
// joint conventions of docs/model.md (front pins turn about -y so a positive angle lifts x toward z).
#include "model.hpp"

#include <atomic>

#include "lie_group.hpp"
#include "planar_closed_chain.hpp"
#include "model_status.hpp"
#include "workspace.hpp"

namespace exc {

namespace {
Vec3 in_plane(const Vec2& p) { return Vec3(p.x(), 0.0, p.y()); }

// Checked on the built tree rather than assumed, so that a future variant cannot silently take the
// planar fast pass of tree_kinematics_from_front.
bool is_planar_front(const Model& m, const Twist& swing, const Twist& pin, const Twist& slide) {
  if (m.parent[0] >= 0 || !m.home_is_translation[0] || m.screw[0] != swing) return false;
  for (int i = 1; i < kNumJoints; ++i)
    if (!m.home_is_translation[i] || m.parent[i] < 0 || m.screw[i] != (m.prismatic[i] ? slide : pin)) return false;
  return true;
}
}  // namespace

Model build_model(const Machine& machine) {
  Model m;
  m.machine = machine;
  const Machine& k = machine;

  const Twist about_z = (Twist() << 0, 0, 1, 0, 0, 0).finished();
  const Twist front_pin = (Twist() << 0, -1, 0, 0, 0, 0).finished();  // positive: x toward +z
  const Twist along_x = (Twist() << 0, 0, 0, 1, 0, 0).finished();

  auto set = [&](int i, int parent, const Vec3& origin_in_parent, const Twist& screw, bool prismatic) {
    m.parent[i] = parent;
    m.home[i] = translation_se3(origin_in_parent);
    m.screw[i] = screw;
    m.prismatic[i] = prismatic;
    m.home_is_translation[i] = true;
  };
  const Vec3 zero = Vec3::Zero();
  set(kSwing, -1, Vec3(0, 0, k.swing_height), about_z, false);
  set(kBoom, kSwing, in_plane(k.C), front_pin, false);
  set(kBoomBarrel, kSwing, in_plane(k.D), front_pin, false);
  set(kBoomRod, kBoomBarrel, zero, along_x, true);
  set(kArmBarrel, kBoom, in_plane(k.F), front_pin, false);
  set(kArm, kBoom, in_plane(k.H), front_pin, false);
  set(kBucket, kArm, in_plane(k.M), front_pin, false);
  set(kArmRod, kArmBarrel, zero, along_x, true);
  set(kBucketBarrel, kArm, in_plane(k.I), front_pin, false);
  set(kBucketRod, kBucketBarrel, zero, along_x, true);
  set(kLink11, kBucketRod, zero, front_pin, false);
  set(kLink12, kBucketRod, zero, front_pin, false);
  m.planar_front = is_planar_front(m, about_z, front_pin, along_x);

  for (int i = 0; i < kNumJoints; ++i) {
    const BodyInertia& b = k.bodies[i];
    m.inertia[i] = spatial_inertia(b.mass, b.com, b.inertia.asDiagonal());
    constexpr std::array<int, 3> in_plane_rows = {1, 3, 5};
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c) m.inertia_in_plane[i](a, c) = m.inertia[i](in_plane_rows[a], in_plane_rows[c]);
  }

  // Table 2: P_l carries the pin at point_p, S_l reaches it at point_s.
  m.loops[0] = {kBoom, kBoomRod, in_plane(k.E), zero};
  m.loops[1] = {kArm, kArmRod, in_plane(k.G), zero};
  m.loops[2] = {kArm, kLink12, in_plane(k.K), Vec3(k.JK, 0, 0)};
  m.loops[3] = {kBucket, kLink11, in_plane(k.L), Vec3(k.JL, 0, 0)};

  m.tip_in_bucket = in_plane(k.T);
  m.base_acceleration << 0, 0, 0, 0, 0, k.gravity;
  m.closed_chain_path = closed_chain_path_preference() == ClosedChainPath::planar && has_planar_closed_chain_structure(m)
                            ? ClosedChainPath::planar
                            : ClosedChainPath::general;
  return m;
}

namespace {
std::atomic<ClosedChainPath> g_closed_chain_path{ClosedChainPath::planar};
}  // namespace

void set_closed_chain_path_preference(ClosedChainPath path) { g_closed_chain_path = path; }
ClosedChainPath closed_chain_path_preference() { return g_closed_chain_path; }

const char* to_string(ModelStatus s) {
  switch (s) {
    case ModelStatus::ok: return "ok";
    case ModelStatus::non_finite_input: return "non-finite input";
    case ModelStatus::no_assembly: return "no assembly (a loop cannot close at these cylinder lengths)";
    case ModelStatus::near_toggle: return "near a toggle position (loop closure ill-conditioned)";
    case ModelStatus::not_converged: return "loop closure did not converge";
    case ModelStatus::singular: return "singular linear system";
  }
  return "unknown";
}

Workspace::Workspace(const Model& model) {
  for (int i = 0; i < kNumJoints; ++i) {
    X_Wi[i] = SE3::Identity();
    f_parent[i] = model.home[i];
    V[i].setZero();
    Vd[i].setZero();
    F[i].setZero();
  }
  cos_phi.fill(1.0);
  sin_phi.fill(0.0);
  omega.fill(0.0);
  alpha.fill(0.0);
  for (int i = 0; i < kNumJoints; ++i) {
    origin[i].setZero();
    origin_d[i].setZero();
    origin_dd[i].setZero();
  }
}

Workspace::PlanarLinks::PlanarLinks() {
  for (int i = 0; i < kNumJoints; ++i) {
    acceleration[i].setZero();
    com[i].setZero();
    J_angle[i].setZero();  // the columns a link's cylinders cannot move stay zero: the passes read them
    J_origin[i].setZero();
    J_com[i].setZero();
  }
}

}  // namespace exc
