#pragma once
#include <cmath>
// Soil reaction at the bucket tip (paper eqs. 9-11, model.md s.5): a mass-spring-damper per axis
// (x, z in the swing plane) anchored at rho_env, active only while the tip is below the terrain,
// with the shear re-anchoring rho_env = rho when |rho_env - rho| > S_dist(h).
#include <array>

#include "settings/enum_table.hpp"
#include "model/closed_chain.hpp"
#include "model/terrain.hpp"

namespace exc::plant {

// Diagonal soil parameters (x, z). All zero means no soil.
struct SoilParameters {
  Vec2 stiffness = Vec2::Zero();  // K_t, N/m
  Vec2 damping = Vec2::Zero();    // B_t, N s/m
  Vec2 mass = Vec2::Zero();       // M_t, kg
};

enum class SoilPreset { none, loose_sand, loam, stiff_clay };
// The names a scene's soil.preset takes.
inline constexpr settings::EnumTable<SoilPreset, 4> kSoilPresets{{{
    {SoilPreset::none, "none", "no soil"},
    {SoilPreset::loose_sand, "loose_sand", "machine.md's loose sand"},
    {SoilPreset::loam, "loam", "machine.md's loam (the paper's digging scene)"},
    {SoilPreset::stiff_clay, "stiff_clay", "machine.md's stiff clay"},
}}};
inline const char* to_string(SoilPreset preset) { return kSoilPresets.name_of(preset); }
// machine.md's table: K_t, B_t, M_t for each preset.
SoilParameters soil_preset(SoilPreset preset);

// The shear distance of eq. 11: S_dist = 0.365 h + 0.00754 (m, h in m).
inline double shear_distance(double depth) { return 0.365 * depth + 0.00754; }

// The soil's state and the force law. The plant asks for the load at every dynamics evaluation
// (load()), then commits the tip's end-of-step position (commit()), which is where the entry anchor
// and the re-anchoring (discrete events) happen.
class SoilModel {
 public:
  SoilModel() = default;
  SoilModel(const Terrain& terrain, const SoilParameters& params) : terrain_(terrain), params_(params) {}

  const Terrain& terrain() const { return terrain_; }
  const SoilParameters& parameters() const { return params_; }
  // A stiffer layer from now on (a rock in the ground: stiffness and damping scaled; 1 restores).
  void set_stiffness_scale(double scale, const SoilParameters& nominal) {
    params_.stiffness = nominal.stiffness * scale;
    params_.damping = nominal.damping * std::sqrt(scale);
  }

  // Depth h = terrain height - tip z (h > 0: in soil).
  double depth(const Vec2& rho) const { return terrain_.height_at(rho.x()) - rho.y(); }

  // The part of eq. 9 known before the acceleration, f = B rhod + K (rho - rho_env), and the added
  // mass M_t; zero out of the soil. A tip that enters during a step is anchored where it is.
  TipLoad load(const Vec2& rho, const Vec2& rhod) const;

  // Total force of the bucket on the soil (eq. 9) once the tip acceleration is known.
  Vec2 total_force(const Vec2& rho, const Vec2& rhod, const Vec2& rhodd) const;

  // End of a step: entry anchor, shear re-anchoring (eqs. 10-11), exit. Returns true on a
  // re-anchoring (a shear failure).
  bool commit(const Vec2& rho);

  // Whether there is soil at all: a preset none (every parameter zero) has no spring to anchor or
  // shear, so a tip below its terrain is in the air, not in soil (the terrain stays the ground's height).
  bool present() const { return !(params_.stiffness.isZero(0) && params_.damping.isZero(0) && params_.mass.isZero(0)); }
  bool in_soil() const { return in_soil_; }
  const Vec2& anchor() const { return anchor_; }
  int reanchor_count() const { return reanchor_count_; }
  void reset() { in_soil_ = false; anchor_.setZero(); reanchor_count_ = 0; }

 private:
  Terrain terrain_;
  SoilParameters params_;
  bool in_soil_ = false;
  Vec2 anchor_ = Vec2::Zero();  // rho_env
  int reanchor_count_ = 0;
};

}  // namespace exc::plant
