#pragma once
// The stages every control law shares, so that a law's update() reads as its own equations only:
// the tracking errors, the closed-chain model at the state (holding the last good command when the
// model refuses it), and saturation with the memory of the last command sent. Allocation-free.
#include "control/control_types.hpp"
#include "control/laws/effort_limits.hpp"
#include "model/closed_chain.hpp"
#include "model/workspace.hpp"

namespace exc::control {

// e = q_a - q_d and ed = qd_a - qd_d into out.
inline void tracking_errors(const ControlInput& in, ControlOutput& out) {
  out.e = in.q - in.q_d;
  out.ed = in.qd - in.qd_d;
}

// The model at (q, v): M_a(q) and h_a(q, v) (v is qd for computed torque, the reference velocity for
// Slotine-Li). False when the model refuses the state: out then carries the status and holds the last
// good command (never NaN); the loop decides what follows (safe_stop). No law reads the passive
// joints' angles: they are skipped.
inline bool model_at(const Model& model, Workspace& ws, const Vec4& q, const Vec4& v, const Vec4& last_tau,
                     ControlOutput& out, Mat4& M_a, Vec4& h_a) {
  const ModelReport report = update_closed_chain(model, ws, q, v, PassiveAngles::skipped);
  out.status = report.status;
  if (!report.ok()) {
    out.tau = out.tau_unsaturated = last_tau;
    return false;
  }
  mass_matrix(model, ws, M_a);
  bias_forces(model, ws, h_a);
  return true;
}

// out.tau = out.tau_unsaturated clamped to the limits; the saturated joints' bits are returned (and
// set in out); last_tau remembers what was sent.
inline std::uint8_t saturate_output(const EffortLimits& limits, ControlOutput& out, Vec4& last_tau) {
  out.saturated = limits.saturate(out.tau_unsaturated, out.tau);
  last_tau = out.tau;
  return out.saturated;
}

}  // namespace exc::control
