#include "sim_plant/coulomb_friction.hpp"

#include <algorithm>
#include <cmath>

namespace exc::plant {

DryFrictionImpulses dry_friction_impulses(const Mat4& inverse_mass, const Vec4& free_velocity, const Vec4& bound,
                                          const Vec4& guess) {
  return dry_friction_impulses(inverse_mass, free_velocity, -bound, bound, guess);
}

DryFrictionImpulses dry_friction_impulses(const Mat4& inverse_mass, const Vec4& free_velocity, const Vec4& lower,
                                          const Vec4& upper, const Vec4& guess) {
  DryFrictionImpulses r;
  r.impulse = guess.cwiseMax(lower).cwiseMin(upper);
  r.velocity = free_velocity - inverse_mass * r.impulse;
  // Converged when no sweep changes a velocity by more than this (m/s, rad/s): far below any motion
  // the plant resolves, and what is left of it on a stuck function is set to exactly 0 below.
  constexpr double kTolerance = 1e-13;
  constexpr int kMaxSweeps = 100;
  const auto active = [&](int i) { return lower[i] < 0 || upper[i] > 0; };
  for (int sweep = 1; sweep <= kMaxSweeps; ++sweep) {
    double change = 0;
    for (int i = 0; i < kNumActive; ++i) {
      if (!active(i)) continue;
      const double w = inverse_mass(i, i);
      const double next = std::clamp(r.impulse[i] + r.velocity[i] / w, lower[i], upper[i]);
      const double d = next - r.impulse[i];
      if (d == 0) continue;
      r.velocity -= inverse_mass.col(i) * d;
      r.impulse[i] = next;
      change = std::max(change, std::abs(d) * w);
    }
    r.sweeps = sweep;
    if (change <= kTolerance) break;
  }
  for (int i = 0; i < kNumActive; ++i)
    if (active(i) && r.impulse[i] > lower[i] && r.impulse[i] < upper[i]) {
      r.stuck |= 1u << i;
      r.velocity[i] = 0;
    }
  return r;
}

}  // namespace exc::plant
