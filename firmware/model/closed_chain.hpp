#pragma once
// The closed chain in independent coordinates (paper eqs. 3-7, 14-17; model.md s.4).
#include "workspace.hpp"

namespace exc {

// The force the bucket exerts on the soil at the tip (paper eq. 9), in the swing plane, split into
// the part known before the acceleration (B_t rhod + K_t (rho - rho_env), N) and the soil's
// added mass M_t (kg, per axis) that multiplies the tip acceleration. Zero when out of the soil.
struct TipLoad {
  Vec2 force = Vec2::Zero();
  Vec2 added_mass = Vec2::Zero();
};

// Position, velocity and acceleration-bias level: loop closure, Psi, gamma, tree twists, and the
// tip kinematics (rho, rhod, J_t, rhodd_bias); the general path also forms H. Every other function
// here needs it called first; none of them needs the passive angles in ws.q (skipped: 8 atan2 fewer,
// ws.q's passive entries NaN). update_closed_chain, mass_matrix and bias_forces take the path
// model.closed_chain_path names (planar: planar_closed_chain.hpp; general: the passes below).
ModelReport update_closed_chain(const Model& model, Workspace& ws, const Vec4& q_a, const Vec4& qd_a,
                                PassiveAngles angles = PassiveAngles::computed);

// tau_a for the real machine (eq. 16b) with the soil force f_soil (bucket on soil, total incl.
// inertial part) acting at the tip; also fills ws.F_c (eq. 7a). Needs update_closed_chain.
void inverse_dynamics(const Model& model, Workspace& ws, const Vec4& qdd_a, const Vec2& f_soil,
                      Vec4& tau_a);

// H (eq. 4) and H_p^-1 at the state of the last update_closed_chain, when that update did not form
// them (the planar path; model.closed_chain_path): inverse_dynamics calls it for F_c.
void ensure_loop_jacobian(const Model& model, Workspace& ws);

// M_a = Psi^T M_r Psi (eq. 17). Needs update_closed_chain.
void mass_matrix(const Model& model, Workspace& ws, Mat4& M_a);

// h_a = Psi^T (C_r qd + g_r + M_r gamma): everything but M_a qdd_a and the soil. Needs update.
void bias_forces(const Model& model, Workspace& ws, Vec4& h_a);

}  // namespace exc
