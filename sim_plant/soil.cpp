// Soil (paper eqs. 9-11, model.md s.5).
#include "sim_plant/soil.hpp"

namespace exc::plant {

SoilParameters soil_preset(SoilPreset preset) {
  // machine.md, "Soil, for the paper's digging scene": the spring force at the re-anchoring distance
  // equals the Fundamental Earthmoving Equation's failure force. Same numbers on both axes.
  SoilParameters p;
  switch (preset) {
    case SoilPreset::none: break;
    case SoilPreset::loose_sand: p.stiffness = Vec2(2e4, 2e4); p.damping = Vec2(2.5e3, 2.5e3); p.mass = Vec2(200, 200); break;
    case SoilPreset::loam: p.stiffness = Vec2(7e4, 7e4); p.damping = Vec2(5e3, 5e3); p.mass = Vec2(200, 200); break;
    case SoilPreset::stiff_clay: p.stiffness = Vec2(2e5, 2e5); p.damping = Vec2(9e3, 9e3); p.mass = Vec2(200, 200); break;
  }
  return p;
}

TipLoad SoilModel::load(const Vec2& rho, const Vec2& rhod) const {
  TipLoad out;
  if (!present() || depth(rho) <= 0.0) return out;
  // eq. 9 without the inertial term; an entering tip has no spring stretch yet.
  const Vec2 anchor = in_soil_ ? anchor_ : rho;
  out.force = params_.damping.cwiseProduct(rhod) + params_.stiffness.cwiseProduct(rho - anchor);
  out.added_mass = params_.mass;
  return out;
}

Vec2 SoilModel::total_force(const Vec2& rho, const Vec2& rhod, const Vec2& rhodd) const {
  const TipLoad l = load(rho, rhod);
  return l.force + l.added_mass.cwiseProduct(rhodd);
}

bool SoilModel::commit(const Vec2& rho) {
  const double h = depth(rho);
  if (!present() || h <= 0.0) {
    in_soil_ = false;
    return false;
  }
  if (!in_soil_) {
    // eq. 10: rho_env starts at the entry point.
    in_soil_ = true;
    anchor_ = rho;
    return false;
  }
  // eq. 11: the spring shears off and re-anchors at the tip.
  if ((anchor_ - rho).norm() > shear_distance(h)) {
    anchor_ = rho;
    ++reanchor_count_;
    return true;
  }
  return false;
}

}  // namespace exc::plant
