#include "control/task/pump_pacing.hpp"

#include <algorithm>
#include <cmath>

namespace exc::control {

PumpPacing::PumpPacing(const Machine& nominal, double share, double period) : period_(period) {
  const HydraulicGeometry g = hydraulic_geometry(nominal);
  area_a_ = g.area_a;
  area_b_ = g.area_b;
  const HydraulicParameters& h = nominal.hydraulics;
  pumps_ = h.pumps_merged ? 1 : 2;
  for (int j = 0; j < 4; ++j) pump_of_[static_cast<std::size_t>(j)] = h.pumps_merged ? 0 : h.pump_of[static_cast<std::size_t>(j)];
  capacity_ = share * h.pump_flow / pumps_;
}

double PumpPacing::target_rate(const Vec4& path_velocity) const {
  double demand[2] = {0, 0};
  for (int j = 0; j < 4; ++j) {
    const double v = path_velocity[j];
    demand[pump_of_[static_cast<std::size_t>(j)]] += (v >= 0 ? area_a_[j] : area_b_[j]) * std::abs(v);
  }
  double rate = 1;
  for (int g = 0; g < pumps_; ++g)
    if (demand[g] * rate > capacity_) rate = capacity_ / demand[g];
  return rate;
}

double paced_duration(const PumpPacing& pacing, const JointTrajectory& trajectory, double period) {
  double tau = trajectory.start_time(), elapsed = 0;
  Vec4 y, yd, ydd;
  while (tau < trajectory.end_time()) {
    trajectory.evaluate(tau, y, yd, ydd);
    tau += pacing.target_rate(yd) * period;
    elapsed += period;
  }
  return elapsed;
}

}  // namespace exc::control
