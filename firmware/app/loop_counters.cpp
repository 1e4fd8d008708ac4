#include "app/loop_counters.hpp"

#include "app/timing_message.hpp"
#include "exlcm/timing_t.hpp"
#include "telemetry/telemetry_sink.hpp"

namespace exc::app {

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

control::PerfCounter& LoopCounters::counter(LoopStage s) {
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

void LoopCounters::publish(telemetry::TelemetrySink& out, const hal::FirmwareCanPort& port, double window_end, std::int64_t utime) {
  exlcm::timing_t m{};
  for (const LoopStage s : {LoopStage::cycle, LoopStage::read, LoopStage::update, LoopStage::write, LoopStage::telemetry,
                            LoopStage::estimate, LoopStage::law, LoopStage::actuation, LoopStage::monitors}) {
    fill_timing((*this)[s], static_cast<std::int8_t>(s), utime, m);
    out.publish(telemetry::Channel::timing, m);
  }
  if (interval.count() > 0) {
    fill_timing(interval, static_cast<std::int8_t>(LoopStage::interval), utime, m);
    m.overruns = static_cast<std::int64_t>(deadline_overruns);
    m.skipped = static_cast<std::int64_t>(skipped_deadlines);
    out.publish(telemetry::Channel::timing, m);
  }
  // The firmware sends or receives every frame of the two-node bus: its counts are the bus's.
  const double load = bus_load_.update(port.tx_stats().bus_ns + port.rx_bus_ns(), window_end);
  out.publish(telemetry::Channel::can_stats, can_stats_message(port.rx_stats(), port.tx_stats(), 0, utime, load));
}

}  // namespace exc::app
