#pragma once
// The soil parameters from the prediction error of the applied efforts (the composite update's
// second term, beyond the paper): recursive least squares, written as a Kalman filter on parameters
// that drift as a slow random walk, in the parameters' own scale (theta_n = Theta / scale):
//   time:    P <- P + (P0 - P) T / memory             (old information fades over `memory` seconds;
//                                                       P never exceeds P0 = I, the prior of one scale)
//   measure: G = P Ys^T (n0^2 I + Ys P Ys^T)^-1,  theta_n += G r,  P <- (I - G Ys) P
// with Ys = Y S the rows of the regressor the residual r belongs to (the cylinders this cycle's
// applied efforts can be trusted on) and n0 the residual's noise (N). Least squares weighs each
// direction by how much the data excite it: the soil's spring is excited 10x more than its damper
// and 100x more than its mass, which a scalar gradient rate would learn at 100x and 10^4x different
// speeds. One update costs a 3 x 3 solve. Allocation-free.
#include <cstdint>

#include <Eigen/Cholesky>

#include "model/types.hpp"

namespace exc::control {

class SoilLeastSquares {
 public:
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  SoilLeastSquares() = default;
  // scale: each parameter's unit (its upper bound); memory (s); period of the calls (s); noise n0 (N).
  SoilLeastSquares(const Vec6& scale, double memory, double period, double noise)
      : scale_(scale), fade_(memory > 0 ? period / memory : 0), noise2_(noise * noise) {
    reset();
  }
  void reset() { P_ = prior(); }
  // Fades old information; call every cycle.
  void fade() { P_ += fade_ * (prior() - P_); }
  // The change of Theta (physical units) that one measurement asks for: the cylinders' rows of the
  // regressor Y (N per unit of Theta) whose bit is set in `rows`, and their residuals r (N).
  Vec6 measure(const Mat4x6& Y, const Vec4& r, std::uint8_t rows) {
    Eigen::Matrix<double, 3, 6> Ys = Eigen::Matrix<double, 3, 6>::Zero();
    Eigen::Vector3d rr = Eigen::Vector3d::Zero();
    for (int j = 1; j < 4; ++j) {
      if (!((rows >> j) & 1u)) continue;
      Ys.row(j - 1) = Y.row(j).cwiseProduct(scale_.transpose());
      rr[j - 1] = r[j];
    }
    const Eigen::Matrix<double, 6, 3> PYt = P_ * Ys.transpose();
    const Eigen::Matrix3d A = Eigen::Matrix3d::Identity() * noise2_ + Ys * PYt;
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(A);
    const Eigen::Matrix<double, 6, 3> G = ldlt.solve(PYt.transpose()).transpose();
    P_ -= G * PYt.transpose();
    P_ = 0.5 * (P_ + P_.transpose());  // symmetric against round-off
    return scale_.cwiseProduct(G * rr);
  }
  const Mat6& covariance() const { return P_; }
  // P0: one scale for the damper and the spring; the soil's added mass is not identified (its term,
  // M_t rhodd, is a few hundred newtons beside tens of kN: what the residual could say of it is the
  // filtered acceleration's error, not the soil's mass).
  static Mat6 prior() { return Vec6(0, 1, 1, 0, 1, 1).asDiagonal(); }

 private:
  Vec6 scale_ = Vec6::Ones();
  double fade_ = 0, noise2_ = 1;
  Mat6 P_ = Mat6::Identity();
};

}  // namespace exc::control
