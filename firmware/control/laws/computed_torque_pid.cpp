#include "control/laws/computed_torque_pid.hpp"

#include "control/laws/law_stages.hpp"
#include "control/laws/lyapunov.hpp"

namespace exc::control {

ComputedTorquePid::ComputedTorquePid(const Model& model, const PidLawSettings& settings, double period,
                                     const EffortLimits& limits)
    : model_(model), ws_(model), period_(period), limits_(limits), pid_(settings.gains) {
  const Mat8 A = error_dynamics_matrix(settings.gains.kp, settings.gains.kv);
  const Mat8 Q = settings.lyapunov_q.asDiagonal();
  solve_lyapunov(A, Q, P_);
}

void ComputedTorquePid::reset() {
  pid_.reset();
  anchor_.reset();
  saturated_ = 0;
}

ControlOutput ComputedTorquePid::update(const ControlInput& in) {
  ControlOutput out;
  tracking_errors(in, out);
  Mat4 M_a;
  Vec4 h_a;
  if (!model_at(model_, ws_, in.q, in.qd, last_tau_, out, M_a, h_a)) return out;
  const Vec4 feedback = pid_.update(out.e, out.ed, period_, saturated_ | in.actuator_limited);
  out.tau_unsaturated = M_a * (in.qdd_d - feedback) + h_a;  // eq. 12 without the soil term
  saturated_ = saturate_output(limits_, out, last_tau_);

  Vec8 x;
  x << out.e, out.ed;
  out.lyapunov = out.lyapunov_tracking = x.dot(P_ * x);
  out.rho = ws_.rho;
  anchor_.resolve(in.soil, ws_.rho, nullptr, out.in_soil, out.rho_env);
  return out;
}

}  // namespace exc::control
