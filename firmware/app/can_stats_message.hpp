#pragma once
// One bus end's CAN counters as the can_stats_t telemetry message (both the firmware and the plant
// publish theirs on EXC_CAN_STATS).
#include <cstdint>

#include "exlcm/can_stats_t.hpp"
#include "hal/can_ports.hpp"

namespace exc::app {

inline exlcm::can_stats_t can_stats_message(const hal::RxStats& rx, const hal::TxStats& tx, std::int8_t node,
                                            std::int64_t utime) {
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
  return cs;
}

}  // namespace exc::app
