#include "app/run_phases.hpp"

#include <cmath>
#include <cstdio>

namespace exc::app {

void PhaseAccumulator::add(double t, double dt, const Vec4& q, const Vec4& q_desired) {
  ++errors_.samples;
  errors_.seconds += dt;
  for (int j = 0; j < 4; ++j) {
    const double e = std::abs(q[j] - q_desired[j]);
    sum_sq_[j] += e * e;
    // The first sample sets the time too: a joint whose error stays 0 (a swing the task never moves)
    // still has a moment its worst is at, so the report's worst window has one to centre on.
    if (e > errors_.max_error[j] || errors_.worst_time[j] < 0) {
      errors_.max_error[j] = e;
      errors_.worst_time[j] = t;
    }
    const bool over = e > kHoldingTolerance[j];
    if (over && !over_[j]) ++errors_.excursions[j];
    over_[j] = over;
  }
}

PhaseErrors PhaseAccumulator::result() const {
  PhaseErrors r = errors_;
  for (int j = 0; j < 4; ++j) r.rms_error[j] = r.samples ? std::sqrt(sum_sq_[j] / static_cast<double>(r.samples)) : 0;
  return r;
}

void RunPhases::add(double t, double dt, safety::Mode mode, bool tracking, const Vec4& q, const Vec4& q_desired) {
  if (mode == safety::Mode::hold) {
    if (hold_start_ < 0) {
      hold_start_ = t;
      inside_since_ = -1;
      settling_ = true;
    }
    if (settling_) {
      bool inside = true;
      for (int j = 0; j < 4; ++j) inside = inside && std::abs(q[j] - q_desired[j]) <= 0.5 * kHoldingTolerance[j];
      if (!inside) inside_since_ = -1;
      else if (inside_since_ < 0) inside_since_ = t;
      settling_ = !(inside && t - inside_since_ >= kHoldSettleDwell) && t - hold_start_ < kHoldSettleLimit;
    }
    (settling_ ? settle_ : hold_).add(t, dt, q, q_desired);
    commanded_ = true;
  } else {
    hold_start_ = -1;
    settle_.leave();
    hold_.leave();
  }
  // The safe state: the centred valves' creep from the pose last asked for (none before any).
  if (mode == safety::Mode::safe_stop && commanded_) stop_.add(t, dt, q, q_desired);
  else stop_.leave();
  if (tracking) {
    commanded_ = true;
    tracking_.add(t, dt, q, q_desired);
  } else {
    tracking_.leave();
  }
}

std::string hold_failure(const PhaseErrors& hold) {
  // The function furthest past its tolerance (in multiples of it), and how many others left theirs.
  int worst = -1, past = 0;
  for (int j = 0; j < 4; ++j) {
    if (!(hold.max_error[j] > kHoldingTolerance[j])) continue;
    ++past;
    if (worst < 0 || hold.max_error[j] / kHoldingTolerance[j] > hold.max_error[worst] / kHoldingTolerance[worst]) worst = j;
  }
  if (worst < 0) return "";
  const int j = worst;
  const int others = past - 1;
  char others_text[64] = "";
  if (others > 0)
    std::snprintf(others_text, sizeof others_text, ", and %d other function%s left %s own", others, others == 1 ? "" : "s",
                  others == 1 ? "its" : "their");
  char text[280];
  std::snprintf(text, sizeof text,
                "the %s left its held pose by %.2f %s at %.2f s (holding tolerance %.2f %s once settled; %llu excursion(s))%s",
                kActiveNames[j], hold.max_error[j] * 1e3, j == 0 ? "mrad" : "mm", hold.worst_time[j],
                kHoldingTolerance[j] * 1e3, j == 0 ? "mrad" : "mm", static_cast<unsigned long long>(hold.excursions[j]), others_text);
  return text;
}

}  // namespace exc::app
