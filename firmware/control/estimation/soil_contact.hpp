#pragma once
// The controller's estimate of soil contact and of the soil anchor rho_env (model.md s.5-6), which it
// cannot measure. It runs the soil model's own anchor rule (paper eqs. 10-11) on its own tip position:
//   - on entry the anchor is the tip (the entry point);
//   - a shear failure when |rho_env - rho| > S_dist(h) = 0.365 h + 0.00754 (eq. 11), h the depth:
//     the anchor jumps to the tip.
// Contact and depth come from one of two sources:
//   - the site map (the scene's ground, flat or a profile), when the firmware is given one and may use
//     it (controller.soil_contact.use_site_map): contact while the tip is below it, depth from it. With
//     exact sensors this reproduces the simulator's anchor exactly;
//   - otherwise the external force at the tip that the law's observer estimates from the applied
//     efforts (external_force_observer.hpp): contact once it exceeds contact_force, left below half of
//     it (hysteresis against the estimate's noise), the ground taken as level through the entry point
//     for the depth. A map is never needed; without one the anchor is as good as the ground is level.
// No allocation.
#include <cmath>

#include "control/control_types.hpp"
#include "model/types.hpp"

namespace exc::control {

// Paper eq. 11: the distance at which the soil fails in shear, for depth h (m).
inline double shear_failure_distance(double depth) { return 0.365 * depth + 0.00754; }

struct SoilContactSettings {
  bool use_site_map = true;     // take contact and depth from the site map when the firmware has one
  double contact_force = 2000;  // N: without a map, the tip force estimate that tells contact
};
// The settings blob's field list (app/settings_blob.hpp): a field added above is added here too.
template <typename Visitor>
void visit_fields(Visitor& v, SoilContactSettings& s) {
  v("use_site_map", s.use_site_map);
  v("contact_force", s.contact_force);
}

class SoilContactEstimator {
 public:
  SoilContactEstimator() = default;
  explicit SoilContactEstimator(const SoilContactSettings& settings) : settings_(settings) {}
  void reset() {
    in_soil_ = false;
    anchor_.setZero();
    surface_ = 0;
  }
  // rho: the tip (x, z world height); map: the site map or null; tip_force: the external force at the
  // tip as estimated (null: none known).
  void update(const Vec2& rho, const Terrain* map, const Vec2* tip_force) {
    bool contact;
    double depth;
    if (map != nullptr && settings_.use_site_map) {
      depth = map->height_at(rho.x()) - rho.y();
      contact = depth > 0;
    } else {
      const double f = tip_force != nullptr ? tip_force->norm() : 0.0;
      contact = in_soil_ ? f > 0.5 * settings_.contact_force : f > settings_.contact_force;
      if (contact && !in_soil_) surface_ = rho.y();
      depth = std::max(surface_ - rho.y(), 0.0);
    }
    if (!contact) {
      in_soil_ = false;
      return;
    }
    if (!in_soil_ || (anchor_ - rho).norm() > shear_failure_distance(depth)) anchor_ = rho;
    in_soil_ = true;
  }
  // What a control law uses: the caller's contact and anchor when it knows them
  // (SoilContext::anchor_given, simulation truth), else this estimate, advanced with the tip rho.
  void resolve(const SoilContext& soil, const Vec2& rho, const Vec2* tip_force, bool& in_soil, Vec2& rho_env) {
    if (soil.anchor_given) {
      in_soil = soil.in_soil;
      rho_env = soil.rho_env;
      return;
    }
    update(rho, soil.site_map, tip_force);
    in_soil = in_soil_;
    rho_env = anchor_;
  }
  bool in_soil() const { return in_soil_; }
  const Vec2& anchor() const { return anchor_; }

 private:
  SoilContactSettings settings_;
  bool in_soil_ = false;
  Vec2 anchor_ = Vec2::Zero();
  double surface_ = 0;  // m, world z of the ground as met at the entry point (no map)
};

}  // namespace exc::control
