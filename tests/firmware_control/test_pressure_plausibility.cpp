// The chamber pressures' plausibility monitor on its own (safety/pressure_plausibility.hpp): its
// range from the machine file's hydraulics numbers, a jump against a spike that returns, a frozen
// reading only while the function moves and away from the circuit's clamps, a non-finite reading.
#include <doctest/doctest.h>

#include <limits>

#include "safety/pressure_plausibility.hpp"
#include "model/machine.hpp"
#include "model/machine_reader.hpp"

using namespace exc;
using safety::PressurePlausibility;
using safety::PressureTest;

namespace {

constexpr double kPeriod = 1e-3;

struct Feed {
  PressurePlausibility monitor;
  Vec4 q, v = Vec4::Zero();
  explicit Feed(const Machine& m, const safety::PressurePlausibilitySettings& s = {})
      : monitor(m, s, kPeriod), q(0.5 * (m.q_min() + m.q_max())) {
    q[0] = 0;
  }
  int sets = 0;
  // Feeds boom side A p (the other chambers at 5 MPa, boom B alternating by the bus's 1 kPa so that it
  // is never frozen); the chambers found.
  std::uint8_t set(double p) {
    Vec4 pa = Vec4::Constant(5e6), pb = Vec4::Constant(5e6);
    pa[1] = p;
    pb[1] += 1e3 * (++sets % 2);
    return monitor.update(true, true, pa, pb, q, v);
  }
};

constexpr std::uint8_t kBoomA = 1u << 2;

}  // namespace

TEST_CASE("firmware/pressure plausibility: the range is the floor and the highest relief plus override, each widened by the margin, from the machine file") {
  const Machine m = reference_machine();
  const safety::PressurePlausibilitySettings s;
  const safety::PressureLimits l = safety::pressure_limits(m, s);
  // The reference machine's numbers (machines/reference-20t.yaml): port relief 36.8 MPa, override
  // 1.5 MPa; vapour 0 and tank 0.3 MPa less the make-up's 0.2 MPa.
  CHECK(l.top[1] == doctest::Approx(36.8e6 + 1.5e6 + s.range_margin));
  CHECK(l.top[0] == doctest::Approx(34.3e6 + 1.5e6 + s.range_margin));
  CHECK(l.floor[1] == doctest::Approx(0.0 - s.range_margin));
  Feed f(m);
  f.set(10e6);
  int sets = 0;
  std::uint8_t found = 0;
  while (found == 0 && sets < 100) {
    found = f.set(l.top[1] + 1e3);  // a drift would reach it slowly; here it stays beyond the top
    ++sets;
    if (sets == 1) CHECK(found == 0);
  }
  // The first set beyond is also a jump; the debounce counts both alike.
  CHECK(found == kBoomA);
  CHECK(sets == s.debounce);
  Feed g(m);
  g.set(10e6);
  found = 0;
  for (int k = 0; k < s.debounce && found == 0; ++k) found = g.set(std::numeric_limits<double>::quiet_NaN());
  CHECK(found == kBoomA);
  CHECK(g.monitor.test_of(2) == PressureTest::range);
}

TEST_CASE("firmware/pressure plausibility: a jump beyond what the oil can make for the debounce is found, a one-set spike that returns and a ramp at the oil's rate are not") {
  const Machine m = reference_machine();
  const safety::PressurePlausibilitySettings s;
  Feed f(m);
  f.set(10e6);
  f.set(10e6);
  const double allowed = f.monitor.step_allowed(2);  // rise per set at this stroke
  REQUIRE(allowed > 0);
  // A ramp at 0.9 of the allowance for 10 sets: no fault.
  double p = 10e6;
  for (int k = 0; k < 10; ++k) CHECK(f.set(p += 0.9 * allowed) == 0);
  CHECK(f.monitor.worst_step_ratio(2) < 1);
  // A spike of 5x for one set, back the next: no fault (the debounce).
  CHECK(f.set(p + 5 * allowed) == 0);
  for (int k = 0; k < 5; ++k) CHECK(f.set(p) == 0);
  // A jump of (debounce + 1)x that stays: found on the debounce's set, as a jump.
  int sets = 0;
  std::uint8_t found = 0;
  while (found == 0 && sets < 20) {
    found = f.set(p + (s.debounce + 1) * allowed);
    ++sets;
  }
  CHECK(found == kBoomA);
  CHECK(sets == s.debounce);
  CHECK(f.monitor.test_of(2) == PressureTest::step);
}

TEST_CASE("firmware/pressure plausibility: a bit-identical reading is frozen after frozen_sets sets of motion, not at rest nor at the tank's level") {
  const Machine m = reference_machine();
  safety::PressurePlausibilitySettings s;
  s.frozen_sets = 50;
  Feed f(m, s);
  // At rest for 3x the window: no fault.
  for (int k = 0; k < 3 * s.frozen_sets; ++k) CHECK(f.set(8e6) == 0);
  // Moving at the tank's level: the circuit holds it there, no fault.
  Feed low(m, s);
  low.v[1] = 0.5 * m.speed_max()[1];
  for (int k = 0; k < 3 * s.frozen_sets; ++k) CHECK(low.set(m.hydraulics.tank_pressure) == 0);
  // Moving, loaded: found on the frozen_sets-th identical set after the first.
  f.v[1] = low.v[1];
  int sets = 0;
  std::uint8_t found = 0;
  while (found == 0 && sets < 3 * s.frozen_sets) {
    found = f.set(8e6);
    ++sets;
  }
  CHECK(found == kBoomA);
  CHECK(sets == s.frozen_sets);
  CHECK(f.monitor.test_of(2) == PressureTest::frozen);
  // A reading that changes by one bus quantum (1 kPa) now and then restarts the count.
  Feed g(m, s);
  g.v[1] = f.v[1];
  for (int k = 0; k < 3 * s.frozen_sets; ++k) CHECK(g.set(8e6 + 1e3 * ((k / (s.frozen_sets - 1)) % 2)) == 0);
}
