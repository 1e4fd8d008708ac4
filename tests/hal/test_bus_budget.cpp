// The bus budget, computed from the DBC: worst-case bits (with stuffing) in one 1 ms cycle at
// 1 Mbit/s classical CAN, and what CAN FD would take for the same signals.
#include <doctest/doctest.h>

#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include "dbc_reader.hpp"
#include "hal/can_bus_load.hpp"

using exc::hal::canfd_frame_bits_worst;
using exc::hal::canfd_payload_bytes;
using exc::hal::classical_frame_bits_worst;

namespace {

struct CycleLoad {
  int cyclic_bits = 0;     // frames sent every cycle (one command set) + the slower frames of that cycle
  int emergency_bits = 0;  // both event-driven emergency frames on top
};

// Worst cycle of the DBC's schedule for one command set (1 effort, 2 valve). Frames with a cycle
// time of N > 1 ms are spread over the N cycles (round robin / offsets, as the ports send them), so
// a cycle carries at most ceil(group / N) of a group of frames sharing that cycle time: count the
// largest ones.
CycleLoad worst_cycle(const std::vector<exc::test::DbcMessage>& dbc, int command_set) {
  CycleLoad load;
  std::map<int, std::vector<int>> slow_groups;
  for (const auto& m : dbc) {
    if (m.command_set != 0 && m.command_set != command_set) continue;
    const int bits = classical_frame_bits_worst(m.dlc);
    if (m.cycle_ms == 0) {
      load.emergency_bits += bits;
    } else if (m.cycle_ms == 1) {
      load.cyclic_bits += bits;
    } else {
      slow_groups[m.cycle_ms].push_back(bits);
    }
  }
  for (auto& [period, bits] : slow_groups) {
    std::sort(bits.rbegin(), bits.rend());
    const std::size_t per_cycle = (bits.size() + static_cast<std::size_t>(period) - 1) / static_cast<std::size_t>(period);
    for (std::size_t i = 0; i < per_cycle && i < bits.size(); ++i) load.cyclic_bits += bits[i];
  }
  return load;
}

int data_bits(const exc::test::DbcMessage& m) {
  int bits = 0;
  for (std::size_t i = 1; i + 1 < m.signals.size(); ++i) bits += m.signals[i].length;  // without Counter and Crc
  return bits;
}

}  // namespace

TEST_CASE("hal/bus budget frame length formula matches the published worst cases") {
  // Independent figures: a standard 8-byte frame is at most 135 bits with stuffing (Davis et al.,
  // "CAN schedulability analysis refuted, revisited and revised", 2007; can-utils 55 + 10 n), an
  // empty one 55 bits.
  CHECK(classical_frame_bits_worst(8) == 135);
  CHECK(classical_frame_bits_worst(0) == 55);
  for (int n = 0; n <= 8; ++n) CHECK(classical_frame_bits_worst(n) == 55 + 10 * n);
  CHECK(canfd_payload_bytes(9) == 12);
  CHECK(canfd_payload_bytes(33) == 48);
}

TEST_CASE("hal/bus budget of the DBC schedule at 1 Mbit/s classical CAN, and the CAN FD alternative") {
  const auto dbc = exc::test::read_dbc(EXC_CAN_DBC_FILE);
  const CycleLoad effort = worst_cycle(dbc, 1);
  const CycleLoad valve = worst_cycle(dbc, 2);
  const int cyclic = std::max(effort.cyclic_bits, valve.cyclic_bits);
  const int with_emergency = std::max(effort.cyclic_bits + effort.emergency_bits, valve.cyclic_bits + valve.emergency_bits);
  MESSAGE("classical CAN, worst cycle: effort ", effort.cyclic_bits, " bits, valve ", valve.cyclic_bits,
          " bits; with both emergency frames ", with_emergency, " bits; budget 500 bits (50% of 1 ms at 1 Mbit/s)");
  // The figures docs/can-protocol.md and the README state (counted from the DBC with the published
  // worst-case frame length): 985 bits in the worst effort cycle, 98.5 % of the bus. It fits the
  // 1 ms cycle, so the SYNC-driven loop runs on a real bus, but not the 50 % budget: issue 14 moves
  // the interface to CAN FD for that.
  CHECK(effort.cyclic_bits == 985);
  CHECK(valve.cyclic_bits == 890);
  CHECK(with_emergency == 1175);
  CHECK(cyclic <= 1000);
  if (cyclic > 500) MESSAGE("classical CAN does NOT meet the 50% budget: ", cyclic / 10.0, "% of the bus");

  // CAN FD with bit-rate switch: every frame becomes an FD frame; the command frames merge into one
  // (both effort halves), the sensor frames into one carrying all pressures every cycle.
  int sensor_bits = 12;   // one Counter + Crc for the merged sensor frame
  int command_bits = 12;  // likewise for the merged command frame
  int effort_bits = 0;
  int valve_bits = 0;
  std::vector<int> other_frames;      // SYNC and the heavier heartbeat: unchanged payloads
  std::vector<int> emergency_frames;  // both emergency frames
  int heartbeat_bytes = 0;
  for (const auto& m : dbc) {
    if (m.name.rfind("SENS_", 0) == 0) {
      sensor_bits += data_bits(m);
    } else if (m.command_set == 1) {
      effort_bits += data_bits(m);
    } else if (m.command_set == 2) {
      valve_bits += data_bits(m);
    } else if (m.cycle_ms == 100) {
      heartbeat_bytes = std::max(heartbeat_bytes, m.dlc);
    } else if (m.cycle_ms == 0) {
      emergency_frames.push_back(m.dlc);
    } else {
      other_frames.push_back(m.dlc);
    }
  }
  other_frames.push_back(heartbeat_bytes);
  command_bits += std::max(effort_bits, valve_bits);
  const int sensor_bytes = canfd_payload_bytes((sensor_bits + 7) / 8);
  const int command_bytes = canfd_payload_bytes((command_bits + 7) / 8);
  for (double data_rate : {2e6, 5e6}) {
    double ns = canfd_frame_bits_worst(sensor_bytes).duration_ns(1e6, data_rate) +
                canfd_frame_bits_worst(command_bytes).duration_ns(1e6, data_rate);
    for (int bytes : other_frames) ns += canfd_frame_bits_worst(bytes).duration_ns(1e6, data_rate);
    double emergency_ns = 0;
    for (int bytes : emergency_frames) emergency_ns += canfd_frame_bits_worst(bytes).duration_ns(1e6, data_rate);
    ns += emergency_ns;
    MESSAGE("CAN FD 1/", data_rate / 1e6, " Mbit/s: sensor frame ", sensor_bytes, " B, command frame ", command_bytes,
            " B; worst cycle ", (ns - emergency_ns) / 1000.0, " us, with both emergency frames ", ns / 1000.0,
            " us (", ns / 1e4, "% of 1 ms)");
    if (data_rate == 5e6) CHECK(ns <= 500'000.0);
  }
}

TEST_CASE("hal/exact frame length: CRC-15 check value, no-stuff and worst-case frames, bounded by the worst-case formula") {
  // CRC-15/CAN of the ASCII string "123456789" is 0x059E (the CRC catalogue's check value).
  std::vector<std::uint8_t> bits;
  for (char c : std::string("123456789"))
    for (int b = 7; b >= 0; --b) bits.push_back(static_cast<std::uint8_t>((c >> b) & 1));
  CHECK(exc::hal::can_crc15(bits.data(), static_cast<int>(bits.size())) == 0x059E);

  // Every frame lies between the unstuffed length (47 + 8 n) and the worst case, whatever its content.
  std::uint32_t state = 12345;
  const auto next = [&state] { return state = state * 1664525u + 1013904223u; };
  int longest[9] = {};
  for (int trial = 0; trial < 20000; ++trial) {
    const std::uint8_t dlc = static_cast<std::uint8_t>(next() % 9);
    std::uint8_t data[8] = {};
    for (int i = 0; i < dlc; ++i) data[i] = static_cast<std::uint8_t>(next() >> 24);
    const int n = exc::hal::classical_frame_bits(next() & 0x7FF, dlc, data);
    CHECK(n >= 47 + 8 * dlc);
    CHECK(n <= classical_frame_bits_worst(dlc));
    longest[dlc] = std::max(longest[dlc], n);
  }
  // All-zero content stuffs every fifth bit from SOF on: far more than random data, and never more
  // than the worst case.
  const std::uint8_t zeros[8] = {};
  const int zero_frame = exc::hal::classical_frame_bits(0, 8, zeros);
  MESSAGE("8-byte frame: all zeros " << zero_frame << " bits, longest of random content " << longest[8]
                                     << ", worst case " << classical_frame_bits_worst(8));
  CHECK(zero_frame > 47 + 64 + 15);
  CHECK(zero_frame <= classical_frame_bits_worst(8));
}
