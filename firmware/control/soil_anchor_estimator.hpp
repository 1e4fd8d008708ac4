#pragma once
// The controller's estimate of the soil anchor rho_env (model.md s.5-6), which it cannot measure.
// Decision: the controller runs the soil model's own anchor rule on its own tip position rho (from
// measured q_a through the model) and the terrain height it knows from the scene:
//   - contact when the tip is below the terrain (depth h = terrain - z > 0);
//   - on entry the anchor is the tip position (the entry point);
//   - a shear failure when |rho_env - rho| > S_dist(h) = 0.365 h + 0.00754 (paper eq. 11): the
//     anchor jumps to the tip.
// With exact measurements it reproduces the simulator's anchor exactly; with noise it differs only
// near the re-anchoring instants, and the K-term of the regressor then briefly disagrees (bounded;
// the projection keeps Theta_hat physical). No allocation.
#include <cmath>

#include "control/control_types.hpp"
#include "model/types.hpp"

namespace exc::control {

// Paper eq. 11: the distance at which the soil fails in shear, for depth h (m).
inline double shear_failure_distance(double depth) { return 0.365 * depth + 0.00754; }

class SoilAnchorEstimator {
 public:
  void reset() {
    in_soil_ = false;
    anchor_.setZero();
  }
  // rho: tip (x, z world height); terrain_height: world z of the flat terrain.
  void update(const Vec2& rho, double terrain_height) {
    const double depth = terrain_height - rho.y();
    if (depth <= 0) {
      in_soil_ = false;
      return;
    }
    if (!in_soil_ || (anchor_ - rho).norm() > shear_failure_distance(depth)) anchor_ = rho;
    in_soil_ = true;
  }
  // What a control law uses: the caller's contact and anchor when it knows them
  // (SoilContext::anchor_given, simulation truth), else this estimate, advanced with the tip rho.
  void resolve(const SoilContext& soil, const Vec2& rho, bool& in_soil, Vec2& rho_env) {
    if (soil.anchor_given) {
      in_soil = soil.in_soil;
      rho_env = soil.rho_env;
      return;
    }
    update(rho, soil.terrain_height);
    in_soil = in_soil_;
    rho_env = anchor_;
  }
  bool in_soil() const { return in_soil_; }
  const Vec2& anchor() const { return anchor_; }

 private:
  bool in_soil_ = false;
  Vec2 anchor_ = Vec2::Zero();
};

}  // namespace exc::control
