#include "control/laws/adaptive_computed_torque.hpp"

#include <cmath>

#include <Eigen/Cholesky>

#include "control/laws/law_stages.hpp"
#include "control/laws/lyapunov.hpp"
#include "settings/settings_error.hpp"

namespace exc::control {

AdaptiveComputedTorque::AdaptiveComputedTorque(const Model& model, const AdaptiveLawSettings& settings, double period,
                                               const EffortLimits& limits)
    : model_(model),
      ws_(model),
      settings_(settings),
      period_(period),
      limits_(limits),
      contact_(settings.adaptation.soil_contact),
      update_contact_(settings.adaptation.soil_contact),
      observer_(period, settings.adaptation.external_force.cutoff_hz),
      regression_filter_(settings.filter),
      identification_(settings.soil.theta_max, settings.adaptation.external_force.identification_memory, period,
                      settings.adaptation.external_force.force_scale),
      tip_filter_(first_order_gain(settings.filter.velocity_cutoff_hz, period)),
      tip_chain_filter_(first_order_gain(settings.filter.velocity_cutoff_hz, period)) {
  PidGains gains = settings.computed_torque.gains;
  if (settings.adaptation.integral_action) {
    const Mat12 A = integral_error_dynamics_matrix(gains.kp, gains.kv, gains.ki);
    Vec12 q;
    q << settings.adaptation.lyapunov_q_integral, settings.computed_torque.lyapunov_q;
    if (!solve_lyapunov(A, Mat12(q.asDiagonal()), P_))
      throw SettingsError("", 0, 0, "controller.ki", "A^T P + P A + Q = 0 (integral states) has no positive definite solution for kp, kv, ki and lyapunov_q_integral");
  } else {
    gains.ki.setZero();  // the paper's law: no integral state, zero rows and columns of P for it
    const Mat8 A = error_dynamics_matrix(gains.kp, gains.kv);
    Mat8 P8;
    if (!solve_lyapunov(A, Mat8(settings.computed_torque.lyapunov_q.asDiagonal()), P8))
      throw SettingsError("", 0, 0, "controller.kv", "A^T P + P A + Q = 0 has no positive definite solution for kp, kv and lyapunov_q");
    P_.bottomRightCorner<8, 8>() = P8;
  }
  feedback_.set_gains(gains);
  reset();
}

void AdaptiveComputedTorque::reset() {
  theta_hat_ = settings_.soil.theta_initial;
  contact_.reset();
  update_contact_.reset();
  observer_.reset();
  tip_force_.setZero();
  regression_filter_.reset();
  identification_.reset();
  tip_filter_.reset();
  tip_chain_filter_.reset();
  feedback_.reset();
  saturated_ = 0;
}

void AdaptiveComputedTorque::visit_state(StateVisitor& visitor) const {
  visitor.visit("adaptive observer estimate", observer_estimate());
  visitor.visit("adaptive identification covariance", identification_covariance());
  visitor.visit("adaptive regression filter", regression_filtered());
  visitor.visit("adaptive tip filter chain", tip_chain());
  visitor.visit("adaptive anchor tip filter", tip_filtered());
}

Vec6 AdaptiveComputedTorque::gamma() const {
  Vec6 g;
  for (int i = 0; i < 6; ++i) g[i] = settings_.adaptation.rate[i] > 0 ? 1 / settings_.adaptation.rate[i] : 0;
  return g;
}

ControlOutput AdaptiveComputedTorque::update(const ControlInput& in) {
  ControlOutput out;
  tracking_errors(in, out);
  out.theta_hat = theta_hat_;
  Mat4 M_a;
  Vec4 h_a;
  if (!model_at(model_, ws_, in.q, in.qd, last_tau_, out, M_a, h_a)) return out;

  out.rho = ws_.rho;
  // Contact and anchor (the controller's own estimate unless the caller knows them): without a map,
  // told by the tip force the observer found last cycle. On the tip lightly filtered: sensor noise
  // triggers eq. 11's shear early and walks the anchors away from the soil's, where a short lag only
  // delays the events; the composite update needs the soil's own events, and with the observer the
  // command's soil term does better with them too. The paper's law (no observer, or no applied
  // efforts to observe) takes the tip as measured: with its events late by the lag, its update read
  // the spring the soil had shed as its error's cause and ran away at high rates (the projection
  // test's 10x rate).
  const Vec2& tip_filtered = tip_filter_.update(ws_.rho);
  const bool observing = settings_.adaptation.external_force.observer && in.applied.valid;
  const Vec2& command_tip = observing ? tip_filtered : ws_.rho;
  const Vec2* tip_force = observer_.primed() ? &tip_force_ : nullptr;
  contact_.resolve(in.soil, command_tip, tip_force, out.in_soil, out.rho_env);
  bool in_soil_filtered = out.in_soil;
  Vec2 anchor_filtered = out.rho_env;
  if (!observing) update_contact_.resolve(in.soil, tip_filtered, tip_force, in_soil_filtered, anchor_filtered);
  const Vec4& qdd_for_y = settings_.adaptation.regressor_acceleration == RegressorAcceleration::desired ? in.qdd_d : in.qdd;
  const Vec2 rhodd = ws_.J_t * qdd_for_y + ws_.rhodd_bias;
  const Mat4x6 Y = soil_regressor(ws_.J_t, command_tip, ws_.rhod, rhodd, out.rho_env, out.in_soil);
  const Vec4 prediction = Y * theta_hat_;

  // What the model and the soil prediction leave unexplained of the applied efforts, now: the
  // observer's input.
  if (in.applied.valid) {
    observer_.update(in.applied.effort - (M_a * in.qdd + h_a) - prediction, in.applied.suspect);
    tip_force_ = tip_force_from_efforts(ws_.J_t, observer_.estimate() + prediction);
  }
  // The same for the update, every signal through one chain R (a filtered regressor), so that the
  // residual mixes signals of one time: R is the chain the filtered acceleration went through (the
  // estimator's two stages, L) and then the anchor's tip filter (F): the soil spring's stretch is
  // taken from the filtered tip the anchors come from, so its events fall when the anchors' do.
  const Vec2 rhod_measured = ws_.J_t * in.qd_measured;
  const Vec2 stretch = in_soil_filtered ? Vec2(tip_filtered - anchor_filtered) : Vec2::Zero();
  RegressionSignals raw;  // through L (then F, below, but for the stretch: F is in it already)
  raw << (in.applied.valid ? in.applied.effort : h_a), h_a, (in_soil_filtered ? rhod_measured : Vec2::Zero()), stretch;
  const RegressionSignals& l = regression_filter_.update(raw);
  TipFilterSignals on_l;  // already through L: through F
  on_l << l.head<10>(), M_a * in.qdd, (in_soil_filtered ? rhodd : Vec2::Zero());
  const TipFilterSignals& tip_chain = tip_chain_filter_.update(on_l);
  Mat2x6 S = Mat2x6::Zero();  // F_soil = S Theta, from the signals through R
  S(0, 0) = tip_chain[14];
  S(1, 3) = tip_chain[15];
  S(0, 1) = tip_chain[8];
  S(1, 4) = tip_chain[9];
  S(0, 2) = l[10];
  S(1, 5) = l[11];
  const Mat4x6 Y_filtered = ws_.J_t.transpose() * S;
  const Vec4 id_residual =
      tip_chain.head<4>() - (tip_chain.segment<4>(10) + tip_chain.segment<4>(4)) - Y_filtered * theta_hat_;
  out.disturbance = observer_.estimate();
  out.tip_force = tip_force_;

  const Vec4 v = in.qdd_d - feedback_.update(out.e, out.ed, period_, saturated_ | in.actuator_limited);
  out.tau_unsaturated = M_a * v + h_a + prediction;  // eq. 12
  if (observing) out.tau_unsaturated += observer_.estimate();
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

  identification_.fade();
  // Joints not driven as commanded, or whose applied effort does not follow the model: left out.
  const std::uint8_t off_dynamics = out.saturated | in.actuator_limited | in.applied.suspect;
  if ((out.in_soil || Y_filtered.any()) && off_dynamics != 0x0F) {
    Vec6 theta_dot = Vec6::Zero(), theta_step = Vec6::Zero();
    // Update law (eq. 27) from the tracking error.
    if (settings_.adaptation.rate.any()) {
      const Eigen::LDLT<Mat4> ldlt(M_a);
      const Mat4x6 Phi = ldlt.solve(Y);                       // M_a^-1 Y
      Vec4 BtPx = P_.bottomRows<4>() * z;                     // B^T P x (or z)
      // A joint not driven as commanded: its error is the limit's, not the soil's. A joint inside the
      // dead zone: its error is what the loop below the law leaves (the valves' resolution), not soil.
      for (int j = 0; j < 4; ++j)
        if (((off_dynamics >> j) & 1u) || std::abs(out.e[j]) < settings_.adaptation.tracking_dead_zone[j]) BtPx[j] = 0;
      theta_dot = -settings_.adaptation.rate.cwiseProduct(Phi.transpose() * BtPx);
    }
    // The composite term: least squares on the prediction error of the applied efforts, a dead zone
    // on each cylinder's residual (noise and what the model leaves out must not walk the estimates).
    const ExternalForceSettings& ef = settings_.adaptation.external_force;
    if (ef.identification_memory > 0 && in.applied.valid) {
      Vec4 r = Vec4::Zero();
      for (int j = 1; j < 4; ++j) {  // a dead zone on each cylinder's residual
        const double m = std::abs(id_residual[j]) - ef.dead_zone;
        r[j] = m > 0 ? std::copysign(m, id_residual[j]) : 0.0;
      }
      theta_step = identification_.measure(Y_filtered, r, static_cast<std::uint8_t>(~off_dynamics & 0x0E));
    }
    theta_hat_ = (theta_hat_ + period_ * theta_dot + theta_step).cwiseMax(settings_.soil.theta_min).cwiseMin(settings_.soil.theta_max);
  }
  return out;
}

}  // namespace exc::control
