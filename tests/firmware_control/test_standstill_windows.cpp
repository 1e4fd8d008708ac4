// The standstill monitor's creep windows (app/creep_window.hpp) on made-up motions with known means:
// a steady creep, a function braking to rest, a ring on an oil spring (decaying, its window mean not
// quite zero) and a stuck spool's motion with a ring on it that slows by a third per window.
#include <doctest/doctest.h>

#include <cmath>
#include <functional>

#include "safety/creep_window.hpp"

using namespace exc;

namespace {

constexpr double kPeriod = 1e-3, kLength = 2.5, kLimit = 0.002, kSlowing = 0.2, kFast = 10;

// Feeds x(t) on the function 0 for `seconds`; returns the time the first creep was found (-1: none).
double first_creep(const std::function<double(double)>& x, double seconds) {
  safety::CreepWindow w;
  const Vec4 limit(kLimit, INFINITY, INFINITY, INFINITY);
  for (std::uint64_t k = 0; k * kPeriod <= seconds; ++k) {
    const double t = static_cast<double>(k) * kPeriod;
    if (w.update(Vec4(x(t), 0, 0, 0), k, kPeriod, kLength, limit, kSlowing, kFast) & 1u) return t;
  }
  return -1;
}

constexpr double kPi = 3.14159265358979323846;

}  // namespace

TEST_CASE("firmware/standstill windows: a steady creep over the rate is found when its second window closes, a braking function and a still one never") {
  CHECK(first_creep([](double t) { return 0.005 * t; }, 10) == doctest::Approx(2 * kLength).epsilon(1e-3));
  // Braking from 0.1 rad/s to rest in 0.5 s (then still), and nothing at all.
  CHECK(first_creep([](double t) { return t < 0.5 ? 0.1 * t - 0.1 * t * t : 0.025; }, 10) < 0);
  CHECK(first_creep([](double) { return 0.3; }, 10) < 0);
}

TEST_CASE("firmware/standstill windows: a decaying ring whose window mean is over ten times the rate is no creep (it turns within the window), and a motion as fast going one way is found at the first window") {
  // A swing ringing on its oil spring after a stop (2.6 s period, decaying over 3 s, from 0.12 rad
  // off its rest): its first window's mean is 0.028 rad/s (14x the rate) but it turned within it.
  const auto ring = [](double t) { return 0.12 * std::cos(2 * kPi * t / 2.6) * std::exp(-t / 3); };
  REQUIRE(std::abs(ring(kLength) - ring(0)) / kLength > kFast * kLimit);
  CHECK(first_creep(ring, 12) < 0);
  // A stuck spool's motion: one way, slowing by a third per 5 s, a small ring on it; its first
  // window's mean 0.074 rad/s: found when that window closes.
  const auto stuck = [](double t) { return 0.09 * t * std::pow(2.0 / 3.0, t / 5) + 0.002 * std::sin(2 * kPi * t / 2.6); };
  CHECK(first_creep(stuck, 12) == doctest::Approx(kLength).epsilon(1e-3));
}
