#pragma once
// Planar kinematics of the front in the swing plane (x forward, z up, origin at the swing frame):
// link angles, origins and their rates, the loop residual h, its Jacobian H = dh/dq and Hd qd
// (model.md s.4), and the tip kinematics. The swing joint is out of this plane: h and rho do not
// depend on it, so its columns are zero.
#include "workspace.hpp"

namespace exc {

// Angles and origins of every link from q (positions only); fills ws.joint_cos,
// ws.joint_sin, ws.cos_phi, ws.sin_phi, ws.origin.
void front_positions(const Model& model, const Vec12& q, Workspace& ws);

// The same with ws.joint_cos, ws.joint_sin already set for q (the closed-form loop closure has
// them from its intersection vectors, without trig).
void front_positions_from_joint_trig(const Model& model, const Vec12& q, Workspace& ws);

// Rates from qd and qdd (after front_positions): ws.omega, ws.alpha, ws.origin_d, ws.origin_dd.
void front_rates(const Model& model, const Vec12& qd, const Vec12& qdd, Workspace& ws);

// A point fixed in link i (local x, z), in the swing plane.
Vec2 front_point(const Workspace& ws, int link, const Vec3& local);

// h (eq. 3) from the positions in ws.
void front_loop_residual(const Model& model, const Workspace& ws, Vec8& h);

// H = dh/dq (8 x 12) from the positions in ws.
void front_loop_jacobian(const Model& model, const Workspace& ws, Mat8x12& H);

// Relative acceleration of the cut pins from the rates in ws (with qdd = 0 this is Hd qd).
void front_loop_acceleration(const Model& model, const Workspace& ws, Vec8& hdd);

// Tip position (swing-plane x, z relative to the swing frame), its Jacobian over the 12 tree
// coordinates, and its acceleration from the rates in ws.
void front_tip(const Model& model, const Workspace& ws, Vec2& p, Eigen::Matrix<double, 2, 12>& J,
               Vec2& acc);

}  // namespace exc
