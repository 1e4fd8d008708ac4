#include "control/adaptive_computed_torque.hpp"

#include <Eigen/Cholesky>

#include "control/law_stages.hpp"
#include "control/lyapunov.hpp"

namespace exc::control {

AdaptiveComputedTorque::AdaptiveComputedTorque(const Model& model, const ControllerConfig& config,
                                               const EffortLimits& limits)
    : model_(model), ws_(model), config_(config), limits_(limits) {
  PidGains gains = config.gains;
  if (config.integral_action) {
    const Mat12 A = integral_error_dynamics_matrix(gains.kp, gains.kv, gains.ki);
    Vec12 q;
    q << config.lyapunov_q_integral, config.lyapunov_q;
    if (!solve_lyapunov(A, Mat12(q.asDiagonal()), P_))
      throw SettingsError("<controller>", 0, 0, "controller.kp/kv/ki", "A^T P + P A + Q = 0 has no SPD solution");
  } else {
    gains.ki.setZero();  // the paper's law: no integral state, zero rows and columns of P for it
    const Mat8 A = error_dynamics_matrix(gains.kp, gains.kv);
    Mat8 P8;
    if (!solve_lyapunov(A, Mat8(config.lyapunov_q.asDiagonal()), P8))
      throw SettingsError("<controller>", 0, 0, "controller.kp/kv", "A^T P + P A + Q = 0 has no SPD solution");
    P_.bottomRightCorner<8, 8>() = P8;
  }
  feedback_.set_gains(gains);
  reset();
}

void AdaptiveComputedTorque::reset() {
  theta_hat_ = config_.theta_initial;
  anchor_.reset();
  feedback_.reset();
  saturated_ = 0;
}

Vec6 AdaptiveComputedTorque::gamma() const {
  Vec6 g;
  for (int i = 0; i < 6; ++i) g[i] = config_.adaptation_rate[i] > 0 ? 1 / config_.adaptation_rate[i] : 0;
  return g;
}

ControlOutput AdaptiveComputedTorque::update(const ControlInput& in) {
  ControlOutput out;
  tracking_errors(in, out);
  out.theta_hat = theta_hat_;
  Mat4 M_a;
  Vec4 h_a;
  if (!model_at(model_, ws_, in.q, in.qd, last_tau_, out, M_a, h_a)) return out;

  // Contact and anchor (the controller's own estimate unless the caller knows them).
  out.rho = ws_.rho;
  anchor_.resolve(in.soil, ws_.rho, out.in_soil, out.rho_env);
  const Vec4& qdd_for_y = config_.regressor_acceleration == RegressorAcceleration::desired ? in.qdd_d : in.qdd;
  const Vec2 rhodd = ws_.J_t * qdd_for_y + ws_.rhodd_bias;
  const Mat4x6 Y = soil_regressor(ws_.J_t, ws_.rho, ws_.rhod, rhodd, out.rho_env, out.in_soil);

  const Vec4 v = in.qdd_d - feedback_.update(out.e, out.ed, config_.period, saturated_ | in.actuator_limited);
  out.tau_unsaturated = M_a * v + h_a + Y * theta_hat_;  // eq. 12
  saturated_ = saturate_output(limits_, out, last_tau_);

  Vec12 z;
  z << feedback_.integral(), out.e, out.ed;
  out.lyapunov_tracking = z.dot(P_ * z);
  out.lyapunov = out.lyapunov_tracking;
  if (in.soil.theta_known) {
    const Vec6 g = gamma();
    const Vec6 tilde = theta_hat_ - in.soil.theta;
    out.lyapunov += tilde.dot(g.cwiseProduct(tilde));
  }

  // Update law (eq. 27), explicit Euler at the control period, then the projection.
  const std::uint8_t off_dynamics = out.saturated | in.actuator_limited;  // joints not driven as commanded
  if (out.in_soil && off_dynamics != 0x0F) {
    const Eigen::LDLT<Mat4> ldlt(M_a);
    const Mat4x6 Phi = ldlt.solve(Y);                       // M_a^-1 Y
    Vec4 BtPx = P_.bottomRows<4>() * z;                     // B^T P x (or z)
    for (int j = 0; j < 4; ++j)
      if ((off_dynamics >> j) & 1u) BtPx[j] = 0;            // its error is the limit's, not the soil's
    Vec6 theta_dot = -config_.adaptation_rate.cwiseProduct(Phi.transpose() * BtPx);
    if (config_.adaptation_leakage_time > 0)  // sigma-modification: the drift over passes bounded
      theta_dot -= (theta_hat_ - config_.theta_initial) / config_.adaptation_leakage_time;
    theta_hat_ = (theta_hat_ + config_.period * theta_dot).cwiseMax(config_.theta_min).cwiseMin(config_.theta_max);
  }
  return out;
}

}  // namespace exc::control
