#pragma once
// The external efforts on the joints, from what the machine applied and the model (beyond the paper;
// a disturbance observer). With the plant M_a qdd + h_a + tau_ext = tau_applied,
//   r = tau_applied - M_a(q) qdd - h_a(q, qd) - Y Theta_hat
// is what the rigid-body model and the soil prediction Y Theta_hat do not explain: a wrong soil
// estimate, friction, a wrong mass model, the soil's re-anchoring between the estimate's events. The
// law adds its low-pass d_hat to eq. 12's command, so a steady error of the model does not become a
// steady force error, and the composite update learns Theta from r (adaptive_computed_torque.hpp).
// tau_applied is measured on a hydraulic machine (chamber pressures x areas) and modelled on a
// force-commanded one (the command through the actuator's known lag); qdd is the state estimator's
// filtered acceleration, so the cut-off stays below its band. Allocation-free.
#include <cmath>
#include <cstdint>

#include <Eigen/Cholesky>

#include "control/estimation/state_estimator.hpp"
#include "model/types.hpp"

namespace exc::control {

class ExternalForceObserver {
 public:
  ExternalForceObserver() = default;
  // period of the calls (s); cutoff of the first-order low-pass (Hz).
  ExternalForceObserver(double period, double cutoff_hz)
      : alpha_(first_order_gain(cutoff_hz, period)) {}

  void reset() {
    primed_ = 0;
    estimate_.setZero();
  }
  // One cycle with the residual r; a joint whose bit is set in `hold` keeps its estimate (its
  // effort is known not to follow the model this cycle). A joint's first trusted residual is taken
  // as it is (no start-up transient).
  const Vec4& update(const Vec4& residual, std::uint8_t hold) {
    for (int j = 0; j < kNumActive; ++j) {
      const std::uint8_t bit = static_cast<std::uint8_t>(1u << j);
      if (hold & bit) continue;
      estimate_[j] = (primed_ & bit) ? estimate_[j] + alpha_ * (residual[j] - estimate_[j]) : residual[j];
      primed_ |= bit;
    }
    return estimate_;
  }
  const Vec4& estimate() const { return estimate_; }
  // Every cylinder has had a trusted residual (the tip force below is then meaningful).
  bool primed() const { return (primed_ & 0x0E) == 0x0E; }

 private:
  double alpha_ = 1.0;
  std::uint8_t primed_ = 0;  // bit j: joint j has had a trusted residual
  Vec4 estimate_ = Vec4::Zero();
};

// The force on the bucket tip (x, z in the swing plane) that best explains the external efforts of
// boom, arm and bucket through tau = J_t^T F (eq. 20): least squares over the three cylinders (the
// swing has no column of J_t). Zero where J_t is degenerate.
inline Vec2 tip_force_from_efforts(const Mat2x4& J_t, const Vec4& tau_ext) {
  const Eigen::Matrix<double, 2, 3> J = J_t.rightCols<3>();
  const Eigen::Matrix2d JJt = J * J.transpose();
  const Eigen::LDLT<Eigen::Matrix2d> ldlt(JJt);
  if (ldlt.info() != Eigen::Success || !(std::abs(JJt.determinant()) > 1e-12)) return Vec2::Zero();
  return ldlt.solve(J * tau_ext.tail<3>());
}

}  // namespace exc::control
