#pragma once
// The spool monitor (docs/safety.md, H1): each main-valve spool's measured position (its LVDT, on
// the bus in SENS_MACHINE) against the position it is expected at, the firmware's own command taken
// through the valve's dynamics (a first-order lag with the machine's valve_time_constant), so a
// healthy spool's lag is no disagreement. As a valve actuator's own monitor does (Danfoss PVE:
// 12 % of the stroke, the opposite way, off neutral with neutral demanded; safety.md), three tests
// per function, each debounced over `debounce` sensor sets in a row:
//   further: the spool further from neutral than expected by more than `excess` of its stroke;
//   against: the spool on the other side of neutral from the expected one by more than `band`;
//   neutral: neutral expected (within `neutral_expected`) and the spool more than `band` off it.
// What it cannot see: a spool stuck at or nearer neutral than it is commanded passes no more flow
// than asked, so it shows only once the command moves past it (toward neutral or the other way);
// the flow plausibility monitor stays as a second, independent channel. Nothing here allocates.
#include <cstdint>

#include "model/types.hpp"

namespace exc::safety {

struct SpoolMonitorSettings {
  bool enabled = true;
  double excess = 0.12;           // of the stroke, further from neutral than expected (PVE: 12 %)
  double band = 0.05;             // of the stroke, off neutral the wrong way or with neutral expected
  double neutral_expected = 0.01; // of the stroke: an expected spool this near neutral is "neutral"
  int debounce = 20;              // sensor sets in a row (20 ms: a spool's lag is 30 ms)
};
// The settings blob's field list (app/settings_blob.hpp): a field added above is added here too.
template <typename Visitor>
void visit_fields(Visitor& v, SpoolMonitorSettings& s) {
  v("enabled", s.enabled);
  v("excess", s.excess);
  v("band", s.band);
  v("neutral_expected", s.neutral_expected);
  v("debounce", s.debounce);
}

enum class SpoolTest : std::uint8_t { none, further, against, neutral };
const char* to_string(SpoolTest test);

class SpoolMonitor {
 public:
  SpoolMonitor() = default;
  // valve_time_constant: the nominal machine's spool lag (s); period: the cycle (s).
  SpoolMonitor(const SpoolMonitorSettings& settings, double valve_time_constant, double period);

  // Every cycle, once the cycle's command is made: the spool targets the firmware sent (-1..1;
  // centred valves: zeros). The expectation for the next sensor set follows them through the lag.
  void command(const Vec4& target);
  // A sensor set of this cycle: the measured spools against the expected ones (active: the valve
  // interface, commanding, the set complete and measured; an inactive set leaves the runs as they
  // are). Returns the first function whose test
  // has failed `debounce` sets in a row, or -1.
  int check(bool active, const Vec4& measured);
  // The tests' runs start again (a restart of the law; the expectation has followed the centred
  // valves of the safe state meanwhile).
  void reset();

  const Vec4& expected() const { return expected_; }
  const SpoolMonitorSettings& settings() const { return s_; }
  SpoolTest failed_test() const { return failed_test_; }
  int failed_function() const { return failed_function_; }
  double worst_ratio() const { return worst_ratio_; }  // largest test value over its limit seen (no fault: < 1)

 private:
  SpoolMonitorSettings s_;
  double gain_ = 1;  // the lag's gain per cycle
  Vec4 expected_ = Vec4::Zero(), target_ = Vec4::Zero();
  int run_[4] = {0, 0, 0, 0};
  SpoolTest failed_test_ = SpoolTest::none;
  int failed_function_ = -1;
  double worst_ratio_ = 0;
};

}  // namespace exc::safety
