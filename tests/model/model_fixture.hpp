#pragma once
// Shared by the model tests: the reference model, random valid states and a smooth trajectory of the
// active coordinates (with exact derivatives) inside the stroke limits.
#include <cmath>
#include <random>

#include "model/closed_chain.hpp"
#include "model/forward_dynamics.hpp"
#include "model/loop_closure.hpp"
#include "model/machine_reader.hpp"

namespace exc::test {

inline const Model& reference_model() {
  static const Model model = build_model(reference_machine());
  return model;
}

// Active coordinates drawn inside the limits (a 5 % margin from each stroke end), rates and
// accelerations of machine-like size.
struct RandomStates {
  explicit RandomStates(unsigned seed) : rng(seed) {}
  std::mt19937 rng;
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
  Vec4 q_a(const Model& m) {
    const Vec4 lo = m.machine.q_min(), hi = m.machine.q_max();
    Vec4 q;
    q[0] = uniform(-M_PI, M_PI);
    for (int k = 1; k < 4; ++k) {
      const double margin = 0.05 * (hi[k] - lo[k]);
      q[k] = uniform(lo[k] + margin, hi[k] - margin);
    }
    return q;
  }
  Vec4 qd_a() { return Vec4(uniform(-1, 1), uniform(-0.3, 0.3), uniform(-0.4, 0.4), uniform(-0.5, 0.5)); }
  Vec4 qdd_a() { return Vec4(uniform(-2, 2), uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)); }
};

// q_a(t) = centre + amplitude * sin(w t + phase), per axis, within the limits.
struct SmoothTrajectory {
  Vec4 centre, amplitude, w, phase;
  explicit SmoothTrajectory(const Model& m) {
    const Vec4 lo = m.machine.q_min(), hi = m.machine.q_max();
    centre << 0.2, 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2]), 0.5 * (lo[3] + hi[3]);
    amplitude << 1.0, 0.35 * (hi[1] - lo[1]), 0.35 * (hi[2] - lo[2]), 0.35 * (hi[3] - lo[3]);
    w << 0.9, 1.3, 1.7, 2.3;
    phase << 0.1, 0.7, -0.4, 1.9;
  }
  Vec4 q(double t) const { return centre + amplitude.cwiseProduct((w * t + phase).array().sin().matrix()); }
  Vec4 qd(double t) const {
    return amplitude.cwiseProduct(w).cwiseProduct((w * t + phase).array().cos().matrix());
  }
  Vec4 qdd(double t) const {
    return -amplitude.cwiseProduct(w).cwiseProduct(w).cwiseProduct((w * t + phase).array().sin().matrix());
  }
};

}  // namespace exc::test
