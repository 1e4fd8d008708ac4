#include "sim_plant/flow_sharing.hpp"

#include <algorithm>

namespace exc::plant {

double load_sensing_pressure(bool any_open, double highest_load, double tank, double margin, double main_relief) {
  const double load = any_open ? std::max(highest_load, tank) : tank;
  return std::min(load + margin, main_relief);
}

double flow_share_scale(double demand, double pump_flow) {
  return demand > pump_flow ? pump_flow / demand : 1.0;
}

}  // namespace exc::plant
