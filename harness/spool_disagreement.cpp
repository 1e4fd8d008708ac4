#include "harness/spool_disagreement.hpp"

#include <cmath>

namespace exc::sim {

bool SpoolDisagreement::disagrees(double spool, double healthy) const {
  if (std::abs(healthy) < limits_.neutral_expected) return std::abs(spool) > limits_.band;
  const double along = healthy >= 0 ? spool : -spool;  // the spool's travel the healthy one's way
  return along - std::abs(healthy) > limits_.excess || -along > limits_.band;
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
