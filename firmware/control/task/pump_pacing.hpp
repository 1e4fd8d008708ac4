#pragma once
// The path's clock paced to the pumps (controller.pump_pacing, valve interface): a path that asks the
// pumps for more oil than they give is slowed so that its own flow stays within a share of theirs,
// as the machine's flow sharing slows every function at once, instead of falling behind until the
// tracking limit stops it (docs/control.md, "Pump pacing").
//
// The path's own flow at rate 1, per pump g: Q_g(tau) = sum over its functions j of A_j |y'_j(tau)|,
// A_j the side the path fills (bore extending, annulus retracting; the swing motor's displacement),
// y' the path's velocity in path time. The target rate is r* = min(1, share Q_pump,g / Q_g) over
// the pumps. The rate follows r* through a first-order lag of time constant T (so the desired
// acceleration never steps), and the path time integrates it:
//     r' = (r* - r) / T,   tau <- tau + r dt,   qd_d = y' r,   qdd_d = y'' r^2 + y' r'.
// The lag lets the demand run over r* by about T dQ/dt while it rises; the share leaves the rest of
// the pumps' flow to the feedback. What a paced path costs in time is estimated at load
// (paced_duration: the same clock without the lag) and added to the run. Allocation-free per cycle.
#include "control/task/trajectory.hpp"
#include "model/hydraulic_geometry.hpp"
#include "model/machine.hpp"
#include "model/types.hpp"

namespace exc::control {

class PumpPacing {
 public:
  static constexpr double kTimeConstant = 0.05;  // s: T, short against the path's changes of flow

  PumpPacing() = default;
  PumpPacing(const Machine& nominal, double share, double period);

  // The rate at which the path's velocity (in path time) keeps its flow within the share.
  double target_rate(const Vec4& path_velocity) const;

  // Tracking starts at path time tau, at full rate.
  void start(double tau) {
    tau_ = tau;
    rate_ = 1;
    rate_dot_ = 0;
  }
  // This cycle: the rate's derivative from the path's velocity at tau(); rate() and rate_dot() are
  // then this cycle's. advance() moves tau and the rate on to the next cycle.
  void update(const Vec4& path_velocity) { rate_dot_ = (target_rate(path_velocity) - rate_) / kTimeConstant; }
  void advance() {
    tau_ += rate_ * period_;
    rate_ += rate_dot_ * period_;
  }
  double tau() const { return tau_; }
  double rate() const { return rate_; }
  double rate_dot() const { return rate_dot_; }

 private:
  Vec4 area_a_ = Vec4::Zero(), area_b_ = Vec4::Zero();
  std::array<int, 4> pump_of_{};
  int pumps_ = 1;
  double capacity_ = 0;  // m^3/s each pump may give the path: share x its flow
  double period_ = 1e-3;
  double tau_ = 0, rate_ = 1, rate_dot_ = 0;
};

// The path's duration when paced (the clock above without its lag, stepped at `period`): at least
// the path's own. Runs once at load.
double paced_duration(const PumpPacing& pacing, const JointTrajectory& trajectory, double period);

}  // namespace exc::control
