#pragma once
// The adaptive computed-torque law's settings (adaptive_computed_torque.hpp): the computed-torque
// law's, whole, and the adaptation it adds. The scene's controller section (ControllerConfig) holds
// each part once as a member; nothing is copied member by member.
#include <cstdint>

#include "control/estimation/soil_contact.hpp"
#include "control/estimation/state_estimator.hpp"
#include "control/laws/computed_torque_pid.hpp"
#include "control/laws/soil_parameter_bounds.hpp"
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

// The adaptation the adaptive law adds to the computed-torque law (eq. 27 and beyond the paper):
// its own, held by ControllerConfig as its `adaptation` member.
struct AdaptationSettings {
  // Gamma^-1 = diag(rate); Theta = [M_x B_x K_x M_z B_z K_z]. Scaled so that each column of Y
  // (rhodd ~0.5 m/s^2, rhod ~0.5 m/s, rho - rho_env ~0.1 m) adapts at a similar pace. Through the
  // valves derive_defaults scales them (controller_config.hpp).
  Vec6 rate = (Vec6() << 6e7, 6e10, 3e12, 6e7, 6e10, 3e12).finished();
  // Per joint (rad swing, m): eq. 27 leaves a joint whose |e| is below this out of its update (the
  // standard dead-zone modification). Default on valves: the valve stage's hold window, the error the
  // valves cannot resolve; 0 on efforts (eq. 27 as published).
  Vec4 tracking_dead_zone = Vec4::Zero();
  RegressorAcceleration regressor_acceleration = RegressorAcceleration::filtered;
  ExternalForceSettings external_force;
  SoilContactSettings soil_contact;
  // Beyond the paper: integral action (K_i and integral_limit as the PID's), with Q of the integral
  // states (z = [int e; e; ed] order: these first, then the computed-torque law's lyapunov_q).
  bool integral_action = false;
  Vec4 lyapunov_q_integral = (Vec4() << 0.64, 0.64, 6.4, 0.064).finished();  // lyapunov_q e weights / 100 (docs/control.md)
};
// The settings blob's field list (app/settings_blob.hpp): a field added above is added here too.
template <typename Visitor>
void visit_fields(Visitor& v, AdaptationSettings& a) {
  v("rate", a.rate);
  v("tracking_dead_zone", a.tracking_dead_zone);
  v.choice("regressor_acceleration", a.regressor_acceleration, kRegressorAccelerations);
  v("external_force", a.external_force);
  v("soil_contact", a.soil_contact);
  v("integral_action", a.integral_action);
  v("lyapunov_q_integral", a.lyapunov_q_integral);
}

// What the adaptive law reads: the computed-torque law's settings it builds on, its adaptation, the
// soil parameters' bounds it shares with Slotine-Li and the estimator's cut-offs its update's signal
// filters take. Each is a ControllerConfig member, whole (adaptive_law_settings() in
// controller_config.hpp puts them together).
struct AdaptiveLawSettings {
  PidLawSettings computed_torque;
  AdaptationSettings adaptation;
  SoilParameterBounds soil;
  EstimatorConfig filter;
};

}  // namespace exc::control
