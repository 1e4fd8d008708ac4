// The codec against the DBC and against independent checks: CRC check value, every signal's range
// ends, bit placement read back bit by bit with the DBC's factor/offset (over the whole FD payload),
// and each reject kind.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include "dbc_reader.hpp"
#include "hal/can_bus_load.hpp"
#include "hal/can_codec.hpp"

using namespace exc::hal;

namespace {

const exc::test::DbcMessage* dbc_message(const std::vector<exc::test::DbcMessage>& dbc, std::uint32_t id) {
  for (const auto& m : dbc) {
    if (m.id == id) return &m;
  }
  return nullptr;
}

CanFrame encoded(const MessageSpec& message, std::uint8_t counter, const double* values) {
  CanFrame frame;
  encode_message(message, counter, values, frame);
  return frame;
}

// Data values at the middle of each signal's range.
void mid_values(const MessageSpec& message, double* values) {
  for (std::size_t i = 0; i < message.data_signal_count(); ++i) {
    const SignalSpec& s = message.data_signal(i);
    values[i] = 0.5 * (s.min + s.max);
  }
}

}  // namespace

TEST_CASE("hal/crc8 SAE J1850 matches its published check value") {
  const char* text = "123456789";
  CHECK(crc8_sae_j1850(reinterpret_cast<const std::uint8_t*>(text), 9) == 0x4B);
  const std::uint8_t empty = 0;
  CHECK(crc8_sae_j1850(&empty, 0) == 0x00);  // init 0xFF xor 0xFF
}

TEST_CASE("hal/crc8 eight bytes at a time equals the bit-by-bit definition at every length") {
  // The polynomial division one bit at a time (init 0xFF, poly 0x1D, final xor 0xFF), independent of
  // the codec's tables, over random payloads of every length a frame can have and across the 8-byte
  // blocks the codec folds at once.
  auto bitwise = [](const std::uint8_t* bytes, std::size_t length) {
    unsigned crc = 0xFF;
    for (std::size_t i = 0; i < length; ++i) {
      for (int b = 7; b >= 0; --b) {
        const unsigned in = (bytes[i] >> b) & 1u, top = (crc >> 7) & 1u;
        crc = (crc << 1) & 0xFFu;
        if ((in ^ top) != 0) crc ^= 0x1Du;
      }
    }
    return static_cast<std::uint8_t>(crc ^ 0xFF);
  };
  std::mt19937 random(34);
  std::uint8_t bytes[kCanFdMaxLength + 2];
  for (int trial = 0; trial < 50; ++trial) {
    for (auto& b : bytes) b = static_cast<std::uint8_t>(random());
    for (std::size_t length = 0; length <= sizeof bytes; ++length) {
      CAPTURE(length);
      CHECK(crc8_sae_j1850(bytes, length) == bitwise(bytes, length));
    }
    // frame_checksum is the same CRC over the identifier's two bytes (little-endian), then the payload.
    const std::uint32_t id = random() & 0x7FFu;
    std::uint8_t with_id[2 + kCanFdMaxLength];
    with_id[0] = static_cast<std::uint8_t>(id & 0xFF);
    with_id[1] = static_cast<std::uint8_t>(id >> 8);
    std::memcpy(with_id + 2, bytes, kCanFdMaxLength);
    for (std::size_t length = 0; length < kCanFdMaxLength; ++length)
      CHECK(frame_checksum(id, bytes, length) == bitwise(with_id, length + 2));
  }
}

TEST_CASE("hal/codec tables match excavator.dbc message by message and signal by signal") {
  exc::test::DbcNetwork network;
  const auto dbc = exc::test::read_dbc(EXC_CAN_DBC_FILE, &network);
  REQUIRE(dbc.size() == kMessageCount);
  // The bus the DBC states is the one the bus time is computed for.
  CHECK(network.baudrate == exc::hal::kNominalBitRate);
  CHECK(network.baudrate_canfd == exc::hal::kDataBitRate);
  std::size_t most_data_signals = 0;
  for (const MessageSpec& message : protocol_messages()) {
    CAPTURE(message.name);
    const auto* d = dbc_message(dbc, message.id);
    REQUIRE(d != nullptr);
    CHECK(d->name == message.name);
    CHECK(d->length == message.length);
    CHECK(valid_length(message.length, message.fd));
    CHECK(d->fd == message.fd);
    CHECK(d->brs == message.brs);
    CHECK(message.fd);  // every frame of the protocol is CAN FD with bit-rate switch
    CHECK(message.brs);
    CHECK(d->sender == to_string(message.sender));
    CHECK(d->cycle_ms == message.cycle_ms);
    CHECK(d->command_set == static_cast<int>(message.command_set));
    REQUIRE(d->signals.size() == message.signal_count);
    most_data_signals = std::max<std::size_t>(most_data_signals, message.data_signal_count());
    CHECK(d->signals.front().name == "Counter");
    CHECK(d->signals.back().name == "Crc");
    CHECK(d->signals.back().start == 8 * (d->length - 1));
    int used_bits = 0;
    for (std::size_t i = 0; i < message.signal_count; ++i) {
      const SignalSpec& s = message.signals[i];
      const auto& ds = d->signals[i];
      CAPTURE(s.name);
      CHECK(ds.name == s.name);
      CHECK(ds.little_endian);
      CHECK(ds.start == s.start);
      CHECK(ds.length == s.length);
      CHECK(ds.is_signed == s.is_signed);
      CHECK(ds.factor == doctest::Approx(s.factor).epsilon(1e-12));
      CHECK(ds.offset == doctest::Approx(s.offset).epsilon(1e-12));
      CHECK(ds.min == doctest::Approx(s.min).epsilon(1e-12));
      CHECK(ds.max == doctest::Approx(s.max).epsilon(1e-12));
      CHECK(ds.unit == s.unit);
      CHECK(ds.start + ds.length <= 8 * d->length);
      used_bits += ds.length;
    }
    CHECK(used_bits <= 8 * d->length);
    // No two signals share a bit.
    std::vector<int> owner(8 * static_cast<std::size_t>(d->length), -1);
    for (std::size_t i = 0; i < d->signals.size(); ++i) {
      for (int b = d->signals[i].start; b < d->signals[i].start + d->signals[i].length; ++b) {
        CHECK_MESSAGE(owner[static_cast<std::size_t>(b)] < 0, d->signals[i].name, " overlaps at bit ", b);
        owner[static_cast<std::size_t>(b)] = static_cast<int>(i);
      }
    }
  }
  CHECK(most_data_signals == kMaxDataSignals);
}

TEST_CASE("hal/codec raw bit fields anywhere in the 64-byte payload read back what was written, and nothing else moves") {
  std::mt19937_64 random(3);
  for (int trial = 0; trial < 20000; ++trial) {
    const unsigned length = 1 + static_cast<unsigned>(random() % 64);
    const unsigned start = static_cast<unsigned>(random() % (8 * kCanFdMaxLength - length + 1));
    CanFrame frame;
    for (auto& byte : frame.data) byte = static_cast<std::uint8_t>(random());
    const CanFrame before = frame;
    const std::uint64_t raw = random() & (length == 64 ? ~0ULL : ((1ULL << length) - 1));
    write_raw_bits(frame, start, length, raw);
    CHECK(read_raw_bits(frame, start, length) == raw);
    // Bit by bit, independently of the codec's loop.
    for (unsigned bit = 0; bit < 8 * kCanFdMaxLength; ++bit) {
      const int got = (frame.data[bit / 8] >> (bit % 8)) & 1;
      const int want = (bit >= start && bit < start + length) ? static_cast<int>((raw >> (bit - start)) & 1)
                                                              : (before.data[bit / 8] >> (bit % 8)) & 1;
      if (got != want) {
        FAIL_CHECK("bit ", bit, " of a ", length, "-bit field at ", start);
        break;
      }
    }
  }
  // A field reaching past the payload is neither read nor written.
  CanFrame frame;
  write_raw_bits(frame, 8 * kCanFdMaxLength - 4, 8, 0xFF);
  for (auto byte : frame.data) CHECK(byte == 0);
  frame.data[kCanFdMaxLength - 1] = 0xFF;
  CHECK(read_raw_bits(frame, 8 * kCanFdMaxLength - 4, 8) == 0);
}

TEST_CASE("hal/codec puts every signal in the bits, factor and offset the DBC gives") {
  const auto dbc = exc::test::read_dbc(EXC_CAN_DBC_FILE);
  for (const MessageSpec& message : protocol_messages()) {
    const auto* d = dbc_message(dbc, message.id);
    REQUIRE(d != nullptr);
    // Each data signal in turn at a few physical values, the others at mid range.
    for (std::size_t k = 0; k < message.data_signal_count(); ++k) {
      const auto& ds = d->signals[k + 1];
      CAPTURE(message.name);
      CAPTURE(ds.name);
      for (double fraction : {0.0, 0.1234, 0.5, 0.87, 1.0}) {
        double values[kMaxDataSignals];
        mid_values(message, values);
        const double wanted = ds.min + fraction * (ds.max - ds.min);
        values[k] = wanted;
        const CanFrame frame = encoded(message, 9, values);
        CHECK(frame.id == d->id);
        CHECK(frame.len == d->length);
        CHECK(frame.fd == d->fd);
        CHECK(frame.brs == d->brs);
        // Read back with the DBC's own layout, independently of the codec.
        CHECK(std::fabs(exc::test::dbc_physical(frame.data, ds) - wanted) <= 0.5 * ds.factor * (1 + 1e-9));
        CHECK(exc::test::dbc_raw(frame.data, d->signals.front()) == 9);  // counter
        const auto& crc = d->signals.back();
        CHECK(exc::test::dbc_raw(frame.data, crc) == frame_checksum(frame.id, frame.data, d->length - 1u));
      }
    }
  }
}

TEST_CASE("hal/codec round trip of every signal at both range ends and beyond") {
  for (const MessageSpec& message : protocol_messages()) {
    for (std::size_t k = 0; k < message.data_signal_count(); ++k) {
      const SignalSpec& s = message.data_signal(k);
      CAPTURE(message.name);
      CAPTURE(s.name);
      double values[kMaxDataSignals];
      double back[kMaxDataSignals];
      for (double end : {s.min, s.max}) {
        mid_values(message, values);
        values[k] = end;
        CanFrame frame;
        const EncodeReport report = encode_message(message, 3, values, frame);
        CHECK(report.clean());
        decode_message(message, frame, back);
        CHECK(std::fabs(back[k] - end) <= 0.5 * s.factor * (1 + 1e-9));
        CHECK(back[k] >= s.min - 1e-9 * std::fabs(s.min) - 1e-12);
        CHECK(back[k] <= s.max + 1e-9 * std::fabs(s.max) + 1e-12);
      }
      // Outside the range: saturated to the nearer end and reported.
      const double span = s.max - s.min;
      for (double outside : {s.min - 0.25 * span, s.max + 0.25 * span}) {
        mid_values(message, values);
        values[k] = outside;
        CanFrame frame;
        const EncodeReport report = encode_message(message, 3, values, frame);
        CHECK(report.saturated == 1);
        decode_message(message, frame, back);
        const double end = outside < s.min ? s.min : s.max;
        CHECK(std::fabs(back[k] - end) <= 0.5 * s.factor * (1 + 1e-9));
      }
      // NaN never reaches the wire as garbage: it is reported and sent as the in-range value nearest 0.
      mid_values(message, values);
      values[k] = std::numeric_limits<double>::quiet_NaN();
      CanFrame frame;
      const EncodeReport report = encode_message(message, 3, values, frame);
      CHECK(report.non_finite == 1);
      decode_message(message, frame, back);
      const double nearest_zero = s.min > 0 ? s.min : (s.max < 0 ? s.max : 0.0);
      CHECK(std::fabs(back[k] - nearest_zero) <= 0.5 * s.factor * (1 + 1e-9));
    }
  }
}

TEST_CASE("hal/codec resolution of the physical signals meets the protocol's targets") {
  // Independent targets from the design brief, not from the tables' own values.
  const auto factor = [](std::uint32_t id, const char* name) {
    const MessageSpec* m = find_message(id);
    for (std::size_t i = 0; i < m->signal_count; ++i) {
      if (std::string(m->signals[i].name) == name) return m->signals[i].factor;
    }
    return -1.0;
  };
  CHECK(factor(can_id::sens_machine, "BoomLength") <= 1e-5);
  CHECK(factor(can_id::sens_machine, "ArmRate") <= 1e-4);
  CHECK(factor(can_id::sens_machine, "SwingAngle") <= 1e-5);
  CHECK(factor(can_id::cmd_effort, "BoomForce") <= 25);
  CHECK(factor(can_id::cmd_effort, "SwingTorque") <= 5);
  // Pressures: 0.02 MPa per bit is what the opened ZX200 sends its pilots with (hydraulics.md); the
  // chambers and pumps must read better than the 0.2 MPa of its feedback.
  CHECK(factor(can_id::cmd_pilot, "BoomPilotA") <= 0.02e6);
  for (const char* p : {"SwingPressureB", "BucketPressureA", "Pump2Pressure"}) {
    CAPTURE(p);
    CHECK(factor(can_id::sens_machine, p) <= 0.01e6);
  }
  // Ranges: pilots 0-5 MPa, chambers up to the port reliefs (36.8 MPa).
  const auto range_max = [](std::uint32_t id, const char* name) {
    const MessageSpec* m = find_message(id);
    for (std::size_t i = 0; i < m->signal_count; ++i) {
      if (std::string(m->signals[i].name) == name) return m->signals[i].max;
    }
    return -1.0;
  };
  CHECK(range_max(can_id::cmd_pilot, "ArmPilotB") >= 5e6);
  CHECK(range_max(can_id::sens_machine, "ArmPressureA") >= 36.8e6);
}

TEST_CASE("hal/codec rejects unknown ID, wrong format (length or FD flag) and corrupt checksum, and counts each") {
  CanFrameCodec codec;
  const MessageSpec& sync = *find_message(can_id::sync);
  const double cycle[] = {5};
  const MessageSpec* out = nullptr;

  CanFrame unknown = encoded(sync, 5, cycle);
  unknown.id = 0x555;
  CHECK(codec.accept(unknown, out) == RxVerdict::unknown_id);
  CHECK(out == nullptr);

  CanFrame short_frame = encoded(sync, 5, cycle);
  short_frame.len = 2;
  CHECK(codec.accept(short_frame, out) == RxVerdict::wrong_format);
  CanFrame long_frame = encoded(sync, 5, cycle);
  long_frame.len = 12;
  CHECK(codec.accept(long_frame, out) == RxVerdict::wrong_format);
  // The same bytes as a classical frame (a node that does not speak FD): refused before the CRC.
  CanFrame classical = encoded(sync, 5, cycle);
  classical.fd = classical.brs = false;
  CHECK(codec.accept(classical, out) == RxVerdict::wrong_format);
  CHECK(out == nullptr);
  // An FD frame sent without the bit-rate switch carries the same content: accepted.
  CanFrame slow = encoded(sync, 5, cycle);
  slow.brs = false;
  CHECK(codec.accept(slow, out) == RxVerdict::ok);

  CanFrame corrupt = encoded(sync, 6, cycle);
  corrupt.data[1] ^= 0x10;
  CHECK(codec.accept(corrupt, out) == RxVerdict::corrupt);
  CHECK(out == nullptr);
  // A flipped bit deep in the 48-byte sensor frame.
  const MessageSpec& sensors = *find_message(can_id::sens_machine);
  double mid[kMaxDataSignals];
  mid_values(sensors, mid);
  CanFrame deep = encoded(sensors, 1, mid);
  deep.data[40] ^= 0x04;
  CHECK(codec.accept(deep, out) == RxVerdict::corrupt);

  // A frame whose ID was changed into another valid ID of the same length: the checksum covers the ID.
  const MessageSpec& fw_emergency = *find_message(can_id::fw_emergency);
  const double fault[] = {1, 7};
  CanFrame moved = encoded(fw_emergency, 1, fault);
  moved.id = can_id::plant_emergency;
  CHECK(codec.accept(moved, out) == RxVerdict::corrupt);

  CHECK(codec.accept(encoded(sync, 6, cycle), out) == RxVerdict::ok);
  CHECK(out == &sync);

  const RxStats& stats = codec.stats();
  CHECK(stats.unknown_id == 1);
  CHECK(stats.wrong_format == 3);
  CHECK(stats.corrupt == 3);
  CHECK(stats.ok == 2);
  CHECK(stats.rejected() == 7);
}

TEST_CASE("hal/codec rejects repeated and stale counters, tolerates a small gap, and resynchronises") {
  CanFrameCodec::Config config;
  config.max_counter_gap = 3;
  config.resync_after = 3;
  CanFrameCodec codec(config);
  const MessageSpec& sync = *find_message(can_id::sync);
  const double cycle[] = {0};
  const MessageSpec* out = nullptr;
  const auto send = [&](std::uint8_t counter) { return codec.accept(encoded(sync, counter, cycle), out); };

  CHECK(send(14) == RxVerdict::ok);        // first frame starts the sequence
  CHECK(send(15) == RxVerdict::ok);
  CHECK(send(15) == RxVerdict::repeated);  // same counter again
  CHECK(send(0) == RxVerdict::ok);         // wraps 15 -> 0
  CHECK(send(3) == RxVerdict::ok);         // two lost frames: gap of 3 tolerated
  CHECK(send(2) == RxVerdict::stale);      // older than the last accepted
  CHECK(send(8) == RxVerdict::stale);      // jump of 5: beyond the tolerated gap
  CHECK(send(4) == RxVerdict::ok);         // the sequence continues
  CHECK(codec.stats().repeated == 1);
  CHECK(codec.stats().stale == 2);

  // A sender that restarted from another counter: after resync_after stale frames it is followed.
  CHECK(send(12) == RxVerdict::stale);
  CHECK(send(13) == RxVerdict::stale);
  CHECK(send(14) == RxVerdict::stale);  // third in a row: becomes the new reference
  CHECK(send(15) == RxVerdict::ok);
  CHECK(codec.stats().stale == 5);

  // Counters are tracked per message: another ID starts its own sequence.
  const MessageSpec& hb = *find_message(can_id::fw_heartbeat);
  const double mode[] = {2};
  CHECK(codec.accept(encoded(hb, 15, mode), out) == RxVerdict::ok);
}

TEST_CASE("hal/codec accepts a new sequence after the sender paused") {
  CanFrameCodec codec;  // fresh_after_ns: 5 ms
  const MessageSpec& valve = *find_message(can_id::cmd_valve);
  const double openings[] = {0.1, 0.2, 0.3, 0.4};
  const MessageSpec* out = nullptr;
  CanFrame frame = encoded(valve, 4, openings);
  frame.timestamp_ns = 1'000'000'000;
  CHECK(codec.accept(frame, out) == RxVerdict::ok);
  frame = encoded(valve, 11, openings);  // would be stale...
  frame.timestamp_ns = 1'002'000'000;    // ...2 ms later
  CHECK(codec.accept(frame, out) == RxVerdict::stale);
  frame.timestamp_ns = 1'020'000'000;    // ...20 ms later: the sender paused, a new sequence
  CHECK(codec.accept(frame, out) == RxVerdict::ok);
}

TEST_CASE("hal/codec SUPERVISOR round trip of every command, and its repeated, stale and corrupt frames rejected") {
  const MessageSpec* supervisor = find_message(can_id::supervisor);
  REQUIRE(supervisor != nullptr);
  CHECK(supervisor->sender == Node::operator_station);
  CanFrameCodec codec;
  const MessageSpec* out = nullptr;
  std::uint8_t counter = 0;
  for (const SupervisorCommand command :
       {SupervisorCommand::none, SupervisorCommand::start, SupervisorCommand::stop, SupervisorCommand::acknowledge}) {
    CAPTURE(to_string(command));
    const double value[] = {static_cast<double>(command)};
    const CanFrame frame = encoded(*supervisor, counter++, value);
    CHECK(frame.len == 2);
    CHECK(frame.fd);
    // The command's raw bits are where the DBC puts them: bits 4..7 of byte 0.
    CHECK((frame.data[0] >> 4) == static_cast<unsigned>(command));
    REQUIRE(codec.accept(frame, out) == RxVerdict::ok);
    REQUIRE(out == supervisor);
    double decoded[1] = {-1};
    decode_message(*out, frame, decoded);
    CHECK(decoded[0] == static_cast<double>(command));
  }
  // A command beyond the DBC's range is sent as its end (counted), never as another command's bits.
  const double beyond[] = {9};
  CanFrame clamped;
  CHECK(encode_message(*supervisor, counter, beyond, clamped).saturated == 1);
  CHECK((clamped.data[0] >> 4) == 3);

  const double stop[] = {static_cast<double>(SupervisorCommand::stop)};
  CHECK(codec.accept(encoded(*supervisor, 3, stop), out) == RxVerdict::repeated);  // the last one again
  CHECK(out == nullptr);
  CHECK(codec.accept(encoded(*supervisor, 12, stop), out) == RxVerdict::stale);
  CanFrame corrupt = encoded(*supervisor, 4, stop);
  corrupt.data[0] ^= 0x10;  // stop (2) turned into acknowledge (3): the checksum catches it
  CHECK(codec.accept(corrupt, out) == RxVerdict::corrupt);
  // The same payload on FW_HEARTBEAT's identifier (also 2 bytes): the checksum covers the ID.
  CanFrame moved = encoded(*supervisor, 4, stop);
  moved.id = can_id::fw_heartbeat;
  CHECK(codec.accept(moved, out) == RxVerdict::corrupt);
  CHECK(codec.accept(encoded(*supervisor, 4, stop), out) == RxVerdict::ok);
  CHECK(codec.stats().ok == 5);
  CHECK(codec.stats().rejected() == 4);
}
