#include "sim_plant/mechanical_energy.hpp"

#include "model/newton_euler.hpp"

namespace exc::plant {

double kinetic_energy(const Model& model, const Workspace& ws) {
  double t = 0;
  for (int i = 0; i < kNumJoints; ++i) t += 0.5 * ws.V[i].dot(model.inertia[i] * ws.V[i]);
  return t;
}

double potential_energy(const Model& model, Workspace& ws) {
  tree_world_poses(model, ws);  // the dynamics passes leave the front's world poses out
  double u = 0;
  for (int i = 0; i < kNumJoints; ++i) {
    const BodyInertia& b = model.machine.bodies[i];
    const double z = ws.X_Wi[i].row(2).head<3>().dot(b.com) + ws.X_Wi[i](2, 3);
    u += b.mass * model.machine.gravity * z;
  }
  return u;
}

}  // namespace exc::plant
