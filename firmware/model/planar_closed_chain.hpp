#pragma once
// The closed chain of this machine in straight-line code (docs/model.md, "The planar closed-chain
// pass"): the same quantities as the general path of closed_chain.hpp (loop closure, Psi, gamma, the
// tip's kinematics, the twists; M_a, eq. 17; h_a) for the one structure written into it, the 12-link
// front of paper Table 1 with its four loops of Table 2 in the swing plane. M_a and h_a come from the
// links' kinetic energy and Kane's equations in the swing frame (each link: its centre of mass and
// angle in the plane and their derivatives over q_a, plus the swing's rotation about z), instead of
// 6-D Newton-Euler over the tree and Psi^T M_r Psi. Dimensions, masses and inertias are read from
// the Model each call: editing the machine file costs nothing; another linkage (a link added, a
// loop changed, a joint out of the plane) fails has_planar_closed_chain_structure and takes the
// general path until this file is rewritten for it. Nothing allocates.
#include "workspace.hpp"

namespace exc {

// The tree, its joints and its loops are those this pass is written for (Table 1, Table 2, planar).
bool has_planar_closed_chain_structure(const Model& model);

// update_closed_chain, mass_matrix and bias_forces of the planar path (called through them, which
// choose by model.closed_chain_path; q_a and qd_a are finite here).
ModelReport planar_update_closed_chain(const Model& model, Workspace& ws, const Vec4& q_a, const Vec4& qd_a,
                                       PassiveAngles angles);
void planar_mass_matrix(const Model& model, Workspace& ws, Mat4& M_a);
void planar_bias_forces(const Model& model, Workspace& ws, Vec4& h_a);

}  // namespace exc
