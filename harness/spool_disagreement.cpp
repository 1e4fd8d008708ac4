#include "harness/spool_disagreement.hpp"

#include <cmath>
#include <string_view>

#include "hal/can_protocol.hpp"

namespace exc::sim {

double spool_resolution(double spool_noise) {
  const hal::MessageSpec* m = hal::find_message(hal::can_id::sens_machine);
  double quantum = 0;
  for (std::size_t i = 0; m != nullptr && i < m->data_signal_count(); ++i)
    if (std::string_view(m->data_signal(i).name) == "BoomSpool") quantum = m->data_signal(i).factor;
  return 3 * spool_noise + quantum;
}

bool SpoolDisagreement::disagrees(double spool, double healthy) const {
  const double band = limits_.band + resolution_, excess = limits_.excess + resolution_;
  if (std::abs(healthy) < limits_.neutral_expected) return std::abs(spool) > band;
  const double along = healthy >= 0 ? spool : -spool;  // the spool's travel the healthy one's way
  return along - std::abs(healthy) > excess || -along > band;
}

void SpoolDisagreement::record(double t, const Vec4& spool, const Vec4& healthy) {
  if (onset_ >= 0) return;
  for (int f = 0; f < 4; ++f) {
    if (!disagrees(spool[f], healthy[f])) continue;
    onset_ = t;
    function_ = f;
    return;
  }
}

}  // namespace exc::sim
