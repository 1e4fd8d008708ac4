#pragma once
// A run's errors per phase, |q_a - q_d| against the pose the firmware asks for (rad swing, m
// cylinders): tracking (the path running, its stop along the path included), settle (each hold's
// start, the path's last error dying out: until every function has stayed inside half the holding
// tolerance for kHoldSettleDwell s, at most kHoldSettleLimit s), hold (the firmware holding a pose
// from then on: after the task, after a stop, at start-up) and stop (the safe state after a fault:
// the centred valves' creep from the pose last asked for). The one phase split of every run's
// summary: excavator-sim's (the plant's truth, harness/lockstep_run) and excavator-firmware's (its
// sensed positions, app/firmware_runner). Host-side, after each cycle, never in the control step;
// allocation-free.
#include <array>
#include <cstdint>
#include <string>

#include "model/types.hpp"
#include "safety/state_machine.hpp"

namespace exc::app {

struct PhaseErrors {
  std::uint64_t samples = 0;
  double seconds = 0;                   // s spent in the phase
  double rms_error[4] = {0, 0, 0, 0};
  double max_error[4] = {0, 0, 0, 0};
  double worst_time[4] = {-1, -1, -1, -1};  // s of the run (the positions' time) at each joint's max, its first if
                                            // several are equal (-1: no sample)
  // Per joint: how often the error rose past the holding tolerance (an excursion: a hunt's
  // overshoot or a correction that came too late).
  std::uint64_t excursions[4] = {0, 0, 0, 0};
};

// The holding tolerance the run's verdict holds every hold to (docs/control.md, "Holding still"):
// |q_a - q_d| of each cylinder within 2.5 mm, the swing within 2.5 mrad, once the hold has settled
// (every function inside half of it for kHoldSettleDwell: a hold that merely entered the tolerance
// on its way in, or a swing ringing through it on its soft oil column, is still settling).
inline constexpr double kHoldingTolerance[4] = {2.5e-3, 2.5e-3, 2.5e-3, 2.5e-3};
// s from the start of a hold to the start of its judgement at the latest: the hold's pose is the
// path's last point, and the error the path ended with (up to 14 mm under PID on the clay slope)
// is corrected first; a hold still outside the tolerance this long after it began is judged anyway.
inline constexpr double kHoldSettleLimit = 10.0;
// s every function must stay inside half the tolerance for the hold to count as settled: longer than
// half the swing's 0.4 Hz ringing period, so a ring through zero is not taken for a settled hold.
inline constexpr double kHoldSettleDwell = 1.5;

// One phase's errors accumulated cycle by cycle: RMS, max and its time, excursions.
class PhaseAccumulator {
 public:
  void add(double t, double dt, const Vec4& q, const Vec4& q_desired);
  // The phase left: an excursion that continues into the next visit is a new one.
  void leave() { over_ = {}; }
  PhaseErrors result() const;

 private:
  PhaseErrors errors_;
  std::array<double, 4> sum_sq_{};
  std::array<bool, 4> over_{};
};

class RunPhases {
 public:
  // After each cycle: its time (s), the period (s), the firmware's mode, whether it tracked, the
  // positions judged (the plant's truth or the sensed ones) and the pose asked for.
  void add(double t, double dt, safety::Mode mode, bool tracking, const Vec4& q, const Vec4& q_desired);
  PhaseErrors tracking() const { return tracking_.result(); }
  PhaseErrors settle() const { return settle_.result(); }
  PhaseErrors hold() const { return hold_.result(); }
  PhaseErrors stop() const { return stop_.result(); }

 private:
  PhaseAccumulator tracking_, settle_, hold_, stop_;
  double hold_start_ = -1;    // s the current hold began (-1: not holding)
  bool settling_ = false;     // the current hold has not settled yet
  double inside_since_ = -1;  // s since every function has been inside half the tolerance (-1: not now)
  bool commanded_ = false;    // the firmware held or tracked a pose (the stop phase counts from then on)
};

// The hold's verdict: "" when every function stayed within the holding tolerance once settled, else
// the function furthest past its tolerance (in multiples of it): by how much, when, how many
// excursions, and how many other functions left theirs.
std::string hold_failure(const PhaseErrors& hold);

}  // namespace exc::app
