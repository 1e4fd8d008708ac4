#include "control/computed_torque_pid.hpp"

#include "control/lyapunov.hpp"

namespace exc::control {

ComputedTorquePid::ComputedTorquePid(const Model& model, const ControllerConfig& config,
                                     const EffortLimits& limits)
    : model_(model), ws_(model), config_(config), limits_(limits), pid_(config.gains) {
  const Mat8 A = error_dynamics_matrix(config.gains.kp, config.gains.kv);
  const Mat8 Q = config.lyapunov_q.asDiagonal();
  solve_lyapunov(A, Q, P_);
}

void ComputedTorquePid::reset() {
  pid_.reset();
  anchor_.reset();
  saturated_ = 0;
}

ControlOutput ComputedTorquePid::update(const ControlInput& in) {
  ControlOutput out;
  out.e = in.q - in.q_d;
  out.ed = in.qd - in.qd_d;
  const ModelReport report = update_closed_chain(model_, ws_, in.q, in.qd);
  out.status = report.status;
  if (!report.ok()) {  // hold the last good command; the loop decides (safe_stop)
    out.tau = out.tau_unsaturated = last_tau_;
    return out;
  }
  Mat4 M_a;
  Vec4 h_a;
  mass_matrix(model_, ws_, M_a);
  bias_forces(model_, ws_, h_a);
  const Vec4 feedback = pid_.update(out.e, out.ed, config_.period, saturated_);
  out.tau_unsaturated = M_a * (in.qdd_d - feedback) + h_a;  // eq. 12 without the soil term
  out.saturated = saturated_ = limits_.saturate(out.tau_unsaturated, out.tau);
  last_tau_ = out.tau;

  Vec8 x;
  x << out.e, out.ed;
  out.lyapunov = out.lyapunov_tracking = x.dot(P_ * x);
  out.rho = ws_.rho;
  anchor_.resolve(in.soil, ws_.rho, out.in_soil, out.rho_env);
  return out;
}

}  // namespace exc::control
