// The bus budget, computed from the DBC: the worst-case time (stuffing included) of every frame at
// 1 Mbit/s arbitration and 5 Mbit/s data phase (CAN FD with bit-rate switch), summed over the worst
// 1 ms cycle of each command set; and the exact frame lengths the bus load is measured with.
#include <doctest/doctest.h>

#include <algorithm>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "dbc_reader.hpp"
#include "hal/can_bus_load.hpp"

using exc::hal::canfd_frame_bits;
using exc::hal::canfd_frame_bits_worst;
using exc::hal::canfd_payload_bytes;
using exc::hal::classical_frame_bits_worst;

namespace {

struct CycleTime {
  std::int64_t cyclic_ns = 0;     // the 1 ms frames of one command set
  std::int64_t worst_ns = 0;      // ... plus a heartbeat and every event frame in the same cycle
};

std::int64_t worst_ns(const exc::test::DbcMessage& m) {
  REQUIRE(m.fd);
  REQUIRE(m.brs);
  return canfd_frame_bits_worst(m.length).duration_ns();
}

// The worst cycle of the DBC's schedule for one command set (1 effort, 2 valve, 3 pilot; the sets are
// exclusive). Frames with a cycle time of N > 1 ms are spread over the N cycles (the heartbeats at
// cycle mod 100 = 0 and 50), so a cycle carries at most ceil(group / N) of a group sharing that cycle
// time: count the longest ones. Event frames (the two emergencies, SUPERVISOR) may all come in one cycle.
CycleTime worst_cycle(const std::vector<exc::test::DbcMessage>& dbc, int command_set) {
  CycleTime t;
  std::map<int, std::vector<std::int64_t>> slow_groups;
  std::int64_t events = 0;
  for (const auto& m : dbc) {
    if (m.command_set != 0 && m.command_set != command_set) continue;
    if (m.cycle_ms == 0) {
      events += worst_ns(m);
    } else if (m.cycle_ms == 1) {
      t.cyclic_ns += worst_ns(m);
    } else {
      slow_groups[m.cycle_ms].push_back(worst_ns(m));
    }
  }
  t.worst_ns = t.cyclic_ns + events;
  for (auto& [period, times] : slow_groups) {
    std::sort(times.rbegin(), times.rend());
    const std::size_t per_cycle = (times.size() + static_cast<std::size_t>(period) - 1) / static_cast<std::size_t>(period);
    for (std::size_t i = 0; i < per_cycle && i < times.size(); ++i) t.worst_ns += times[i];
  }
  return t;
}

// The kernel's worst-case length of a standard CAN FD frame with intermission, written out from
// include/linux/can/length.h (as reworked in 2023): can_bitstuffing_len(22 + 8 n) + CRC field with delimiter
// (28 bits up to 16 bytes, else 33) + ACK, ACK delimiter, EOF (9) + intermission (3).
int kernel_canfd_frame_bits(int n) {
  const int destuffed = 22 + 8 * n;
  return destuffed + (destuffed - 1) / 4 + (n <= 16 ? 28 : 33) + 9 + 3;
}

}  // namespace

TEST_CASE("hal/bus budget frame length formulas match the published worst cases") {
  // Classical: a standard 8-byte frame is at most 135 bits with stuffing (Davis et al., "CAN
  // schedulability analysis refuted, revisited and revised", 2007; can-utils 55 + 10 n).
  CHECK(classical_frame_bits_worst(8) == 135);
  CHECK(classical_frame_bits_worst(0) == 55);
  for (int n = 0; n <= 8; ++n) CHECK(classical_frame_bits_worst(n) == 55 + 10 * n);
  // CAN FD: the same total as the kernel's can_frame_bits(), at every FD length; 67 bits empty,
  // 712 bits for 64 bytes.
  CHECK(canfd_frame_bits_worst(0).total() == 67);
  CHECK(canfd_frame_bits_worst(8).total() == 147);
  CHECK(canfd_frame_bits_worst(48).total() == 552);
  CHECK(canfd_frame_bits_worst(64).total() == 712);
  for (int n : {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64}) {
    CAPTURE(n);
    CHECK(canfd_frame_bits_worst(n).total() == kernel_canfd_frame_bits(n));
    // At the nominal rate: SOF to BRS (17) with at most 4 stuff bits, CRC delimiter to intermission (13).
    CHECK(canfd_frame_bits_worst(n).nominal == 34);
  }
  CHECK(canfd_payload_bytes(9) == 12);
  CHECK(canfd_payload_bytes(33) == 48);
  CHECK(canfd_payload_bytes(65) == -1);
  // At 1 and 5 Mbit/s: 34 us + 200 ns per data-phase bit.
  CHECK(canfd_frame_bits_worst(4).duration_ns() == 48'600);
  CHECK(canfd_frame_bits_worst(48).duration_ns() == 137'600);
}

TEST_CASE("hal/bus budget of the DBC schedule: every command set's worst cycle at or under 50% of 1 ms on CAN FD 1/5 Mbit/s") {
  exc::test::DbcNetwork network;
  const auto dbc = exc::test::read_dbc(EXC_CAN_DBC_FILE, &network);
  REQUIRE(network.baudrate == exc::hal::kNominalBitRate);       // the rates the times are computed at
  REQUIRE(network.baudrate_canfd == exc::hal::kDataBitRate);
  const std::string names[] = {"", "effort", "valve", "pilot"};
  // The figures docs/can-protocol.md states, from the DBC with the worst-case frame lengths:
  //   cyclic: SYNC (4 B) + the command frame + SENS_MACHINE (48 B)
  //   worst:  cyclic + a heartbeat (2 B) + both emergency frames (4 B each) + SUPERVISOR (2 B)
  const std::int64_t cyclic[] = {0, 250'800, 242'800, 258'800};
  const std::int64_t worst[] = {0, 437'200, 429'200, 445'200};
  for (int set = 1; set <= 3; ++set) {
    CAPTURE(names[set]);
    const CycleTime t = worst_cycle(dbc, set);
    MESSAGE(names[set], " commands: cyclic frames ", t.cyclic_ns / 1000.0, " us (", t.cyclic_ns / 1e4,
            " % of 1 ms), worst cycle with a heartbeat, both emergency frames and SUPERVISOR ", t.worst_ns / 1000.0, " us (",
            t.worst_ns / 1e4, " %)");
    CHECK(t.cyclic_ns == cyclic[set]);
    CHECK(t.worst_ns == worst[set]);
    CHECK(t.worst_ns <= 500'000);  // the budget: half of the 1 ms cycle
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
    const std::uint8_t len = static_cast<std::uint8_t>(next() % 9);
    std::uint8_t data[8] = {};
    for (int i = 0; i < len; ++i) data[i] = static_cast<std::uint8_t>(next() >> 24);
    const int n = exc::hal::classical_frame_bits(next() & 0x7FF, len, data);
    CHECK(n >= 47 + 8 * len);
    CHECK(n <= classical_frame_bits_worst(len));
    longest[len] = std::max(longest[len], n);
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

TEST_CASE("hal/exact CAN FD frame length: worked frames bit by bit, and every content between the unstuffed and the worst case") {
  // ID 0x000, no data, BRS. Bits: SOF 0, ID 00000000000, RRS 0, IDE 0, FDF 1, res 0, BRS 1, ESI 0,
  // DLC 0000. Five zeros (SOF and 4 ID bits) -> stuff 1; five more ID zeros -> stuff 1; then
  // 0 0 | 0 0 1 0 1 (RRS IDE FDF res BRS) and ESI + DLC, five zeros -> stuff 1 after the last DLC bit.
  // Nominal: 17 + 2 stuff + 13 (CRC delimiter .. intermission) = 32; data: ESI + DLC 5 + 1 stuff +
  // 27 (stuff count and CRC-17 with fixed stuff bits) = 33.
  const exc::hal::CanFdFrameBits empty = canfd_frame_bits(0x000, 0, nullptr, true);
  CHECK(empty.nominal == 32);
  CHECK(empty.data == 33);
  CHECK(empty.duration_ns() == 32 * 1000 + 33 * 200);
  // ID 0x555 (10101010101) and eight bytes 0x55: never five equal bits, no stuff bit at all.
  std::uint8_t alternating[8];
  std::fill(std::begin(alternating), std::end(alternating), 0x55);
  const exc::hal::CanFdFrameBits none = canfd_frame_bits(0x555, 8, alternating, true);
  CHECK(none.nominal == 30);
  CHECK(none.data == 5 + 64 + 27);
  // Without the bit-rate switch every bit is nominal.
  const exc::hal::CanFdFrameBits slow = canfd_frame_bits(0x555, 8, alternating, false);
  CHECK(slow.data == 0);
  CHECK(slow.nominal == none.total());

  std::mt19937 random(99);
  const int lengths[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};
  for (int n : lengths) {
    CAPTURE(n);
    const exc::hal::CanFdFrameBits worst = canfd_frame_bits_worst(n);
    const int unstuffed_data = 5 + 8 * n + exc::hal::canfd_crc_field_bits(n);
    for (int trial = 0; trial < 2000; ++trial) {
      std::uint8_t data[64];
      // Random bytes, and runs of equal bytes that stuff heavily.
      const bool runs = trial % 2 == 0;
      for (int i = 0; i < n; ++i) data[i] = runs ? static_cast<std::uint8_t>((random() % 2) ? 0xFF : 0x00) : static_cast<std::uint8_t>(random());
      const exc::hal::CanFdFrameBits b = canfd_frame_bits(random() & 0x7FF, static_cast<std::uint8_t>(n), data, true);
      CHECK(b.nominal >= 30);
      CHECK(b.nominal <= worst.nominal);
      CHECK(b.data >= unstuffed_data);
      CHECK(b.total() <= worst.total());
      CHECK(b.duration_ns() <= worst.duration_ns());
    }
  }
  // frame_time_ns: classical frames at the nominal rate, FD frames at both.
  exc::hal::CanFrame f;
  f.id = 0x555;
  f.len = 8;
  std::copy(std::begin(alternating), std::end(alternating), f.data);
  CHECK(exc::hal::frame_time_ns(f) == exc::hal::classical_frame_bits(0x555, 8, alternating) * 1000);
  f.fd = true;
  CHECK(exc::hal::frame_time_ns(f) == none.total() * 1000);
  f.brs = true;
  CHECK(exc::hal::frame_time_ns(f) == 30 * 1000 + 96 * 200);
}

namespace {

// The frame lengths by their definition, bit by bit over an array of the frame's bits (the code
// can_bus_load.cpp had before its byte tables): the reference the table-driven counts must equal.
struct ReferenceBits {
  std::uint8_t bits[22 + 8 * 64 + 15];
  int n = 0;
  void put(std::uint32_t value, int width) {
    for (int b = width - 1; b >= 0; --b) bits[n++] = static_cast<std::uint8_t>((value >> b) & 1u);
  }
  // Stuff bits after bits [0, split) and after [split, n).
  void stuff(int split, int& before, int& after) const {
    before = after = 0;
    int run = 0;
    std::uint8_t last = 2;
    for (int i = 0; i < n; ++i) {
      if (bits[i] == last) {
        ++run;
      } else {
        last = bits[i];
        run = 1;
      }
      if (run == 5) {
        ++(i < split ? before : after);
        last = static_cast<std::uint8_t>(!last);
        run = 1;
      }
    }
  }
};

int reference_classical_bits(std::uint32_t id, int len, const std::uint8_t* data) {
  ReferenceBits s;
  s.put(0, 1);
  s.put(id & 0x7FF, 11);
  s.put(0, 3);
  s.put(static_cast<std::uint32_t>(len), 4);
  for (int i = 0; i < len; ++i) s.put(data[i], 8);
  s.put(exc::hal::can_crc15(s.bits, s.n), 15);
  int stuff = 0, unused = 0;
  s.stuff(s.n, stuff, unused);
  return s.n + stuff + 13;
}

exc::hal::CanFdFrameBits reference_fd_bits(std::uint32_t id, int len, const std::uint8_t* data, bool brs) {
  ReferenceBits s;
  s.put(0, 1);
  s.put(id & 0x7FF, 11);
  s.put(0b0010, 4);  // RRS, IDE, FDF, res
  s.put(brs ? 1 : 0, 1);
  s.put(0, 1);
  s.put(exc::hal::dlc_of_length(static_cast<std::uint8_t>(len)), 4);
  for (int i = 0; i < len; ++i) s.put(data[i], 8);
  int before = 0, after = 0;
  s.stuff(16, before, after);
  const int arbitration = 17 + before;
  const int data_phase = s.n - 17 + after + exc::hal::canfd_crc_field_bits(len);
  if (!brs) return {arbitration + data_phase + 13, 0};
  return {arbitration + 13, data_phase};
}

}  // namespace

TEST_CASE("hal/exact frame length: the byte-table stuffing and CRC equal the bit-by-bit definition on 400000 frames") {
  std::mt19937 random(2024);
  const int fd_lengths[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};
  std::uint8_t data[64];
  int mismatches = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    // Random bytes, runs of 0x00 / 0xFF (stuffing every fifth bit), and bytes near a run's end.
    const int kind = trial % 3;
    const int len = kind == 2 ? 64 : fd_lengths[random() % 16];
    for (int i = 0; i < len; ++i) {
      const std::uint32_t r = random();
      data[i] = kind == 0 ? static_cast<std::uint8_t>(r) : kind == 1 ? static_cast<std::uint8_t>(r % 2 ? 0xFF : 0x00)
                                                                     : static_cast<std::uint8_t>(r % 2 ? 0xF0 : 0x07);
    }
    const std::uint32_t id = random() & 0x7FF;
    const bool brs = (trial / 3) % 2 == 0;
    const exc::hal::CanFdFrameBits got = canfd_frame_bits(id, static_cast<std::uint8_t>(len), data, brs);
    const exc::hal::CanFdFrameBits want = reference_fd_bits(id, len, data, brs);
    mismatches += got.nominal != want.nominal || got.data != want.data;
    const int classical = std::min(len, 8);
    mismatches += exc::hal::classical_frame_bits(id, static_cast<std::uint8_t>(classical), data) !=
                  reference_classical_bits(id, classical, data);
  }
  CHECK(mismatches == 0);
  // Every byte after every stuffing state, one at a time behind a prefix that sets the state.
  for (int prefix = 0; prefix < 256; ++prefix) {
    for (int byte = 0; byte < 256; ++byte) {
      const std::uint8_t two[2] = {static_cast<std::uint8_t>(prefix), static_cast<std::uint8_t>(byte)};
      const exc::hal::CanFdFrameBits got = canfd_frame_bits(0x7FF, 2, two, true);
      const exc::hal::CanFdFrameBits want = reference_fd_bits(0x7FF, 2, two, true);
      CHECK_MESSAGE(got.data == want.data, "bytes " << prefix << " " << byte);
      CHECK(exc::hal::classical_frame_bits(0, 2, two) == reference_classical_bits(0, 2, two));
    }
  }
}
