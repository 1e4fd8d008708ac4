#include "diagnostics/loop_counters.hpp"

#include "diagnostics/timing_message.hpp"
#include "telemetry/telemetry_sink.hpp"

namespace exc::diagnostics {

LoopCounters::LoopCounters(double period)
    : cycle("cycle", period * 1e6),
      read("read", 100.0),
      update("control", 100.0),
      write("write", 100.0),
      interval("interval", period * 1.5e6),
      telemetry("telemetry", 100.0),
      estimate("estimate", 100.0),
      law("law", 100.0),
      actuation("actuation", 100.0),
      monitors("monitors", 100.0) {}

PerfCounter& LoopCounters::counter(LoopStage s) {
  switch (s) {
    case LoopStage::cycle: return cycle;
    case LoopStage::read: return read;
    case LoopStage::update: return update;
    case LoopStage::write: return write;
    case LoopStage::interval: return interval;
    case LoopStage::telemetry: return telemetry;
    case LoopStage::estimate: return estimate;
    case LoopStage::law: return law;
    case LoopStage::actuation: return actuation;
    case LoopStage::monitors: return monitors;
  }
  return cycle;
}

void LoopCounters::publish_step(int step, telemetry::TelemetrySink& out, const hal::FirmwareCanPort& port, double window_end,
                                std::int64_t utime) {
  static constexpr LoopStage kStages[kTimingStages] = {LoopStage::cycle,    LoopStage::read,     LoopStage::update,
                                                       LoopStage::write,    LoopStage::telemetry, LoopStage::estimate,
                                                       LoopStage::law,      LoopStage::actuation, LoopStage::monitors};
  if (step % 2 == 1) {
    if (made_ == Made::timing) out.publish(telemetry::Channel::timing, timing_);
    if (made_ == Made::can_stats) out.publish(telemetry::Channel::can_stats, can_stats_);
    made_ = Made::none;
    return;
  }
  const int part = step / 2;
  if (part < kTimingStages) {
    fill_timing((*this)[kStages[part]], static_cast<std::int8_t>(kStages[part]), utime, timing_);
    made_ = Made::timing;
  } else if (part == kTimingStages) {
    if (interval.count() == 0) return;
    fill_timing(interval, static_cast<std::int8_t>(LoopStage::interval), utime, timing_);
    timing_.overruns = static_cast<std::int64_t>(deadline_overruns);
    timing_.skipped = static_cast<std::int64_t>(skipped_deadlines);
    made_ = Made::timing;
  } else {
    // The firmware sends or receives every frame of the two-node bus: its counts are the bus's.
    const double load = bus_load_.update(port.tx_stats().bus_ns + port.rx_bus_ns(), window_end);
    can_stats_ = can_stats_message(port.rx_stats(), port.tx_stats(), 0, utime, load);
    made_ = Made::can_stats;
  }
}

}  // namespace exc::diagnostics
