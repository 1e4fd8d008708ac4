#pragma once
// Passivity-based adaptive control (Slotine and Li), going beyond the paper: no measured
// acceleration is needed.
//   qd_r = qd_d - Lambda e,  qdd_r = qdd_d - Lambda ed,  s = qd - qd_r = ed + Lambda e
//   tau_a = M_a qdd_r + C_a qd_r + g_a + Y_r Theta_hat - K_D s
//   Y_r Theta = J_t^T F_r, F_r per axis = M rhodd_r + B rhod_r + K (rho - rho_env),
//     rhod_r = J_t qd_r, rhodd_r = J_t qdd_r + Jd_t qd_r
//   Theta_hat_dot = -Gamma^-1 Y_r^T s, projected onto [theta_min, theta_max]
//   V = 1/2 s^T M_a s + 1/2 Theta~^T Gamma Theta~ (+ e^T Lambda K_D e), Vdot = -s^T K_D s
// C_a qd_r + g_a comes from the model's bias_forces evaluated at (q, qd_r): that is
// C_a(q, qd_r) qd_r + g_a, not C_a(q, qd) qd_r. The difference, C_a(q, s) qd_r, is second order
// (|s| |qd_r|) and tiny for an excavator's joint speeds; it vanishes as s -> 0. Likewise Jd_t.
// K_D = diag(kd_j * M_a,jj(q)) so that one kd (1/s) suits joints whose inertias differ by 100x.
#include "control/control_types.hpp"
#include "control/laws/effort_limits.hpp"
#include "control/laws/regressor.hpp"
#include "control/laws/soil_parameter_bounds.hpp"
#include "control/estimation/soil_contact.hpp"
#include "model/closed_chain.hpp"

namespace exc::control {

// The law's own settings (controller.slotine_li; ControllerConfig's `slotine_li` member). It takes
// the soil parameters' bounds beside them (soil_parameter_bounds.hpp), shared with the adaptive law.
// Defaults: the same error bandwidth as the computed-torque laws, kv = lambda + kd, kp = lambda kd.
struct SlotineLiSettings {
  Vec4 lambda = Vec4::Constant(8);  // 1/s: s = ed + lambda e
  Vec4 kd = Vec4::Constant(8);      // 1/s: the damping of s, scaled by M_a
  Vec6 adaptation_rate = (Vec6() << 3e3, 3e5, 3e7, 3e3, 3e5, 3e7).finished();  // Gamma^-1 of its update
};
// The settings blob's field list (app/settings_blob.hpp): a field added above is added here too.
template <typename Visitor>
void visit_fields(Visitor& v, SlotineLiSettings& s) {
  v("lambda", s.lambda);
  v("kd", s.kd);
  v("adaptation_rate", s.adaptation_rate);
}

class SlotineLi final : public Controller {
 public:
  SlotineLi(const Model& model, const SlotineLiSettings& settings, const SoilParameterBounds& soil, double period,
            const EffortLimits& limits);
  void reset() override;
  ControlOutput update(const ControlInput& in) override;
  const Vec6& theta_hat() const { return theta_hat_; }

 private:
  const Model& model_;
  Workspace ws_;
  SlotineLiSettings settings_;
  SoilParameterBounds soil_;
  double period_;  // s
  EffortLimits limits_;
  Vec6 theta_hat_ = Vec6::Zero();
  SoilContactEstimator anchor_;
  Vec4 last_tau_ = Vec4::Zero();
};

}  // namespace exc::control
