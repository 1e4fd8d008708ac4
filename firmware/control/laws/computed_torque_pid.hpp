#pragma once
// The baseline of the paper's comparison ("PID"): inverse-dynamics feed-forward of the closed chain
// with PID feedback inside it, no soil compensation:
//   tau_a = M_a(q) (qdd_d - K_v ed - K_p e - K_i int e) + h_a(q, qd)      (eq. 12 without Y Theta)
// Saturated to the effort limits; the integral is frozen on saturated joints (anti-windup).
// Lyapunov value reported: x^T P x with the same P as the adaptive law (tracking part only).
#include "control/control_types.hpp"
#include "control/laws/effort_limits.hpp"
#include "control/laws/pid.hpp"
#include "control/estimation/soil_contact.hpp"
#include "model/closed_chain.hpp"

namespace exc::control {

// The computed-torque law's own settings; the adaptive law adds its adaptation to these
// (adaptive_law_settings.hpp). ControllerConfig holds them as its `pid` member.
struct PidLawSettings {
  // Computed-torque error dynamics e'' + kv e' + kp e (+ ki int e for the PID baseline).
  // Order: swing (rad), boom, arm, bucket (m).
  PidGains gains = default_gains();
  // Q of A^T P + P A + Q = 0, diagonal, x = [e; ed] order: the adaptive law's (eqs. 21-25), and the
  // PID's reported x^T P x. Position weights ~kp make B^T P x lean on e (less on the filtered,
  // lagging ed). Per joint the weights offset the inverse-inertia scaling of Phi = M_a^-1 Y: the
  // light bucket would otherwise dominate the update and the heavy arm learn slowly (tuned on the
  // dig scene: docs/control.md).
  Vec8 lyapunov_q = (Vec8() << 64, 64, 640, 6.4, 1, 1, 10, 0.1).finished();

  static PidGains default_gains() {
    PidGains g;
    // omega_n = 8 rad/s (1.3 Hz), critically damped: below the oil-column frequencies of a 20 t
    // machine (1.5-6 Hz, machine.md), so the same gains suit a scene with hydraulics.
    g.kp = Vec4::Constant(64);    // 1/s^2
    g.kv = Vec4::Constant(16);    // 1/s
    g.ki = Vec4::Constant(100);   // 1/s^3: kv kp = 1024 > ki, stable (Routh)
    g.integral_limit = Vec4::Constant(0.05);
    return g;
  }
};
// The settings blob's field list (app/settings_blob.hpp): a field added above is added here too.
template <typename Visitor>
void visit_fields(Visitor& v, PidLawSettings& s) {
  v("gains", s.gains);
  v("lyapunov_q", s.lyapunov_q);
}

class ComputedTorquePid final : public Controller {
 public:
  // The model must outlive the controller. Start-up: allocates (the Workspace, P).
  ComputedTorquePid(const Model& model, const PidLawSettings& settings, double period, const EffortLimits& limits);
  void reset() override;
  ControlOutput update(const ControlInput& in) override;
  void visit_state(StateVisitor& visitor) const override { visitor.visit("pid integral", pid_.integral()); }
  Pid& pid() { return pid_; }
  const Pid& pid() const { return pid_; }

 private:
  const Model& model_;
  Workspace ws_;
  double period_;  // s: the only setting it keeps besides its gains (in pid_)
  EffortLimits limits_;
  Pid pid_;
  Mat8 P_ = Mat8::Identity();
  SoilContactEstimator anchor_;
  std::uint8_t saturated_ = 0;
  Vec4 last_tau_ = Vec4::Zero();
};

}  // namespace exc::control
