#pragma once
// M_a = Psi^T M_r Psi (eq. 17) as a sum of body kinetic energies, without forming M_r.
#include "workspace.hpp"

namespace exc {

// Psi^T M_r Psi = sum_i J_i^T G_i J_i, with J_i the body Jacobian of link i over the 4 active
// coordinates (J_i = Ad_{f^-1} J_parent + S_i Psi_i) and G_i its spatial inertia. On the planar
// front's pin transforms (ws.pin_valid) a front column stays in the plane (w_y, v_x, v_z), so only
// the swing column is a full twist; otherwise the general Newton-Euler passes give M_r Psi.
// Needs update_closed_chain (or tree kinematics at ws.q).
void projected_mass_matrix(const Model& model, const Workspace& ws, const Mat12x4& Psi, Mat4& M_a);

}  // namespace exc
