#include "harness/run_recorder.hpp"

#include <algorithm>
#include <cmath>

#include "safety/firmware_faults.hpp"

namespace exc::sim {

RunRecorder::RunRecorder(const plant::Scene& scene, const std::vector<double>& cycle_starts, const FaultSchedule& fault,
                         const plant::Plant& plant, const safety::SpoolMonitorSettings& spool_limits)
    : scene_(scene),
      starts_(cycle_starts),
      fault_(fault),
      hydraulic_(plant.fidelity().has(plant::kHydraulicCircuit)),
      cycles_(std::max<std::size_t>(1, cycle_starts.size())),
      cycle_sum_sq_(cycles_.size(), std::array<double, 4>{}),
      disagreement_(spool_limits, spool_resolution(scene.sensors.spool_noise)) {
  if (hydraulic_) min_pressure_ = peak_pressure_ = plant.state().hydraulics.min_pressure;
  if (fault.kind != plant::FaultKind::none) judge_.emplace(scene.machine, fault.start, scene.cycle);
}

void RunRecorder::record(const plant::Plant& plant, const app::CycleStatus& st) {
  const plant::PlantState& s = plant.state();
  // The plant's time of the spools the firmware reads next cycle; only an onset before the first
  // detection counts (the safe state's centred command disagrees with a stuck spool afterwards).
  if (hydraulic_ && first_fault_detected_time_ < 0) disagreement_.record(s.time, s.spool, plant.healthy_spool());
  const Vec4 q_desired(st.q_desired[0], st.q_desired[1], st.q_desired[2], st.q_desired[3]);
  moving_now_ = std::abs(s.qd_a[0]) >= kRestSwingRate;
  for (int j = 1; j < 4; ++j) moving_now_ = moving_now_ || std::abs(s.qd_a[j]) >= kRestCylinderRate;
  if (moving_now_) last_moving_ = s.time;
  if (judge_) judge_->record(s.time, s.q_a, s.qd_a, hydraulic_ && s.hydraulics.swing_brake_applied);
  peak_soil_force_ = std::max(peak_soil_force_, s.soil_force.norm());
  if (hydraulic_) {
    peak_pressure_ = std::max(peak_pressure_, s.hydraulics.max_pressure);
    min_pressure_ = std::min(min_pressure_, s.hydraulics.min_pressure);
  }
  phases_.add(s.time, scene_.cycle, static_cast<safety::Mode>(st.mode), st.tracking, s.q_a, q_desired);
  if (st.tracking) {
    const std::size_t c = starts_.empty() ? 0
        : static_cast<std::size_t>(std::max<std::ptrdiff_t>(
              0, std::upper_bound(starts_.begin(), starts_.end(), st.task_time) - starts_.begin() - 1));
    CycleRecord& rec = cycles_[c];
    if (rec.samples == 0) rec.start = s.time;
    rec.end = s.time;
    ++rec.samples;
    for (int j = 0; j < 4; ++j) {
      const double e = s.q_a[j] - q_desired[j];
      cycle_sum_sq_[c][j] += e * e;
      rec.max_error[j] = std::max(rec.max_error[j], std::abs(e));
    }
    rec.peak_soil_force = std::max(rec.peak_soil_force, s.soil_force.norm());
    for (int i = 0; i < 6; ++i) rec.theta_hat[i] = st.theta_hat[i];
  }
  if (first_safe_stop_time_ < 0 && st.safe_stops > 0) {
    // The firmware's clock (the schedule's): the plant's lags it by every SYNC a burst dropped.
    first_safe_stop_time_ = static_cast<double>(st.cycle) * scene_.cycle;
    first_fault_detected_time_ = st.fault_detected_time;
    first_fault_code_ = st.last_fault;
  }
}

bool RunRecorder::runs_on(double now, double rest_horizon) const {
  if (rest_horizon <= 0 || first_safe_stop_time_ < 0 || now >= first_safe_stop_time_ + rest_horizon) return false;
  // At rest for kRestSettle, and a judged stop's drift fit covered (kStopJudgeSpan from its onset).
  const bool judged =
      !judge_ || now >= judge_->fit_onset(first_fault_detected_time_, disagreement_.onset()) + kStopJudgeSpan + scene_.cycle;
  return moving_now_ || now - std::max(last_moving_, 0.0) < kRestSettle || !judged;
}

void RunRecorder::finish(RunRecord& r) const {
  r.hydraulic = hydraulic_;
  // The tracking figures are the tracking phase's (the same samples, the same errors).
  r.tracking = phases_.tracking();
  r.tracking_samples = r.tracking.samples;
  for (int j = 0; j < 4; ++j) {
    r.rms_error[j] = r.tracking.rms_error[j];
    r.max_error[j] = r.tracking.max_error[j];
  }
  r.settle = phases_.settle();
  r.hold = phases_.hold();
  r.stop = phases_.stop();
  for (std::size_t c = 0; c < cycles_.size(); ++c) {
    CycleRecord rec = cycles_[c];
    for (int j = 0; j < 4; ++j)
      rec.rms_error[j] = rec.samples ? std::sqrt(cycle_sum_sq_[c][j] / static_cast<double>(rec.samples)) : 0;
    if (rec.samples > 0) r.cycles.push_back(rec);
  }
  r.peak_soil_force = peak_soil_force_;
  if (hydraulic_) {
    r.peak_pressure = peak_pressure_;
    r.min_pressure = min_pressure_;
  }
  // At rest from the first sample after the last that moved; never, if the last one moved.
  if (!moving_now_) r.machine_at_rest_time = last_moving_ < 0 ? 0.0 : last_moving_ + scene_.cycle;
  r.first_safe_stop_time = first_safe_stop_time_;
  r.first_fault_detected_time = first_fault_detected_time_;
  r.first_fault_code = first_fault_code_;
  r.spool_disagreement_onset = disagreement_.onset();
  if (judge_ && first_safe_stop_time_ >= 0) {
    // The emergency stop's figures (the solenoids' closing, the brake) for a fault that takes it at
    // once; a controlled stop escalated later is judged as the controlled stop it began as.
    const bool emergency =
        safety::stop_of(static_cast<safety::FirmwareFault>(first_fault_code_)) == safety::StopKind::emergency;
    r.stop_judgement = judge_->judge(first_fault_detected_time_, disagreement_.onset(), first_safe_stop_time_, scene_.cycle, emergency);
    if (!r.stop_judgement->judged) r.stop_judgement.reset();
  }
}

}  // namespace exc::sim
