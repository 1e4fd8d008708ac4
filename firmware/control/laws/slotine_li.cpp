#include "control/laws/slotine_li.hpp"

#include "control/laws/law_stages.hpp"

namespace exc::control {

SlotineLi::SlotineLi(const Model& model, const SlotineLiSettings& settings, const SoilParameterBounds& soil,
                     double period, const EffortLimits& limits)
    : model_(model), ws_(model), settings_(settings), soil_(soil), period_(period), limits_(limits) {
  reset();
}

void SlotineLi::reset() {
  theta_hat_ = soil_.theta_initial;
  anchor_.reset();
}

ControlOutput SlotineLi::update(const ControlInput& in) {
  ControlOutput out;
  tracking_errors(in, out);
  out.theta_hat = theta_hat_;
  const Vec4& lambda = settings_.lambda;
  const Vec4 qd_r = in.qd_d - lambda.cwiseProduct(out.e);
  const Vec4 qdd_r = in.qdd_d - lambda.cwiseProduct(out.ed);
  const Vec4 s = out.ed + lambda.cwiseProduct(out.e);

  // Kinematics at (q, qd_r): M_a(q), C_a(q, qd_r) qd_r + g_a, J_t(q), Jd_t(q, qd_r) qd_r.
  Mat4 M_a;
  Vec4 h_r;
  if (!model_at(model_, ws_, in.q, qd_r, last_tau_, out, M_a, h_r)) return out;

  out.rho = ws_.rho;  // position level: independent of the velocity passed in
  anchor_.resolve(in.soil, ws_.rho, nullptr, out.in_soil, out.rho_env);
  const Vec2 rhod_r = ws_.J_t * qd_r;
  const Vec2 rhodd_r = ws_.J_t * qdd_r + ws_.rhodd_bias;
  const Mat4x6 Y = soil_regressor(ws_.J_t, ws_.rho, rhod_r, rhodd_r, out.rho_env, out.in_soil);

  const Vec4 kd = settings_.kd.cwiseProduct(M_a.diagonal());
  out.tau_unsaturated = M_a * qdd_r + h_r + Y * theta_hat_ - kd.cwiseProduct(s);
  saturate_output(limits_, out, last_tau_);

  out.lyapunov_tracking = 0.5 * s.dot(M_a * s) + out.e.dot(lambda.cwiseProduct(kd).cwiseProduct(out.e));
  out.lyapunov = out.lyapunov_tracking;
  if (in.soil.theta_known) {
    const Vec6 tilde = theta_hat_ - in.soil.theta;
    for (int i = 0; i < 6; ++i)
      if (settings_.adaptation_rate[i] > 0)
        out.lyapunov += 0.5 * tilde[i] * tilde[i] / settings_.adaptation_rate[i];
  }
  // A joint not driven as commanded (saturated, or clamped by the lag stage) is left out of the update.
  const std::uint8_t off_dynamics = out.saturated | in.actuator_limited;
  if (out.in_soil && off_dynamics != 0x0F) {
    Vec4 s_used = s;
    for (int j = 0; j < 4; ++j)
      if ((off_dynamics >> j) & 1u) s_used[j] = 0;
    const Vec6 theta_dot = -settings_.adaptation_rate.cwiseProduct(Y.transpose() * s_used);
    theta_hat_ = (theta_hat_ + period_ * theta_dot).cwiseMax(soil_.theta_min).cwiseMin(soil_.theta_max);
  }
  return out;
}

}  // namespace exc::control
