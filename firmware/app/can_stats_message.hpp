#pragma once
// One bus end's CAN counters as the can_stats_t telemetry message (both the firmware and the plant
// publish theirs on EXC_CAN_STATS).
#include <cstdint>

#include "exlcm/can_stats_t.hpp"
#include "hal/can_bus_load.hpp"
#include "hal/can_ports.hpp"

namespace exc::app {

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
  cs.wrong_dlc = static_cast<std::int64_t>(rx.wrong_dlc);
  cs.unknown = static_cast<std::int64_t>(rx.unknown_id);
  cs.dropped = static_cast<std::int64_t>(tx.send_failed);
  cs.bus_load = bus_load;
  return cs;
}

// Bus load over a window: on-wire bits counted by the port since the last call over what the bus
// carries at 1 Mbit/s in the window's (simulated or real) time.
class BusLoadWindow {
 public:
  double update(std::uint64_t total_bits, double now_s) {
    const double span = now_s - last_time_;
    const double load = span > 0 ? static_cast<double>(total_bits - last_bits_) / (hal::kClassicalBitRate * span) : 0;
    last_bits_ = total_bits;
    last_time_ = now_s;
    return load;
  }

 private:
  std::uint64_t last_bits_ = 0;
  double last_time_ = 0;
};

}  // namespace exc::app
