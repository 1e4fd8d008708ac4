#pragma once
// Geometric Newton-Euler on the 12-link tree (paper eq. 1, corrected as in model.md s.3), and the
// tree's mass matrix from the same passes. All results go to the Workspace; nothing allocates.
#include "workspace.hpp"

namespace exc {

// Forward pass, positions and velocities: f_{lambda(i),i} = M_i exp([S_i] q_i), X_Wi, and
// V_i = Ad_{f^-1} V_lambda(i) + S_i qd_i. Stores q, qd into ws.
void tree_kinematics(const Model& model, Workspace& ws, const Vec12& q, const Vec12& qd);

// The same forward pass at q = ws.q, reusing the planar front pass that front_positions(model, ws.q,
// ws) has just made (link angles' cosines and sines, origins in the swing plane): no per-link trig and
// no 3x3 products. The front links' world poses X_Wi, which the dynamics does not use, are left to
// tree_world_poses (X_Wi[0] and tip_world are set). Falls back to tree_kinematics when the tree is
// not a planar front (model.planar_front, decided once by build_model).
void tree_kinematics_from_front(const Model& model, Workspace& ws, const Vec12& qd);

// Every X_Wi after tree_kinematics_from_front (or update_closed_chain), from the planar pass; a
// no-op after tree_kinematics, which fills them itself.
void tree_world_poses(const Model& model, Workspace& ws);

// Inverse dynamics of the tree at the state of the last tree_kinematics, with joint accelerations
// qdd, gravity (base acceleration Vd_0), and the force f_soil that the bucket exerts on the soil at
// the tip (swing-plane x, z; its reaction acts on the bucket). Fills ws.Vd, ws.F and tau.
void tree_inverse_dynamics(const Model& model, Workspace& ws, const Vec12& qdd, const Vec2& f_soil,
                           Vec12& tau);

// M_r A for a 12 x N matrix A: the velocity- and gravity-free Newton-Euler passes run on N
// acceleration columns at once (N = 12 with A = I gives M_r, N = 4 with A = Psi gives M_r Psi).
template <int N>
void tree_inertia_times(const Model& model, const Workspace& ws, const Eigen::Matrix<double, 12, N>& A,
                        Eigen::Matrix<double, 12, N>& out);

// The tree's 12 x 12 mass matrix at the state of the last tree_kinematics.
void tree_mass_matrix(const Model& model, const Workspace& ws, Mat12& M_r);

}  // namespace exc
