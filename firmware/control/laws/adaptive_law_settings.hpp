#pragma once
// The adaptive computed-torque law's settings (adaptive_computed_torque.hpp), its own: the law takes
// these and no other law's. The scene's controller section (ControllerConfig) holds them among the
// others and hands them out (control/consumer_settings.hpp); the enumeration and the external-force
// settings are declared here, in the law's room, and ControllerConfig holds them as members.
#include <cstdint>

#include "control/estimation/soil_contact.hpp"
#include "control/estimation/state_estimator.hpp"
#include "control/laws/pid.hpp"
#include "settings/enum_table.hpp"

namespace exc::control {

// Where the adaptive law's regressor takes the joint acceleration for the soil's M_t rhodd term.
enum class RegressorAcceleration : std::uint8_t { filtered = 0, desired = 1 };
inline constexpr settings::EnumTable<RegressorAcceleration, 2> kRegressorAccelerations{{{
    {RegressorAcceleration::filtered, "filtered", "the estimator's filtered joint acceleration"},
    {RegressorAcceleration::desired, "desired", "the trajectory's desired acceleration"},
}}};

// The external force observer and the composite update of the adaptive law (beyond the paper:
// external_force_observer.hpp, adaptive_computed_torque.hpp). The paper's own law is observer: false,
// identification_memory: 0.
struct ExternalForceSettings {
  bool observer = true;        // add the observer's estimate of what the model misses to the command
  double cutoff_hz = 5;        // the observer's low-pass; default a third of filters.acceleration_cutoff_hz
  // s: the composite update's memory, least squares on the residual of the applied efforts
  // (soil_identification.hpp); 0: eq. 27 alone.
  double identification_memory = 20;
  double force_scale = 30000;  // N: the residual's noise n0 per sample (least squares' measurement noise)
  double dead_zone = 300;      // N: of each cylinder's residual, no update below it (noise, friction)
};
// The settings blob's field list (app/settings_blob.hpp): a field added above is added here too.
template <typename Visitor>
void visit_fields(Visitor& v, ExternalForceSettings& e) {
  v("observer", e.observer);
  v("cutoff_hz", e.cutoff_hz);
  v("identification_memory", e.identification_memory);
  v("force_scale", e.force_scale);
  v("dead_zone", e.dead_zone);
}

// What the law reads, each the ControllerConfig member of the same name (controller_config.hpp says
// what each means and its default).
struct AdaptiveLawSettings {
  double period = 1e-3;  // s
  PidGains gains;        // K_p, K_v (and K_i, integral_limit with integral action)
  Vec8 lyapunov_q = Vec8::Zero();
  bool integral_action = false;
  Vec4 lyapunov_q_integral = Vec4::Zero();
  Vec6 adaptation_rate = Vec6::Zero();
  Vec4 tracking_dead_zone = Vec4::Zero();
  Vec6 theta_min = Vec6::Zero(), theta_max = Vec6::Zero(), theta_initial = Vec6::Zero();
  RegressorAcceleration regressor_acceleration = RegressorAcceleration::filtered;
  ExternalForceSettings external_force;
  SoilContactSettings soil_contact;
  EstimatorConfig filter;  // the cut-offs of the update's signal filters (the estimator's)
};

}  // namespace exc::control
