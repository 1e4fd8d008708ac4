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

// What the law reads, its own (ControllerConfig's period, gains and lyapunov_q).
struct PidLawSettings {
  double period = 1e-3;  // s
  PidGains gains;
  Vec8 lyapunov_q = Vec8::Zero();  // Q of the reported x^T P x
};

class ComputedTorquePid final : public Controller {
 public:
  // The model must outlive the controller. Start-up: allocates (the Workspace, P).
  ComputedTorquePid(const Model& model, const PidLawSettings& settings, const EffortLimits& limits);
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
