#pragma once
// Kinetic and potential energy of the 12-link tree at the state of the last tree_kinematics (which
// update_closed_chain also runs): T = sum 1/2 V_i^T J_i V_i (body twists, spatial inertias about the
// frame origins), U = sum m_i g z_com,i (world heights). Used for the energy-drift measurement.
#include "model/workspace.hpp"

namespace exc::plant {

double kinetic_energy(const Model& model, const Workspace& ws);
double potential_energy(const Model& model, const Workspace& ws);

}  // namespace exc::plant
