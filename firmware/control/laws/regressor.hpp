#pragma once
// The soil regressor (paper eqs. 18-20; model.md s.5-6): Y Theta = J_t^T F_soil with
// Theta = [M_x B_x K_x M_z B_z K_z] and, per axis, F_soil = M rhodd + B rhod + K (rho - rho_env).
// Zero out of the soil. Y is 4 x 6; no allocation.
#include <Eigen/Core>

#include "model/types.hpp"

namespace exc::control {

inline Mat4x6 soil_regressor(const Mat2x4& J_t, const Vec2& rho, const Vec2& rhod, const Vec2& rhodd,
                             const Vec2& rho_env, bool in_soil) {
  if (!in_soil) return Mat4x6::Zero();
  Mat2x6 S = Mat2x6::Zero();  // F_soil = S Theta (eq. 9 per axis)
  S(0, 0) = rhodd.x();
  S(0, 1) = rhod.x();
  S(0, 2) = rho.x() - rho_env.x();
  S(1, 3) = rhodd.y();
  S(1, 4) = rhod.y();
  S(1, 5) = rho.y() - rho_env.y();
  return J_t.transpose() * S;  // eq. 20: tau_soil = J_t^T F_soil
}

// The soil force F_soil (bucket on soil, N) for parameters theta, same convention.
inline Vec2 soil_force(const Vec6& th, const Vec2& rho, const Vec2& rhod, const Vec2& rhodd,
                       const Vec2& rho_env) {
  return Vec2(th[0] * rhodd.x() + th[1] * rhod.x() + th[2] * (rho.x() - rho_env.x()),
              th[3] * rhodd.y() + th[4] * rhod.y() + th[5] * (rho.y() - rho_env.y()));
}

}  // namespace exc::control
