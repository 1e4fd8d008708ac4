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
// - rho_env: SoilAnchorEstimator on the controller's own rho (or given, in simulation tests).
// - Tip acceleration for Y: rhodd = J_t qdd_a + Jd_t qd_a with qdd_a the filtered estimate
//   (state_estimator.hpp) or qdd_d, by config (regressor_acceleration).
#include "control/controller_config.hpp"
#include "control/effort_limits.hpp"
#include "control/pid.hpp"
#include "control/regressor.hpp"
#include "control/soil_anchor_estimator.hpp"
#include "model/closed_chain.hpp"

namespace exc::control {

class AdaptiveComputedTorque final : public Controller {
 public:
  // The model must outlive the controller. Start-up: allocates (the Workspace, the Lyapunov solve).
  // Throws SettingsError if the gains give no SPD P.
  AdaptiveComputedTorque(const Model& model, const ControllerConfig& config, const EffortLimits& limits);
  void reset() override;
  ControlOutput update(const ControlInput& in) override;
  ControllerKind kind() const override { return ControllerKind::adaptive; }

  // P of V over z = [int e; e; ed] (without integral action the int e rows and columns are zero).
  const Mat12& lyapunov_p() const { return P_; }
  const Vec6& theta_hat() const { return theta_hat_; }
  void set_theta_hat(const Vec6& th) { theta_hat_ = th.cwiseMax(config_.theta_min).cwiseMin(config_.theta_max); }
  // The integral of e (with integral action; tests start from a given one).
  void set_error_integral(const Vec4& i) { feedback_.set_integral(i); }
  // Gamma of V (the inverse of the adaptation rates; a zero rate gives an infinite weight, so V is
  // reported with that parameter's term left out).
  Vec6 gamma() const;

 private:
  const Model& model_;
  Workspace ws_;
  ControllerConfig config_;
  EffortLimits limits_;
  Mat12 P_ = Mat12::Zero();
  Pid feedback_;                      // K_p e + K_v ed (+ K_i int e), the integral frozen on saturation
  std::uint8_t saturated_ = 0;
  Vec6 theta_hat_ = Vec6::Zero();
  SoilAnchorEstimator anchor_;
  Vec4 last_tau_ = Vec4::Zero();
};

}  // namespace exc::control
