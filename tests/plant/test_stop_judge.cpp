// The stop judge's ring envelope (harness/stop_judge.hpp, docs/safety.md "The stop requirement"), on
// records made here from a ring's closed form: v(t) = A exp(-t / tau) sin(2 pi f t), position its
// integral. The plant's dry friction holds a slow function at exactly zero velocity for a cycle or more
// at its turning points (sim_plant/coulomb_friction.hpp sticks exactly), so the ring's reversals pass
// through zero instead of changing sign between two samples; a re-excited function (a draining bucket
// reaching its end stop shakes the arm) rings afresh after it has been at rest.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "harness/stop_judge.hpp"
#include "model/machine_reader.hpp"

using namespace exc;

namespace {

constexpr double kCycle = 1e-3;  // s, the plant's period
constexpr int kRingFunction = 2;  // the arm

// One decaying ring on the arm, starting at `start` (s): amplitude (m/s), envelope time constant (s;
// infinite: a ring that does not decay), frequency (Hz).
struct Ring {
  double start, amplitude, tau, frequency;
};

// The arm's velocity at t: the rings' sum; with `stick`, exactly 0 within `stick` s of each zero
// crossing of the latest ring begun (dry friction holding the arm at a turning point).
double arm_velocity(const std::vector<Ring>& rings, double t, double stick) {
  double v = 0;
  const Ring* latest = nullptr;
  for (const Ring& r : rings) {
    if (t < r.start) continue;
    const double u = t - r.start;
    v += r.amplitude * std::exp(-u / r.tau) * std::sin(2 * M_PI * r.frequency * u);
    latest = &r;
  }
  if (latest != nullptr && stick > 0) {
    const double u = t - latest->start, half = 0.5 / latest->frequency;
    if (u > stick && std::abs(u - std::round(u / half) * half) <= stick) return 0.0;
  }
  return v;
}

sim::StopJudgement judge_rings(const std::vector<Ring>& rings, double stick, double length = 8.0) {
  const Machine machine = reference_machine();
  sim::StopJudge judge(machine, 0.0, kCycle, length + 1);
  Vec4 q(0.0, 2.46, 2.32, 2.14), qd = Vec4::Zero();
  for (int k = 0; k * kCycle <= length; ++k) {
    const double t = k * kCycle;
    qd[kRingFunction] = arm_velocity(rings, t, stick);
    judge.record(t, q, qd, false);
    q[kRingFunction] += qd[kRingFunction] * kCycle;
  }
  // Detected at the start, the valves centred in the same cycle (a controlled stop: no brake asked).
  return judge.judge(0.0, -1.0, kCycle, kCycle, false);
}

}  // namespace

TEST_CASE("plant/stop judge: a ring whose velocity rests at exactly zero for cycles at its turning points (dry friction holding it) is judged on its envelope like the same ring crossing zero, and one that does not decay misses R3") {
  const double tau = 0.8;  // s
  const std::vector<Ring> decaying = {{0.0, 0.030, tau, 2.5}};
  const sim::StopJudgement crossing = judge_rings(decaying, 0.0);
  INFO("crossing zero: tau " << crossing.ring_tau[kRingFunction] << " s");
  CHECK(crossing.ring_tau[kRingFunction] == doctest::Approx(tau).epsilon(0.15));
  CHECK(crossing.meets_r3);
  for (const double stick : {0.0015, 0.004, 0.02}) {
    const sim::StopJudgement held = judge_rings(decaying, stick);
    INFO("held " << stick * 1e3 << " ms at each turning point: tau " << held.ring_tau[kRingFunction] << " s (" << held.why << ")");
    CHECK(held.ring_tau[kRingFunction] == doctest::Approx(crossing.ring_tau[kRingFunction]).epsilon(0.05));
    CHECK(held.meets_r3);
  }
  // The same ring at a constant 5 mm/s: not decaying whether or not friction holds its turning points.
  const std::vector<Ring> sustained = {{0.0, 0.005, 1e12, 2.5}};
  for (const double stick : {0.0, 0.004}) {
    const sim::StopJudgement held = judge_rings(sustained, stick);
    INFO("a sustained ring held " << stick * 1e3 << " ms at each turning point: tau " << held.ring_tau[kRingFunction] << " s");
    CHECK(held.ring_tau[kRingFunction] > sim::kRingTauLimit);
    CHECK_FALSE(held.meets_r3);
  }
  // A slow ring (tau 6 s, beyond the 3.5 s limit) held at its turning points misses R3 on its envelope.
  const sim::StopJudgement slow = judge_rings({{0.0, 0.030, 6.0, 2.5}}, 0.004);
  INFO("a slow ring: tau " << slow.ring_tau[kRingFunction] << " s (" << slow.why << ")");
  CHECK(slow.ring_tau[kRingFunction] == doctest::Approx(6.0).epsilon(0.1));
  CHECK_FALSE(slow.meets_r3);
}

TEST_CASE("plant/stop judge: a function that rang down, rested and was shaken into a new ring has each ring judged apart, not one envelope across the rest") {
  // The first ring from 70 mm/s dies within 2 s; at 5 s (after 3 s at rest) a new one from 40 mm/s.
  const std::vector<Ring> rings = {{0.0, 0.070, 0.3, 3.0}, {5.0, 0.040, 0.2, 3.0}};
  for (const double stick : {0.0, 0.002}) {
    const sim::StopJudgement j = judge_rings(rings, stick);
    INFO("held " << stick * 1e3 << " ms at each turning point: tau " << j.ring_tau[kRingFunction] << " s (" << j.why << ")");
    CHECK(j.ring_tau[kRingFunction] == doctest::Approx(0.3).epsilon(0.15));  // the slower of the two rings
    CHECK(j.meets_r3);
  }
  // A second ring that does not decay is not hidden by the first one's decay.
  const sim::StopJudgement j = judge_rings({{0.0, 0.070, 0.3, 3.0}, {5.0, 0.005, 1e12, 3.0}}, 0.002);
  INFO("a sustained second ring: tau " << j.ring_tau[kRingFunction] << " s");
  CHECK_FALSE(j.meets_r3);
}

TEST_CASE("plant/stop judge: a ring shaken up again before it came to rest (a drained bucket reaching its end stop) is judged from its crest to its rest, not by one exponential fitted across both") {
  // 100 mm/s at 3 Hz, tau 0.3 s: below 1 mm/s by 0.3 ln 100 = 1.4 s; at 1.7 s shaken to 36 mm/s,
  // tau 0.4 s: below the floor by 1.7 + 0.4 ln 36 = 3.1 s. From the crest (near 0.08 s) to rest at
  // 3.1 s: the exponential from 100 mm/s to 1 mm/s that takes as long has tau near 3.0 / ln 100 = 0.66 s.
  const std::vector<Ring> rings = {{0.0, 0.100, 0.3, 3.0}, {1.7, 0.036, 0.4, 3.0}};
  for (const double stick : {0.0, 0.002}) {
    const sim::StopJudgement j = judge_rings(rings, stick);
    INFO("held " << stick * 1e3 << " ms at each turning point: tau " << j.ring_tau[kRingFunction] << " s (" << j.why << ")");
    CHECK(j.ring_tau[kRingFunction] == doctest::Approx((1.7 + 0.4 * std::log(36.0) - 0.08) / std::log(100.0)).epsilon(0.15));
    CHECK(j.meets_r3);
  }
}

TEST_CASE("plant/stop judge: R1 counts from a stuck spool's onset of disagreement, and the drift of a stop found late is fitted after its detection, not over the motion before it") {
  // The arm moves at 10 mm/s under control from the fault's start until detection at 3 s, then stands.
  const Machine machine = reference_machine();
  const auto judge_at = [&](double onset, double detected) {
    sim::StopJudge judge(machine, 0.0, kCycle, detected + 5);
    Vec4 q(0.0, 2.46, 2.32, 2.14), qd = Vec4::Zero();
    for (int k = 0; k * kCycle <= detected + 4; ++k) {
      const double t = k * kCycle;
      qd[kRingFunction] = t < detected ? 0.010 : 0.0;
      judge.record(t, q, qd, false);
      q[kRingFunction] += qd[kRingFunction] * kCycle;
    }
    return judge.judge(detected, onset, detected + kCycle, kCycle, false);
  };
  // Found 60 ms after its onset at 2.94 s: R1 met, counted from the onset.
  const sim::StopJudgement soon = judge_at(2.94, 3.0);
  CHECK(soon.onset_after_s == doctest::Approx(2.94));
  CHECK(soon.detected_after_onset_s == doctest::Approx(0.06));
  CHECK(soon.meets_r1);
  // Found 3 s after an onset at the fault's start: R1 missed, and the stop's drift is the standing arm's.
  const sim::StopJudgement late = judge_at(0.0, 3.0);
  CHECK(late.detected_after_onset_s == doctest::Approx(3.0));
  CHECK_FALSE(late.meets_r1);
  CHECK(std::abs(late.drift[kRingFunction]) < 1e-9);
  CHECK(late.meets_r3);
  // No onset (a spool that never disagreed by detection, or a fault that sticks none): from the start.
  const sim::StopJudgement none = judge_at(-1.0, 0.05);
  CHECK(none.onset_after_s == -1.0);
  CHECK(none.detected_after_onset_s == doctest::Approx(0.05));
  CHECK(none.meets_r1);
}
