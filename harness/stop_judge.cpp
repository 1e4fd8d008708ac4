#include "harness/stop_judge.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace exc::sim {
namespace {

// m/s, rad/s: a ring's peak below "at rest" is no ring to fit (a function creeping or stick-slipping
// below it is at rest by the safety concept's measure).
constexpr double kRingFloor = kRestCylinderRate;
static_assert(kRestCylinderRate == kRestSwingRate, "one floor for every function's ring");
constexpr int kRingPeaks = 3;            // peaks the envelope's fit needs
constexpr int kMaxPeaks = 512;           // half periods fitted at most (a 2.5 Hz ring over 100 s)
const char* const kFunctions[] = {"swing", "boom", "arm", "bucket"};

std::string format(const char* fmt, double a, double b) {
  char buf[200];
  std::snprintf(buf, sizeof buf, fmt, a, b);
  return buf;
}

// The slowest envelope time constant of the rings in samples [from, end) of function f (0: no ring
// with kRingPeaks peaks above the floor; 1e9: one that does not decay). A half period is the velocity
// on one side of zero, judged by its samples above the floor: a sample at or below it (a function its
// dry friction holds at a turning point, for a cycle or more at nearly every reversal once slow; or a
// creep too slow to count) belongs to neither side and ends no half period. Its peak is the largest
// |velocity| in it. A ring ends once the function has been below the floor for kRestSettle: motion after
// that is a new ring (excited afresh, e.g. by a draining bucket reaching its end stop), judged apart.
// A ring is judged from its crest (its largest peak; the peaks before it are the ring building up).
// One that has ended decayed from its crest A_c at t_c to the floor by its last sample above it, t_e:
// its envelope's time constant is (t_e - t_c) / ln(A_c / floor), the exponential that takes as long
// (a ring shaken up again before it rested, or cut short by an end stop, is not one exponential, and a
// fit of one to its peaks can find no decay in motion that has died out). One still ringing at the
// record's end: A exp(-t / tau) fitted by least squares to its peaks from the crest on.
template <class Samples>
double ring_envelope_tau(const Samples& samples, std::size_t from, int f) {
  double peak_t[kMaxPeaks], peak_a[kMaxPeaks];
  int peaks = 0;
  double worst = 0;
  // The ring of peaks [0, peaks), its last sample above the floor at `last`: its envelope's tau,
  // folded into the worst.
  const auto judge_ring = [&](bool ended, double last) {
    int crest = 0;
    for (int p = 1; p < peaks; ++p)
      if (peak_a[p] > peak_a[crest]) crest = p;
    const int used = peaks - crest;
    if (used >= kRingPeaks && ended) {
      worst = std::max(worst, (last - peak_t[crest]) / std::log(peak_a[crest] / kRingFloor));
    } else if (used >= kRingPeaks) {
      double pt = 0, pl = 0, ptt = 0, ptl = 0;
      for (int p = crest; p < peaks; ++p) {
        const double l = std::log(peak_a[p]);
        pt += peak_t[p];
        pl += l;
        ptt += peak_t[p] * peak_t[p];
        ptl += peak_t[p] * l;
      }
      const double den = used * ptt - pt * pt;
      const double slope = den > 0 ? (used * ptl - pt * pl) / den : 0.0;
      worst = std::max(worst, slope < 0 ? -1.0 / slope : 1e9);
    }
    peaks = 0;
  };
  int side = 0;  // the open half period's sign (0: none open)
  double half_peak = 0, half_time = 0, last_above = -1e300;
  const std::size_t n = samples.size();
  for (std::size_t k = from; k < n; ++k) {
    const double v = samples[k].qd[f];
    const double t = samples[k].t;
    if (std::abs(v) <= kRingFloor) continue;
    const int sign = v > 0 ? 1 : -1;
    const bool new_ring = t - last_above > kRestSettle;
    if (side != 0 && (sign != side || new_ring) && peaks < kMaxPeaks) {
      peak_t[peaks] = half_time;  // the half period closed: the velocity came back through the floor
      peak_a[peaks] = half_peak;
      ++peaks;
    }
    if (new_ring) judge_ring(true, last_above);
    if (sign != side || new_ring) {
      side = sign;
      half_peak = 0;
    }
    if (std::abs(v) > half_peak) {
      half_peak = std::abs(v);
      half_time = t;
    }
    last_above = t;
  }
  // The last half period counts once the velocity has come back to the floor before the record's end
  // (a half period cut by the record's end may not have reached its peak); the last ring has ended
  // when the record ends kRestSettle after its last sample above the floor.
  const bool back = n > 0 && std::abs(samples[n - 1].qd[f]) <= kRingFloor;
  if (side != 0 && back && peaks < kMaxPeaks) {
    peak_t[peaks] = half_time;
    peak_a[peaks] = half_peak;
    ++peaks;
  }
  judge_ring(back && samples[n - 1].t - last_above >= kRestSettle, last_above);
  return worst;
}

}  // namespace

StopJudge::StopJudge(const Machine& machine, double fault_start, double cycle, double span)
    : hp_(machine.hydraulics), start_(fault_start) {
  samples_.reserve(static_cast<std::size_t>(std::ceil(span / cycle)) + 2);
}

void StopJudge::record(double t, const Vec4& q_a, const Vec4& qd_a, bool brake_applied) {
  if (t < start_ || samples_.size() == samples_.capacity()) return;
  samples_.push_back(Sample{t, q_a, qd_a, brake_applied});
}

double StopJudge::fit_onset(double detected, double spool_onset) const {
  // Never earlier than 0.1 s before detection: a spool found late (R1 missed) leaves the machine
  // under control until then, and the drift judges the stop, not the motion before it.
  const double earliest = std::max(start_, detected - 0.1);
  return spool_onset >= 0 && spool_onset <= detected ? std::max(spool_onset, earliest) : earliest;
}

StopJudgement StopJudge::judge(double detected, double spool_onset, double safe_state, double period, bool emergency) const {
  StopJudgement j;
  if (detected < 0 || safe_state < 0 || samples_.empty() || detected > samples_.back().t) return j;
  j.judged = true;
  j.detected_after_s = detected - start_;
  j.outputs_after_s = safe_state - detected;
  const bool onset_known = spool_onset >= 0 && spool_onset <= detected;
  j.onset_after_s = onset_known ? spool_onset - start_ : -1.0;
  j.detected_after_onset_s = onset_known ? detected - spool_onset : j.detected_after_s;
  j.meets_r1 = j.detected_after_onset_s <= 0.1 + 1e-9;
  j.meets_r2 = j.outputs_after_s <= period + 1e-9;
  std::size_t d = 0;
  while (d + 1 < samples_.size() && samples_[d].t < detected - 1e-9) ++d;
  const std::size_t n = samples_.size();
  // The valve that ends a function's motion: on the emergency stop the pump-line shut-off and the
  // holding valves; on a controlled stop the main spools centring (95 % of their lag).
  const double closing = emergency ? std::max(hp_.pump_shutoff_time, hp_.holding_valve_close_time) : 3 * hp_.valve_time_constant;
  // The drift's fit: from 1.5 s after the onset of disagreement to the record's end.
  const double fit_from = fit_onset(detected, spool_onset) + kDriftFrom;
  j.drift_span = samples_.back().t - fit_from;
  for (int f = 0; f < 4; ++f) {
    // The first stop after detection: the velocity reverses or falls to "at rest".
    const double v0 = samples_[d].qd[f];
    double peak = std::abs(v0);
    std::size_t s = d;
    while (s + 1 < n && std::abs(samples_[s].qd[f]) >= (f == 0 ? kRestSwingRate : kRestCylinderRate) && samples_[s].qd[f] * v0 > 0) {
      ++s;
      peak = std::max(peak, std::abs(samples_[s].qd[f]));
    }
    j.peak_speed[f] = peak;
    j.travel[f] = std::abs(samples_[s].q[f] - samples_[d].q[f]);
    // The first overshoot: how far the function ran on after the closing valve had closed (the
    // stop frame reaches the machine a cycle after detection), the oil column's compression.
    const double closed = detected + period + closing;
    std::size_t c = d;
    while (c < s && samples_[c].t < closed - 1e-9) ++c;
    j.first_overshoot[f] = std::abs(samples_[s].q[f] - samples_[c].q[f]);
    // Speed x (closing + 0.1 s), plus that overshoot; the swing's stop is its brake's (stated).
    j.travel_allowed[f] = f == 0 ? -1.0 : peak * (closing + kTravelMargin) + j.first_overshoot[f];
    // Net drift: least-squares slope of position against time.
    double st = 0, sq = 0, stt = 0, stq = 0;
    int m = 0;
    for (const Sample& x : samples_) {
      if (x.t < fit_from) continue;
      const double t = x.t - fit_from;
      st += t;
      sq += x.q[f];
      stt += t * t;
      stq += t * x.q[f];
      ++m;
    }
    const double den = m * stt - st * st;
    j.drift[f] = m > 1 && den > 0 ? (m * stq - st * sq) / den : 0.0;
    j.ring_tau[f] = ring_envelope_tau(samples_, s + 1, f);
  }
  for (std::size_t k = d; k < n; ++k)
    if (samples_[k].brake) {
      j.brake_after_s = samples_[k].t - detected;
      break;
    }
  // Exempt: a cylinder still drifting whose outflow side has no holding valve (gravity drives it
  // there whatever the pumps do): declared with its travel, not judged.
  bool exempt[4] = {false, false, false, false};
  for (int f = 1; f < 4; ++f) {
    if (std::abs(j.drift[f]) <= kDriftLimit) continue;
    const bool cap_out = j.drift[f] < 0;  // retracting: the cap side drains
    const bool held = (f == 1 && cap_out && hp_.load_holding_valves) || (f == 2 && !cap_out && hp_.load_holding_valves) ||
                      (f == 3 && hp_.bucket_holding_valve);
    if (held) continue;
    exempt[f] = true;
    j.exempt.push_back(StopExemption{f, std::string(kFunctions[f]) + ": gravity drives it out through its " +
                                            (cap_out ? "cap" : "rod") + " side, which has no holding valve",
                                     std::abs(samples_.back().q[f] - samples_[d].q[f])});
  }
  std::string why;
  if (j.drift_span < kDriftSpan - 2 * period)
    why = format("the record ends %.2f s after 1.5 s from the onset, short of the drift fit's %.1f s", j.drift_span, kDriftSpan);
  for (int f = 0; f < 4 && why.empty(); ++f) {
    if (exempt[f]) continue;
    const std::string name = kFunctions[f];
    if (std::abs(j.drift[f]) > kDriftLimit)
      why = name + format(f == 0 ? " drifts at %.2f mrad/s (limit %.1f)" : " drifts at %.2f mm/s (limit %.1f)", std::abs(j.drift[f]) * 1e3,
                          kDriftLimit * 1e3);
    else if (j.ring_tau[f] > kRingTauLimit)
      why = name + format(" rings with an envelope time constant of %.2f s (limit %.1f)", j.ring_tau[f], kRingTauLimit);
    else if (f > 0 && j.travel[f] > j.travel_allowed[f] + 1e-6)
      why = name + format(" travelled %.1f mm after detection before its first stop, allowed %.1f", j.travel[f] * 1e3,
                          j.travel_allowed[f] * 1e3);
  }
  if (why.empty() && emergency && hp_.swing_brake_torque > 0 && (j.brake_after_s < 0 || j.brake_after_s > kBrakeLimit))
    why = format("the swing brake engaged %.3f s after detection (limit %.1f)", j.brake_after_s, kBrakeLimit);
  j.meets_r3 = why.empty();
  j.why = why;
  return j;
}

}  // namespace exc::sim
