#pragma once
// Work cycles: a task that repeats. Cycle k+1 starts with a return move from where cycle k ended to
// the cycle's first point; the whole sequence is one C2 spline through the cycles' knots (shifted in
// time), so position, velocity and acceleration are continuous everywhere, including the joins.
// The truck-loading cycle (the job of an automated 20 t machine): the dig pass, then lift and swing
// to the dump angle, open the bucket over the truck, swing back to where the next pass starts.
// Start-up code: allocates, throws SettingsError through the checks of dig_path.hpp.
#include <string>
#include <vector>

#include "control/task/dig_path.hpp"

namespace exc::control {

// The truck-loading cycle's dump: the tip pose over the truck with the bucket curled (pitch) and
// opened (open_pitch), at the dump swing angle.
struct DumpPose {
  double swing = 1.5707963267948966;  // rad
  TipPose curled;                     // x, z, pitch when it arrives
  double open_pitch = 1.0;            // rad, the bucket opened to dump
};

struct TruckCycleTimes {
  double to_dump = 6;  // s: from the end of the dig pass to the dump pose (lift and swing)
  double dump = 2;     // s: opening the bucket
  double back = 6;     // s: swinging back to the start of the next pass
};

struct CycleKnots {
  std::vector<double> times;  // strictly increasing, the first one the cycle's start
  std::vector<Vec4> points;
};

// N copies of one cycle's knots, copy k shifted to start `gap` s after copy k-1's last knot (the
// return move); also returns each cycle's start time.
CycleKnots repeat_cycle(const CycleKnots& cycle, int count, double gap, std::vector<double>& cycle_starts);

// The knots of one truck-loading cycle: the dig pass (IK samples of the tip path at dig_swing), the
// dump pose curled and opened, and the dig pass's first point again when `close` (the last cycle
// swings back too; earlier ones leave that to the next cycle's first knot).
CycleKnots truck_loading_cycle(const Machine& machine, double dig_swing, const std::vector<DigWaypoint>& path,
                               const DumpPose& dump, const TruckCycleTimes& times, const TrajectoryCheckOptions& options,
                               const std::string& file, const std::string& field);

}  // namespace exc::control
