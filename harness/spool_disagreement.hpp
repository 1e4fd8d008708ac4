#pragma once
// The onset of a stuck spool's disagreement, judged on the plant's truth (the stop requirement's R1,
// docs/safety.md: a stuck or runaway spool found within 100 ms of it). A spool stuck where the command
// holds it disagrees with nothing; it disagrees from the first cycle the spool as it is lies past what
// the spool monitor promises to see, against the spool a healthy valve would have there
// (Plant::healthy_spool): further from neutral by more than `excess` of the stroke, on the other side
// of neutral by more than `band`, or off neutral by more than `band` where the healthy spool is within
// `neutral_expected` of it. Each limit is taken past the spool's measurement by its resolution (three
// of the LVDT's standard deviations and the bus's quantum): a spool stuck within the sensor's noise
// of a limit disagrees by nothing the measurement can tell, and none can be asked to find it. A spool
// stuck nearer neutral than commanded gives no more flow than asked and never disagrees by this
// measure (the monitor's stated blind side).
#include "model/types.hpp"
#include "safety/spool_monitor.hpp"

namespace exc::sim {

// The measured spool's resolution, a fraction of the stroke: 3 x the LVDT's noise (sensors.spool_noise)
// plus the quantum the bus carries it in (SENS_MACHINE's spool signals, hal/can_protocol.cpp).
double spool_resolution(double spool_noise);

class SpoolDisagreement {
 public:
  SpoolDisagreement(const safety::SpoolMonitorSettings& limits, double resolution)
      : limits_(limits), resolution_(resolution) {}
  // Every cycle: t (s) the plant's time of `spool` (as it is) and `healthy` (as a healthy valve's).
  // Only the first onset is kept.
  void record(double t, const Vec4& spool, const Vec4& healthy);
  // Whether `spool` disagrees with `healthy` by the limits above.
  bool disagrees(double spool, double healthy) const;
  double onset() const { return onset_; }     // s, -1: none yet
  int function() const { return function_; }  // the function that disagreed first, -1: none

 private:
  safety::SpoolMonitorSettings limits_;
  double resolution_;
  double onset_ = -1;
  int function_ = -1;
};

}  // namespace exc::sim
