#include "sim_plant/orifice.hpp"

#include <cmath>

namespace exc::plant {

void orifice_flow(double dp, double laminar_pressure, double& flow, double& dflow_ddp) {
  const double a = std::abs(dp);
  if (a < laminar_pressure) {
    // Linear branch meeting sqrt at dp = laminar_pressure (same value there).
    const double s = 1.0 / std::sqrt(laminar_pressure);
    flow = dp * s;
    dflow_ddp = s;
  } else {
    const double r = std::sqrt(a);
    flow = dp > 0 ? r : -r;
    dflow_ddp = 0.5 / r;
  }
}

}  // namespace exc::plant
