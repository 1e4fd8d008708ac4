#include "sim_plant/mechanical_energy.hpp"

#include "model/newton_euler.hpp"

namespace exc::plant {

double kinetic_energy(const Model& model, const Workspace& ws) {
  double t = 0;
  for (int i = 0; i < kNumJoints; ++i) t += 0.5 * ws.V[i].dot(model.inertia[i] * ws.V[i]);
  return t;
}

double potential_energy(const Model& model, const Workspace& ws) {
  // A front link's world pose (set_front_world_pose) has the row (sin phi, 0, cos phi) in z and the
  // height z_swing + origin.y: its centre of mass's height needs that row alone, so the eleven 4x4
  // poses are not built when the planar pass left them out (the same products and sums as the dot
  // product with the built row: the same energy bit for bit).
  const bool poses = ws.front_world_poses_valid;
  const double z0 = ws.X_Wi[0](2, 3);
  double u = 0;
  for (int i = 0; i < kNumJoints; ++i) {
    const BodyInertia& b = model.machine.bodies[i];
    double z;
    if (poses || i == 0) {
      z = ws.X_Wi[i].row(2).head<3>().dot(b.com) + ws.X_Wi[i](2, 3);
    } else {
      z = ws.sin_phi[i] * b.com.x() + (0.0 * b.com.y() + ws.cos_phi[i] * b.com.z()) + (z0 + ws.origin[i].y());
    }
    u += b.mass * model.machine.gravity * z;
  }
  return u;
}

}  // namespace exc::plant
