#pragma once
// PID feedback per active joint, in acceleration units (it sits inside the computed-torque law, so
// the gains are the closed-loop error dynamics: e'' + Kv e' + Kp e + Ki int(e) = 0).
// Anti-windup: conditional integration (a joint's integrator is frozen while its effort saturates)
// plus a clamp of each integral to +-integral_limit. No allocation.
#include <algorithm>
#include <cstdint>

#include "control/laws/effort_limits.hpp"

namespace exc::control {

struct PidGains {
  Vec4 kp = Vec4::Zero(), kv = Vec4::Zero(), ki = Vec4::Zero();
  Vec4 integral_limit = Vec4::Constant(1e300);  // |int e dt| bound per joint (m s or rad s)
};
// The settings blob's field list (app/settings_blob.hpp): a field added above is added here too.
template <typename Visitor>
void visit_fields(Visitor& v, PidGains& g) {
  v("kp", g.kp);
  v("kv", g.kv);
  v("ki", g.ki);
  v("integral_limit", g.integral_limit);
}

class Pid {
 public:
  explicit Pid(const PidGains& g = {}) : gains_(g) {}
  void set_gains(const PidGains& g) { gains_ = g; }
  const PidGains& gains() const { return gains_; }
  void reset() { integral_.setZero(); }
  void set_integral(const Vec4& i) { integral_ = i; }
  const Vec4& integral() const { return integral_; }

  // Feedback acceleration Kp e + Kv ed + Ki int(e); the integral advances by e dt on every joint
  // that did not saturate on the previous step.
  Vec4 update(const Vec4& e, const Vec4& ed, double dt, std::uint8_t saturated_last_step) {
    for (int j = 0; j < kNumActive; ++j) {
      if (!is_saturated(saturated_last_step, j)) integral_[j] += e[j] * dt;
      integral_[j] = std::clamp(integral_[j], -gains_.integral_limit[j], gains_.integral_limit[j]);
    }
    return gains_.kp.cwiseProduct(e) + gains_.kv.cwiseProduct(ed) + gains_.ki.cwiseProduct(integral_);
  }

 private:
  PidGains gains_;
  Vec4 integral_ = Vec4::Zero();
};

}  // namespace exc::control
