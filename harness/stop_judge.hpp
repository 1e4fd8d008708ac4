#pragma once
// A faulted run's stop judged on the machine's truth against the stop requirement (docs/safety.md,
// "The stop requirement"): R1 detection after the fault's start, R2 the safe state's outputs after
// detection, R3 per function the travel from detection to its first stop against its speed times the
// closing valve's time plus 0.1 s plus the first overshoot, the net drift (the slope of a straight line fitted to its
// position from 1.5 s after the onset over at least 2 s, so a ring's periods average out),
// the envelope time constant of each remaining ring (half periods told by the velocity's side of
// zero above the rest floor, so a function its friction holds for a cycle at a turning point still
// reverses; a ring ends after 1 s at rest; one that has ended is judged from its crest to its rest, one
// still ringing by a fit to its peaks), and the swing brake's engagement. Motion a port
// without a holding valve lets gravity drive is exempt, declared with its travel. The plant's truth
// is recorded into a ring sized before the loop, so the lockstep loop allocates nothing.
#include <array>
#include <string>
#include <vector>

#include "model/machine.hpp"
#include "model/types.hpp"

namespace exc::sim {

// R3's figures (docs/safety.md): drift below 1 mm/s (1 mrad/s swing) from 1.5 s after the onset over
// at least 2 s, a ring's envelope time constant at most 3.5 s, the swing's brake within 0.3 s.
// "At rest" (docs/safety.md): every cylinder under 1 mm/s, the swing under 1 mrad/s; a run past its
// scene ends, and a ring is over, once the machine has been at rest for kRestSettle.
inline constexpr double kRestCylinderRate = 1e-3;  // m/s
inline constexpr double kRestSwingRate = 1e-3;     // rad/s
inline constexpr double kRestSettle = 1.0;         // s
inline constexpr double kDriftFrom = 1.5;          // s after the onset (StopJudge::fit_onset)
inline constexpr double kDriftSpan = 2.0;          // s, the fit's least span
inline constexpr double kDriftLimit = 1e-3;        // m/s, rad/s
inline constexpr double kRingTauLimit = 3.5;       // s
inline constexpr double kBrakeLimit = 0.3;         // s after detection
inline constexpr double kTravelMargin = 0.1;       // s beyond the closing valve's time
inline constexpr double kStopJudgeSpan = kDriftFrom + kDriftSpan;  // s after the fault a judged run lasts at least

struct StopExemption {
  int function = 0;
  std::string reason;
  double travel = 0;  // m (rad) from detection to the record's end
};

struct StopJudgement {
  bool judged = false;              // a stop was taken after a fault's start and recorded
  double detected_after_s = -1;     // from the fault's start
  // R1: from the onset of a stuck spool's disagreement (harness/spool_disagreement.hpp); for a run
  // whose spool disagreed only after detection, or a fault that sticks no spool, from the fault's start
  // as above. onset_after_s: the onset from the fault's start (-1: none before detection).
  double onset_after_s = -1;
  double detected_after_onset_s = -1;
  double outputs_after_s = -1;      // R2: the safe state's outputs after detection
  std::array<double, 4> peak_speed{};  // m/s (rad/s), from detection to the first stop
  std::array<double, 4> travel{};              // to the function's first stop after detection
  std::array<double, 4> first_overshoot{};     // run on after the closing valve closed, to that stop
  // peak speed x (closing time + 0.1 s) + first overshoot; swing (-1): stated, not bounded
  std::array<double, 4> travel_allowed{};
  std::array<double, 4> drift{};               // R3: m/s (rad/s), the fit's slope
  double drift_span = 0;                       // s the fit covered
  std::array<double, 4> ring_tau{};            // s, the slowest ring's (0: no ring to fit; 1e9: not decaying)
  double brake_after_s = -1;                   // swing brake engaged after detection (-1: never)
  std::vector<StopExemption> exempt;
  bool meets_r1 = false, meets_r2 = false, meets_r3 = false;
  std::string why;  // the first of R3's figures missed ("" when R3 is met)
};

class StopJudge {
 public:
  // fault_start: s; cycle: the plant's period; machine: the plant's (its holding valves and closing times).
  StopJudge(const Machine& machine, double fault_start, double cycle, double span = 12.0);
  // Every cycle from the fault's start: the plant's truth (no allocation).
  void record(double t, const Vec4& q_a, const Vec4& qd_a, bool brake_applied);
  // After the run: detected and safe_state are the firmware's times (s; -1: no stop); spool_onset the
  // onset of a stuck spool's disagreement (s, -1: none); emergency: the stop was the emergency stop
  // (the safety solenoids dropped, the swing brake dumped).
  StopJudgement judge(double detected, double spool_onset, double safe_state, double period, bool emergency) const;
  // The onset the drift fit counts from: a stuck spool's onset of disagreement when it came no later
  // than detection, otherwise as early as R1 lets it lie; never before the fault's start or earlier
  // than 0.1 s before detection.
  double fit_onset(double detected, double spool_onset) const;

 private:
  struct Sample {
    double t;
    Vec4 q, qd;
    bool brake;
  };
  HydraulicParameters hp_;
  double start_;
  std::vector<Sample> samples_;  // reserved for the span: never grows in the loop
};

}  // namespace exc::sim
