// Randomized decoder fuzz: millions of random and half-valid frames (classical and CAN FD, every
// length up to 64 bytes) through CanFrameCodec::accept, each verdict compared with a reference check
// written here from the DBC (its own CRC, bit by bit, and its own counter model). Nothing the
// reference rejects may be accepted, and vice versa.
#include <doctest/doctest.h>

#include <array>
#include <map>
#include <random>

#include "dbc_reader.hpp"
#include "hal/can_codec.hpp"

using namespace exc::hal;

namespace {

// CRC-8, polynomial 0x1D, init 0xFF, xor 0xFF, computed bit by bit (no table).
std::uint8_t reference_crc(std::uint32_t id, const std::uint8_t* data, int n) {
  std::uint8_t bytes[2 + 64] = {static_cast<std::uint8_t>(id & 0xFF), static_cast<std::uint8_t>(id >> 8)};
  for (int i = 0; i < n; ++i) bytes[2 + i] = data[i];
  std::uint8_t crc = 0xFF;
  for (int i = 0; i < n + 2; ++i) {
    crc ^= bytes[i];
    for (int b = 0; b < 8; ++b) crc = (crc & 0x80) ? static_cast<std::uint8_t>((crc << 1) ^ 0x1D) : static_cast<std::uint8_t>(crc << 1);
  }
  return crc ^ 0xFF;
}

struct ReferenceSequence {
  bool started = false;
  int last = 0;
  int stale_run = 0;
};

}  // namespace

TEST_CASE("hal/codec fuzz: 2 million random frames, verdicts equal a reference check") {
  const auto dbc = exc::test::read_dbc(EXC_CAN_DBC_FILE);
  std::map<std::uint32_t, int> length_of;
  std::map<std::uint32_t, bool> fd_of;
  std::vector<std::uint32_t> ids;
  for (const auto& m : dbc) {
    length_of[m.id] = m.length;
    fd_of[m.id] = m.fd;
    ids.push_back(m.id);
  }
  constexpr std::uint8_t kLengths[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};
  CanFrameCodec codec;  // gap 3, resync after 3; timestamps stay 0 so the pause rule is off
  std::map<std::uint32_t, ReferenceSequence> reference;
  std::mt19937_64 random(20240611);
  std::array<std::uint64_t, 6> verdicts{};
  std::uint64_t mismatches = 0;
  constexpr int kFrames = 2'000'000;
  for (int n = 0; n < kFrames; ++n) {
    CanFrame frame;
    const std::uint64_t r = random();
    // Mostly protocol IDs (so deeper checks are reached), sometimes any 11-bit or out-of-range ID.
    const int kind = static_cast<int>(r % 16);
    frame.id = kind < 13 ? ids[(r >> 8) % ids.size()] : (kind < 15 ? static_cast<std::uint32_t>((r >> 8) & 0x7FF)
                                                                    : static_cast<std::uint32_t>(r >> 32));
    const auto known = length_of.find(frame.id);
    frame.len = (known != length_of.end() && ((r >> 20) % 8) != 0) ? static_cast<std::uint8_t>(known->second)
                                                                    : kLengths[(r >> 24) % 16];
    // Mostly the DBC's format; one in 16 the other one (a classical frame from a foreign node).
    frame.fd = (known != length_of.end() ? fd_of[frame.id] : true) != (((r >> 44) % 16) == 0);
    if (!frame.fd && frame.len > 8) frame.len = 8;
    frame.brs = frame.fd && ((r >> 48) & 1);
    for (int i = 0; i < frame.len; i += 8) {
      const std::uint64_t payload = random();
      for (int b = 0; b < 8 && i + b < frame.len; ++b) frame.data[i + b] = static_cast<std::uint8_t>(payload >> (8 * b));
    }
    const bool right_format = known != length_of.end() && frame.len == known->second && frame.fd == fd_of[frame.id];
    // Half of the right-format frames get a valid checksum, so the counter logic is fuzzed too.
    if (right_format && ((r >> 40) & 1)) {
      frame.data[frame.len - 1] = reference_crc(frame.id, frame.data, frame.len - 1);
    }

    RxVerdict expected = RxVerdict::ok;
    if (known == length_of.end()) {
      expected = RxVerdict::unknown_id;
    } else if (!right_format) {
      expected = RxVerdict::wrong_format;
    } else if (frame.data[frame.len - 1] != reference_crc(frame.id, frame.data, frame.len - 1)) {
      expected = RxVerdict::corrupt;
    } else {
      ReferenceSequence& seq = reference[frame.id];
      const int counter = frame.data[0] & 0x0F;
      if (seq.started) {
        const int delta = ((counter - seq.last) % 16 + 16) % 16;
        if (delta == 0) expected = RxVerdict::repeated;
        else if (delta > 3) expected = RxVerdict::stale;
      }
      if (expected == RxVerdict::stale) {
        if (++seq.stale_run >= 3) {
          seq.last = counter;
          seq.stale_run = 0;
        }
      } else if (expected == RxVerdict::ok) {
        seq = {true, counter, 0};
      }
    }

    const MessageSpec* message = nullptr;
    const RxVerdict got = codec.accept(frame, message);
    ++verdicts[static_cast<std::size_t>(got)];
    if (got != expected || (got == RxVerdict::ok) != (message != nullptr)) {
      if (++mismatches <= 5) {
        MESSAGE("mismatch: id ", frame.id, " len ", int(frame.len), " fd ", frame.fd, " got ", to_string(got), " expected ",
                to_string(expected));
      }
    }
    if (message != nullptr) {
      double values[kMaxDataSignals];
      decode_message(*message, frame, values);  // must not crash on any accepted payload
    }
  }
  MESSAGE("verdicts: ok ", verdicts[0], ", unknown ", verdicts[1], ", wrong_format ", verdicts[2], ", corrupt ", verdicts[3],
          ", repeated ", verdicts[4], ", stale ", verdicts[5]);
  CHECK(mismatches == 0);
  // The fuzz reached every branch.
  for (auto count : verdicts) CHECK(count > 1000);
  const RxStats& stats = codec.stats();
  CHECK(stats.ok + stats.rejected() == static_cast<std::uint64_t>(kFrames));
}
