#include "sim_plant/coulomb_friction.hpp"

#include <algorithm>
#include <cmath>

namespace exc::plant {

DryFrictionImpulses dry_friction_impulses(const Mat4& inverse_mass, const Vec4& free_velocity, const Vec4& bound,
                                          const Vec4& guess) {
  DryFrictionImpulses r;
  r.impulse = guess.cwiseMax(-bound).cwiseMin(bound);
  r.velocity = free_velocity - inverse_mass * r.impulse;
  // Converged when no sweep changes a velocity by more than this (m/s, rad/s): far below any motion
  // the plant resolves, and what is left of it on a stuck function is set to exactly 0 below.
  constexpr double kTolerance = 1e-13;
  constexpr int kMaxSweeps = 100;
  for (int sweep = 1; sweep <= kMaxSweeps; ++sweep) {
    double change = 0;
    for (int i = 0; i < kNumActive; ++i) {
      if (bound[i] <= 0) continue;
      const double w = inverse_mass(i, i);
      const double next = std::clamp(r.impulse[i] + r.velocity[i] / w, -bound[i], bound[i]);
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
    if (bound[i] > 0 && std::abs(r.impulse[i]) < bound[i]) {
      r.stuck |= 1u << i;
      r.velocity[i] = 0;
    }
  return r;
}

}  // namespace exc::plant
