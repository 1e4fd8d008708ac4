#pragma once
// Plausibility of the eight chamber pressures the valve stage's force loop closes on (docs/safety.md,
// H4): a wrong pressure sensor makes the force loop push what it should not. Three tests per chamber,
// each debounced, counted in sensor sets (never timed):
//   range   the reading below the circuit's floor (vapour pressure) or above the highest pressure
//           the chamber can reach (its relief plus the relief's override at the pumps' flow), each
//           widened by range_margin (a transmitter's error);
//   step    the reading moves faster than the oil can: dp/dt = beta / V (Q - A v) with V the
//           chamber's volume at the measured stroke, v the larger of the measured speed and the
//           function's top speed, Q in: the pumps' whole flow (a meter-in, a make-up valve), Q out:
//           the fully open meter-out at the last plausible pressure (or the pumps' flow through a
//           relief), times step_factor (the nominal bulk modulus and volumes against the real ones).
//           A follower tracks the reading at those rates; the reading off the follower in `debounce`
//           sets in a row is a jump (a single spike that returns is not);
//   frozen  the reading bit-identical in frozen_sets sets in a row in which the function moves
//           (faster than moving_share of its top speed), between the circuit's clamps: a stuck-at
//           sensor. At the tank/vapour floor or at a relief the circuit itself holds a chamber still,
//           so no set there counts. Quantisation makes a slowly changing pressure repeat for a while:
//           the window is long against it (docs/safety.md gives the longest seen without a fault).
// Inactive (not commanding, no pressures): nothing counted, the follower restarts at the readings.
// Fixed-size state, no allocation.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "model/hydraulic_geometry.hpp"
#include "model/machine.hpp"
#include "model/types.hpp"

namespace exc::safety {

struct PressurePlausibilitySettings {
  bool enabled = true;
  double range_margin = 0.5e6;  // Pa beyond the floor and the top (about 1 % of a 60 MPa transmitter's span)
  // The oil's fastest change times this: the effective bulk modulus lies in 0.7-1.2 GPa with hoses
  // (hydraulics.md), so the nominal one can be off by up to 1.7x; 2 covers it.
  double step_factor = 2;
  // Sensor sets in a row, bit-identical while moving. The bus carries 1 kPa: a pressure changing by
  // less than 2 kPa/s repeats for half a second, so the window is long against that.
  int frozen_sets = 500;
  double moving_share = 0.02;   // of the function's top speed: faster is "moving"
  int debounce = 3;             // sensor sets in a row for the range and the step tests
};
// The settings blob's field list (app/settings_blob.hpp): a field added above is added here too.
template <typename Visitor>
void visit_fields(Visitor& v, PressurePlausibilitySettings& s) {
  v("enabled", s.enabled);
  v("range_margin", s.range_margin);
  v("step_factor", s.step_factor);
  v("frozen_sets", s.frozen_sets);
  v("moving_share", s.moving_share);
  v("debounce", s.debounce);
}

enum class PressureTest : std::uint8_t { none, range, step, frozen };
const char* to_string(PressureTest test);

// What the tests need of the nominal machine, derived once at start-up.
struct PressureLimits {
  Vec4 floor = Vec4::Zero();       // Pa, lowest plausible reading per function (both chambers)
  Vec4 top = Vec4::Zero();         // Pa, highest plausible reading
  Vec4 clamp_low = Vec4::Zero();   // Pa: at or below, the circuit's floor holds the chamber (no frozen count)
  Vec4 clamp_high = Vec4::Zero();  // Pa: at or above, a relief holds it
  Vec4 meter_out_a = Vec4::Zero(), meter_out_b = Vec4::Zero();  // fully open meter-out gains, m^3/s/sqrt(Pa)
  double pump_flow = 0, tank_pressure = 0, laminar_pressure = 1;
  Vec4 area_a = Vec4::Zero(), area_b = Vec4::Zero();  // m^2 (swing m^3/rad)
  Vec4 q_min = Vec4::Zero(), q_max = Vec4::Zero();
  Vec4 speed_max = Vec4::Zero();
  double bulk_modulus = 1e9, dead_volume = 0, swing_volume = 0;
};
PressureLimits pressure_limits(const Machine& nominal, const PressurePlausibilitySettings& s);

class PressurePlausibility {
 public:
  static constexpr int kChambers = 8;  // chamber c = 2 i + side: function i, side 0 = A (bore, port A), 1 = B

  PressurePlausibility() = default;
  PressurePlausibility(const Machine& nominal, const PressurePlausibilitySettings& s, double period)
      : s_(s), limits_(pressure_limits(nominal, s)), period_(period) {}

  // One cycle. fresh: a new sensor set arrived this cycle (only fresh sets are judged; the step's
  // allowance grows with the cycles since the last one). Returns the chambers found this cycle
  // (bit c), once per episode; test_of() says which test.
  std::uint8_t update(bool active, bool fresh, const Vec4& p_a, const Vec4& p_b, const Vec4& q, const Vec4& v) {
    if (!active || !s_.enabled) {
      primed_ = false;
      run_range_.fill(0);
      run_step_.fill(0);
      run_frozen_.fill(0);
      return 0;
    }
    ++cycles_since_fresh_;
    if (!fresh) return 0;
    std::uint8_t found = 0;
    for (int i = 0; i < 4; ++i) {
      const bool moving = std::abs(v[i]) > s_.moving_share * limits_.speed_max[i];
      const double speed = std::max(std::abs(v[i]), limits_.speed_max[i]);
      for (int side = 0; side < 2; ++side) {
        const int c = 2 * i + side;
        const double p = side == 0 ? p_a[i] : p_b[i];
        if (!primed_) {
          follower_[c] = last_[c] = p;
          continue;
        }
        // range
        const bool out = !(p >= limits_.floor[i] && p <= limits_.top[i]);  // NaN is out
        if (count(run_range_[c], out, s_.debounce)) report(found, c, PressureTest::range);
        // step: the follower moves towards the reading at the oil's fastest rate
        const double area = side == 0 ? limits_.area_a[i] : limits_.area_b[i];
        const double per_flow = s_.step_factor * limits_.bulk_modulus / volume(i, side, q[i]) * period_ * cycles_since_fresh_;
        const double meter_out = (side == 0 ? limits_.meter_out_a[i] : limits_.meter_out_b[i]) *
                                 orifice_unit_flow(std::max(0.0, follower_[c] - limits_.tank_pressure), limits_.laminar_pressure);
        const double rise = per_flow * (limits_.pump_flow + area * speed);
        const double fall = per_flow * (std::max(limits_.pump_flow, meter_out) + area * speed);
        step_allowed_[c] = rise;
        const double off = p - follower_[c];
        follower_[c] += std::clamp(off, -fall, rise);
        const double allowed = off > 0 ? rise : fall;
        const bool jumped = std::isfinite(p) && std::abs(p - follower_[c]) > 0;
        worst_step_ratio_[c] = std::max(worst_step_ratio_[c], std::abs(off) / allowed);
        if (count(run_step_[c], jumped, s_.debounce)) report(found, c, PressureTest::step);
        if (!std::isfinite(follower_[c])) follower_[c] = p;
        // frozen: only moving sets between the circuit's clamps count; a change restarts the count
        const bool clamped = p <= limits_.clamp_low[i] || p >= limits_.clamp_high[i];
        if (p != last_[c]) {
          run_frozen_[c] = 0;
        } else if (moving && !clamped) {
          ++run_frozen_[c];
          longest_frozen_[c] = std::max(longest_frozen_[c], run_frozen_[c]);
          if (run_frozen_[c] == s_.frozen_sets) report(found, c, PressureTest::frozen);
        }
        last_[c] = p;
      }
    }
    primed_ = true;
    cycles_since_fresh_ = 0;
    return found;
  }

  PressureTest test_of(int chamber) const { return test_[static_cast<std::size_t>(chamber)]; }
  // For reports and margins: the largest step over its allowance (1: the edge) and the longest run of
  // moving sets with a bit-identical reading, per chamber, since construction.
  double worst_step_ratio(int chamber) const { return worst_step_ratio_[static_cast<std::size_t>(chamber)]; }
  int longest_frozen(int chamber) const { return longest_frozen_[static_cast<std::size_t>(chamber)]; }
  double step_allowed(int chamber) const { return step_allowed_[static_cast<std::size_t>(chamber)]; }
  const PressureLimits& limits() const { return limits_; }
  const PressurePlausibilitySettings& settings() const { return s_; }

 private:
  // Counts a failing test; true on the set that completes the debounce.
  static bool count(int& run, bool failing, int debounce) {
    run = failing ? run + 1 : 0;
    return run == debounce;
  }
  void report(std::uint8_t& found, int c, PressureTest test) {
    found |= static_cast<std::uint8_t>(1u << c);
    test_[static_cast<std::size_t>(c)] = test;
  }
  double volume(int i, int side, double q) const {
    if (i == 0) return limits_.swing_volume;
    const double stroke = side == 0 ? q - limits_.q_min[i] : limits_.q_max[i] - q;
    const double area = side == 0 ? limits_.area_a[i] : limits_.area_b[i];
    return limits_.dead_volume + area * std::clamp(stroke, 0.0, limits_.q_max[i] - limits_.q_min[i]);
  }

  PressurePlausibilitySettings s_;
  PressureLimits limits_;
  double period_ = 1e-3;
  bool primed_ = false;
  int cycles_since_fresh_ = 0;
  std::array<double, kChambers> follower_{}, last_{}, worst_step_ratio_{}, step_allowed_{};
  std::array<int, kChambers> run_range_{}, run_step_{}, run_frozen_{}, longest_frozen_{};
  std::array<PressureTest, kChambers> test_{};
};

}  // namespace exc::safety
