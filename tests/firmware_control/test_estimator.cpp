#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "control/estimation/state_estimator.hpp"

using namespace exc;
using namespace exc::control;

TEST_CASE("firmware/estimator: slow motion passes with a small lag, acceleration from velocity alone") {
  StateEstimator est;  // 1 kHz, 25 Hz velocity, 15 Hz acceleration
  const double w = 2 * 3.14159265358979323846 * 0.5, amp = 0.2, dt = 1e-3;
  double worst_v = 0, worst_a = 0;
  for (int k = 0; k < 6000; ++k) {
    const double t = k * dt;
    const Vec4 v = Vec4::Constant(amp * w * std::cos(w * t));
    est.update(Vec4::Constant(amp * std::sin(w * t)), v);
    if (t > 1.0) {
      // Closed-form truth of the motion: the lag of a 0.5 Hz signal through both filters stays a
      // few per cent of the amplitude (group delays ~9 ms and ~11 ms).
      worst_v = std::max(worst_v, std::abs(est.velocity()[0] - amp * w * std::cos(w * t)));
      worst_a = std::max(worst_a, std::abs(est.acceleration()[0] + amp * w * w * std::sin(w * t)));
    }
  }
  const double v_amp = amp * w, a_amp = amp * w * w;
  CHECK(worst_v < 0.04 * v_amp);
  CHECK(worst_a < 0.10 * a_amp);
  CHECK(worst_a > 0);  // the filters do lag: a pass-through would be exact here
}

TEST_CASE("firmware/estimator: velocity noise is attenuated, the acceleration stays bounded") {
  StateEstimator est;
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.01);
  double sum_sq = 0, sum_sq_a = 0;
  int n = 0;
  for (int k = 0; k < 20000; ++k) {
    est.update(Vec4::Zero(), Vec4::Constant(noise(rng)));
    if (k > 1000) {
      sum_sq += est.velocity()[1] * est.velocity()[1];
      sum_sq_a += est.acceleration()[1] * est.acceleration()[1];
      ++n;
    }
  }
  // White noise through a 25 Hz 2nd-order low-pass at 1 kHz: variance ratio ~ pi fc / (sqrt2 fs) ~ 0.056.
  const double ratio = std::sqrt(sum_sq / n) / 0.01;
  CHECK(ratio < 0.35);
  CHECK(ratio > 0.1);
  CHECK(std::sqrt(sum_sq_a / n) < 0.01 * 2 * 3.14159 * 25);
}

TEST_CASE("firmware/estimator starts at the first measurement without a transient") {
  StateEstimator est;
  est.update(Vec4(0.1, 2.4, 2.5, 2.0), Vec4(0.2, 0.1, -0.1, 0.05));
  CHECK((est.velocity() - Vec4(0.2, 0.1, -0.1, 0.05)).norm() < 1e-15);
  CHECK(est.acceleration().norm() == 0);
  est.update(Vec4(0.1, 2.4, 2.5, 2.0), Vec4(0.2, 0.1, -0.1, 0.05));
  CHECK(est.acceleration().norm() < 1e-12);
}
