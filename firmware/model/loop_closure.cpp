// Loop closure (paper Table 2, model.md s.4): closed form by circle intersections (law of cosines),
// and a Newton iteration as the general path.
#include "loop_closure.hpp"

#include <cmath>
#include <limits>

#include "front_kinematics.hpp"

namespace exc {

namespace {

// Below these sines of the angle between the two radii at a circle intersection, H_p is treated as
// singular. Four-bar: 0.1 (~5.7 deg of transmission angle); the reference machine stays above 0.24
// within its stroke limits and toggles at L_bucket ~1.581 m. Triangles: 0.01, since a cylinder
// triangle nearly flat at its stroke end (boom at 1.70 m: ~0.07) is a real, usable pose.
constexpr double kToggleSine = 0.1;
constexpr double kTriangleSine = 0.01;

struct Intersection {
  Vec2 point;
  double sine = 0;  // |sin| of the angle at 'point' between the radii: 0 at tangency (toggle)
  bool exists = false;
};

// The point P with |P - A| = ra and |P - B| = rb on the left (side = +1) or right (-1) of A -> B,
// seen with x right and z up.
Intersection intersect_circles(const Vec2& A, double ra, const Vec2& B, double rb, double side) {
  Intersection out;
  const Vec2 AB = B - A;
  const double d = AB.norm();
  if (!(d > 0) || !(ra > 0) || !(rb > 0)) return out;
  const double inv_d = 1.0 / d;  // one division; the rest are products (this runs 4 times per update)
  const double a = 0.5 * (ra * ra - rb * rb + d * d) * inv_d;
  const double h2 = ra * ra - a * a;
  if (!(h2 >= 0)) return out;  // the circles do not meet: no assembly
  const double h = std::sqrt(h2);
  const Vec2 e = AB * inv_d;
  out.point = A + a * e + side * h * Vec2(-e.y(), e.x());
  out.sine = h * d / (ra * rb);  // |cross(A - P, B - P)| / (ra rb)
  out.exists = true;
  return out;
}

// Branches of the reference machine (reference-machine.yaml 'assembly'; fixed by its poses).
constexpr double kBoomSide = -1.0;   // E to the right of D -> C
constexpr double kArmSide = 1.0;     // G left of F -> H
constexpr double kBucketSide = 1.0;  // J left of I -> K, L left of J -> M

ModelReport fail(ModelStatus s, int loop, double conditioning) {
  ModelReport r;
  r.status = s;
  r.loop = loop;
  r.conditioning = conditioning;
  return r;
}

}  // namespace

void loop_residual(const Model& model, const Vec12& q, Vec8& h) {
  Workspace scratch(model);  // fixed-size (on the stack): only its planar part is used
  front_positions(model, q, scratch);
  front_loop_residual(model, scratch, h);
}

ModelReport solve_loop_closure(const Model& model, Workspace& ws, const Vec4& q_a, PassiveAngles angles) {
  if (!q_a.allFinite()) return fail(ModelStatus::non_finite_input, -1, 0);
  const Machine& m = model.machine;
  double conditioning = 1.0;

  // Loop 0, boom triangle C-D-E in the swing frame.
  const double boom_E_radius = m.E.norm();
  const Intersection E = intersect_circles(m.D, q_a[1], m.C, boom_E_radius, kBoomSide);
  if (!E.exists) return fail(ModelStatus::no_assembly, 0, 0);
  if (E.sine < kTriangleSine) return fail(ModelStatus::near_toggle, 0, E.sine);
  conditioning = std::min(conditioning, E.sine);

  // Loop 1, arm triangle F-H-G in the boom frame.
  const double arm_G_radius = m.G.norm();
  const Intersection G = intersect_circles(m.F, q_a[2], m.H, arm_G_radius, kArmSide);
  if (!G.exists) return fail(ModelStatus::no_assembly, 1, 0);
  if (G.sine < kTriangleSine) return fail(ModelStatus::near_toggle, 1, G.sine);
  conditioning = std::min(conditioning, G.sine);

  // Loops 2 and 3, the bucket four-bar in the arm frame: J from the cylinder and link 12, then L
  // from link 11 and the bucket.
  const Intersection J = intersect_circles(m.I, q_a[3], m.K, m.JK, kBucketSide);
  if (!J.exists) return fail(ModelStatus::no_assembly, 2, 0);
  if (J.sine < kToggleSine) return fail(ModelStatus::near_toggle, 2, J.sine);
  const Intersection L = intersect_circles(J.point, m.JL, m.M, m.L.x(), kBucketSide);
  if (!L.exists) return fail(ModelStatus::no_assembly, 3, 0);
  if (L.sine < kToggleSine) return fail(ModelStatus::near_toggle, 3, L.sine);
  conditioning = std::min({conditioning, J.sine, L.sine});

  // Each pin angle from a vector of known length (a radius of its circle): cos q and sin q are
  // its components over that length, turned back by the reference direction where there is one;
  // one atan2 per pin and no further trig in the passes that follow.
  ws.pin_valid = false;  // f_parent no longer matches joint_cos, joint_sin
  Vec12& q = ws.q;
  q[kSwing] = q_a[0];
  q[kBoomRod] = q_a[1];
  q[kArmRod] = q_a[2];
  q[kBucketRod] = q_a[3];
  for (const int i : {kBoomRod, kArmRod, kBucketRod}) {
    ws.joint_cos[i] = 1.0;
    ws.joint_sin[i] = 0.0;
  }
  const bool with_angles = angles == PassiveAngles::computed;
  auto set_pin = [&](int i, const Vec2& unit) {
    ws.joint_cos[i] = unit.x();
    ws.joint_sin[i] = unit.y();
    q[i] = with_angles ? std::atan2(unit.y(), unit.x()) : std::numeric_limits<double>::quiet_NaN();
  };
  // The unit vector of 'v' seen from the unit reference direction 'ref' (its angle minus ref's).
  auto relative = [](const Vec2& v, const Vec2& ref) {
    return Vec2(v.x() * ref.x() + v.y() * ref.y(), v.y() * ref.x() - v.x() * ref.y());
  };
  // relative(v / r, ref / r) = relative(v, ref) / r^2.
  set_pin(kBoom, relative(E.point - m.C, m.E) * (1.0 / (boom_E_radius * boom_E_radius)));
  set_pin(kBoomBarrel, (E.point - m.D) * (1.0 / q_a[1]));
  set_pin(kArm, relative(G.point - m.H, m.G) * (1.0 / (arm_G_radius * arm_G_radius)));
  set_pin(kArmBarrel, (G.point - m.F) * (1.0 / q_a[2]));
  set_pin(kBucketBarrel, (J.point - m.I) * (1.0 / q_a[3]));
  set_pin(kBucket, (L.point - m.M) * (1.0 / m.L.x()));  // L lies on the bucket x axis
  const Vec2 bucket_barrel(ws.joint_cos[kBucketBarrel], ws.joint_sin[kBucketBarrel]);
  set_pin(kLink11, relative(L.point - J.point, bucket_barrel) * (1.0 / m.JL));
  set_pin(kLink12, relative(m.K - J.point, bucket_barrel) * (1.0 / m.JK));

  ModelReport r;
  r.conditioning = conditioning;
  return r;
}

ModelReport solve_loop_closure_newton(const Model& model, Workspace& ws, const Vec4& q_a, int max_iterations,
                                      double tolerance) {
  if (!q_a.allFinite() || !ws.q.allFinite()) return fail(ModelStatus::non_finite_input, -1, 0);
  Vec12 q = ws.q;
  for (int k = 0; k < kNumActive; ++k) q[kActiveJoints[k]] = q_a[k];
  Vec8 h;
  Mat8x12 H;
  Mat8 H_p;
  for (int it = 0; it <= max_iterations; ++it) {
    front_positions(model, q, ws);
    front_loop_residual(model, ws, h);
    front_loop_jacobian(model, ws, H);
    for (int k = 0; k < kNumPassive; ++k) H_p.col(k) = H.col(kPassiveJoints[k]);
    ws.lu_Hp.compute(H_p);
    const double rcond = ws.lu_Hp.rcond();
    if (h.cwiseAbs().maxCoeff() <= tolerance) {
      if (rcond < 1e-6) return fail(ModelStatus::near_toggle, -1, rcond);
      ws.q = q;
      ModelReport r;
      r.conditioning = rcond;
      return r;
    }
    if (it == max_iterations) break;
    if (!(rcond > 1e-12)) return fail(ModelStatus::near_toggle, -1, rcond);
    const Vec8 step = ws.lu_Hp.solve(h);
    if (!step.allFinite()) return fail(ModelStatus::singular, -1, rcond);
    for (int k = 0; k < kNumPassive; ++k) q[kPassiveJoints[k]] -= step[k];
  }
  // Either the cylinders admit no assembly, or the guess was too far for this branch.
  return fail(ModelStatus::not_converged, -1, 0);
}

}  // namespace exc
