#pragma once
// One bus end's CAN counters as the can_stats_t telemetry message (both the firmware and the plant
// publish theirs on EXC_CAN_STATS).
#include <cstdint>

#include "exlcm/can_stats_t.hpp"
#include "hal/can_ports.hpp"

namespace exc::diagnostics {

// bus_load: the fraction of bus time used since the previous message (BusLoadWindow), or 0 where the
// end cannot see the whole bus.
inline exlcm::can_stats_t can_stats_message(const hal::RxStats& rx, const hal::TxStats& tx, std::int8_t node,
                                            std::int64_t utime, double bus_load = 0) {
  exlcm::can_stats_t cs{};
  cs.utime = utime;
  cs.node = node;  // 0 = firmware end, 1 = plant end
  cs.tx = static_cast<std::int64_t>(tx.frames_sent);
  cs.rx_ok = static_cast<std::int64_t>(rx.ok);
  cs.stale = static_cast<std::int64_t>(rx.stale);
  cs.repeated = static_cast<std::int64_t>(rx.repeated);
  cs.corrupt = static_cast<std::int64_t>(rx.corrupt);
  cs.wrong_dlc = static_cast<std::int64_t>(rx.wrong_format);  // the field keeps its name in the logs
  cs.unknown = static_cast<std::int64_t>(rx.unknown_id);
  cs.dropped = static_cast<std::int64_t>(tx.send_failed);
  cs.bus_load = bus_load;
  return cs;
}

// Bus load over a window: the on-wire time of the frames the port counted since the last call (each
// frame's exact length at the nominal and data bit rates, hal/can_bus_load.hpp) over the window's
// (simulated or real) time: the fraction of bus time used.
class BusLoadWindow {
 public:
  double update(std::uint64_t total_bus_ns, double now_s) {
    const double span = now_s - last_time_;
    const double load = span > 0 ? static_cast<double>(total_bus_ns - last_bus_ns_) * 1e-9 / span : 0;
    last_bus_ns_ = total_bus_ns;
    last_time_ = now_s;
    return load;
  }

 private:
  std::uint64_t last_bus_ns_ = 0;
  double last_time_ = 0;
};

}  // namespace exc::diagnostics
