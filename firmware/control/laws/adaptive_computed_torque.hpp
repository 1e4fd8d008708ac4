#pragma once
// Adaptive computed torque with soil compensation (paper eqs. 12-28, as corrected in model.md s.6):
//   tau_a = M_a(q) (qdd_d - K_v ed - K_p e) + h_a(q, qd) + Y(q, qd, qdd) Theta_hat      (eq. 12)
//   Y Theta = J_t^T F_soil, Theta = [M_x B_x K_x M_z B_z K_z]                          (eqs. 18-20)
//   e = q_a - q_d, x = [e; ed], A = [0 I; -K_p -K_v], B = [0; I]
//   A^T P + P A + Q = 0, solved once at construction                                  (eqs. 24-25)
//   Theta_hat_dot = -Gamma^-1 Phi^T B^T P x, Phi = M_a^-1 Y                           (eq. 27)
//   V = x^T P x + Theta~^T Gamma Theta~, Theta~ = Theta_hat - Theta, Vdot = -x^T Q x   (eqs. 26, 28)
// Sign check: with the plant M_a qdd + h_a + J_t^T F_soil = tau_a the error obeys
// edd + K_v ed + K_p e = Phi Theta~, so Vdot = -x^T Q x + 2 Theta~^T (Phi^T B^T P x + Gamma Theta_hat_dot).
// Beyond the paper, optional (controller.integral_action): integral action, qdd_d - K_v ed - K_p e
// - K_i int e, with z = [int e; e; ed], A = [0 I 0; 0 0 I; -K_i -K_p -K_v], B = [0; 0; I] in place of
// x, A, B above; the same proof (the error obeys edd + K_v ed + K_p e + K_i int e = Phi Theta~).
// Decisions the paper leaves open (docs/control.md):
// - Update law integrated by explicit Euler at the control period, then projected onto
//   [theta_min, theta_max] per parameter. Gamma is diagonal, so the clamp is the projection in the
//   Gamma metric and V stays non-increasing.
// - Saturation: a joint whose effort saturated (or whose command the actuator-lag stage clamped) does
//   not follow the error dynamics above, so its error is left out of the update (its term of B^T P x
//   is zeroed: P is block-diagonal per joint); the other joints keep adapting. Before, any saturated
//   joint froze the whole update, so a swing at its torque limit (which the soil regressor does not
//   even act on: J_t has no swing column) stopped the arm and bucket from learning the soil.
// - Contact and rho_env: SoilContactEstimator (soil_contact.hpp): the site map, or the observer's tip
//   force (below), or given (simulation tests).
// Beyond the paper, on by default (controller.external_force; the paper's law is observer: false,
// prediction_rate: 0), for the machine the firmware really drives:
// - An external force observer (external_force_observer.hpp): r = tau_applied - M_a qdd - h_a -
//   Y Theta_hat, with tau_applied measured (chamber pressures) or modelled (a force-commanded
//   machine); its low-pass d_hat joins eq. 12: tau = ... + Y Theta_hat + d_hat. Through valves the
//   force loop drives the cylinders toward this command; a steady error of the model (the soil between
//   re-anchorings, friction, a wrong mass) would otherwise be a steady force error that the valves
//   turn into motion.
// - A composite update (Slotine and Li's composite adaptation, normalised): besides eq. 27's tracking
//   term, Theta_hat_dot += gamma_p S (Y S)^T W dz(r) / (n0^2 + |W (Y S)|^2), the gradient of the
//   prediction error of the applied efforts, with S = diag(theta_max) (each parameter in units of its
//   range), W selecting the cylinders not suspect this cycle, dz a dead zone per cylinder, n0 the
//   force scale. Normalised, a parameter the residual excites converges at about gamma_p whatever
//   the soil's scale, so one rate fits every machine and interface. Projection as below.
// - Pauses: a joint whose applied effort is known not to follow the model (a valve fully open, a
//   relief or make-up valve open, the pumps short: ControlInput::applied.suspect) is left out of both
//   terms, as a saturated one is.
// - Tip acceleration for Y: rhodd = J_t qdd_a + Jd_t qd_a with qdd_a the filtered estimate
//   (state_estimator.hpp) or qdd_d, by config (regressor_acceleration).
#include "control/control_types.hpp"
#include "control/laws/adaptive_law_settings.hpp"
#include "control/laws/effort_limits.hpp"
#include "control/laws/pid.hpp"
#include "control/laws/regressor.hpp"
#include "control/estimation/external_force_observer.hpp"
#include "control/estimation/soil_contact.hpp"
#include "control/estimation/soil_identification.hpp"
#include "control/estimation/state_estimator.hpp"
#include "model/closed_chain.hpp"

namespace exc::control {

class AdaptiveComputedTorque final : public Controller {
 public:
  // The model must outlive the controller. Start-up: allocates (the Workspace, the Lyapunov solve).
  // Throws SettingsError if the gains give no SPD P.
  AdaptiveComputedTorque(const Model& model, const AdaptiveLawSettings& settings, double period, const EffortLimits& limits);
  void reset() override;
  ControlOutput update(const ControlInput& in) override;
  void visit_state(StateVisitor& visitor) const override;

  // P of V over z = [int e; e; ed] (without integral action the int e rows and columns are zero).
  const Mat12& lyapunov_p() const { return P_; }
  const Vec6& theta_hat() const { return theta_hat_; }
  void set_theta_hat(const Vec6& th) { theta_hat_ = th.cwiseMax(settings_.soil.theta_min).cwiseMin(settings_.soil.theta_max); }
  // The integral of e (with integral action; tests start from a given one).
  void set_error_integral(const Vec4& i) { feedback_.set_integral(i); }
  // Gamma of V (the inverse of the adaptation rates; a zero rate gives an infinite weight, so V is
  // reported with that parameter's term left out).
  Vec6 gamma() const;
  // The composite update's memory (visit_state shows it: it decays while the machine holds).
  const Vec4& observer_estimate() const { return observer_.estimate(); }
  const Mat6& identification_covariance() const { return identification_.covariance(); }
  const Eigen::Matrix<double, 12, 1>& regression_filtered() const { return regression_filter_.value(); }
  const Eigen::Matrix<double, 16, 1>& tip_chain() const { return tip_chain_filter_.value(); }
  const Vec2& tip_filtered() const { return tip_filter_.value(); }

 private:
  const Model& model_;
  Workspace ws_;
  AdaptiveLawSettings settings_;
  double period_;  // s, the control period the update is integrated at
  EffortLimits limits_;
  Mat12 P_ = Mat12::Zero();
  Pid feedback_;                      // K_p e + K_v ed (+ K_i int e), the integral frozen on saturation
  std::uint8_t saturated_ = 0;
  Vec6 theta_hat_ = Vec6::Zero();
  SoilContactEstimator contact_;         // on the measured tip: the command's soil term
  SoilContactEstimator update_contact_;  // on the filtered tip: the composite update's regressor
  ExternalForceObserver observer_;
  Vec2 tip_force_ = Vec2::Zero();     // the observer's tip force of the last cycle (contact without a map)
  Vec4 last_tau_ = Vec4::Zero();
  // The composite update's signals as the acceleration is filtered: applied efforts, h_a, the tip's
  // velocity and the soil spring's stretch (x, z).
  using RegressionSignals = Eigen::Matrix<double, 12, 1>;
  EstimatorLowPass<12> regression_filter_;
  SoilLeastSquares identification_;
  FirstOrderLowPass<2> tip_filter_;  // the anchor rule's tip filter (first order at the velocity cut-off)
  // The tip filter's stage for the update's other signals: applied efforts, h_a, the tip's velocity
  // (all through L first), M_a qdd and the tip's acceleration (through L by the estimator).
  using TipFilterSignals = Eigen::Matrix<double, 16, 1>;
  FirstOrderLowPass<16> tip_chain_filter_;
};

}  // namespace exc::control
