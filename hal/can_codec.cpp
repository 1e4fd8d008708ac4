#include "hal/can_codec.hpp"

#include <cmath>
#include <cstring>

namespace exc::hal {
namespace {

// Table for CRC-8 polynomial 0x1D, built at compile time from the bitwise definition; row k (k >= 1)
// is row 0 applied k + 1 times: a byte's contribution to the register k bytes later (the CRC is
// linear, so eight bytes fold into one step of eight look-ups, "slicing by 8").
struct Crc8Table {
  std::uint8_t entry[256];
  std::uint8_t slice[8][256];
  constexpr Crc8Table() : entry{}, slice{} {
    for (int i = 0; i < 256; ++i) {
      std::uint8_t crc = static_cast<std::uint8_t>(i);
      for (int bit = 0; bit < 8; ++bit) {
        crc = static_cast<std::uint8_t>((crc & 0x80) ? ((crc << 1) ^ 0x1D) : (crc << 1));
      }
      entry[i] = crc;
      slice[0][i] = crc;
    }
    for (int k = 1; k < 8; ++k)
      for (int i = 0; i < 256; ++i) slice[k][i] = entry[slice[k - 1][i]];
  }
};
constexpr Crc8Table kCrc8Table;

// The register after `length` more bytes: eight at a time through the slices, then one by one. The
// same value as the byte loop, which the tests hold to the bitwise definition and the check value.
std::uint8_t crc8_update(std::uint8_t crc, const std::uint8_t* bytes, std::size_t length) {
  const auto& t = kCrc8Table.slice;
  std::size_t i = 0;
  for (; i + 8 <= length; i += 8) {
    crc = static_cast<std::uint8_t>(t[7][crc ^ bytes[i]] ^ t[6][bytes[i + 1]] ^ t[5][bytes[i + 2]] ^
                                    t[4][bytes[i + 3]] ^ t[3][bytes[i + 4]] ^ t[2][bytes[i + 5]] ^
                                    t[1][bytes[i + 6]] ^ t[0][bytes[i + 7]]);
  }
  for (; i < length; ++i) crc = kCrc8Table.entry[crc ^ bytes[i]];
  return crc;
}

std::uint64_t mask_of(unsigned length) { return length >= 64 ? ~0ULL : ((1ULL << length) - 1); }

// Eight payload bytes as one little-endian word (the frame's Intel bit order: bit k of the word is
// bit k % 8 of byte k / 8), on any host.
std::uint64_t load_word(const std::uint8_t* bytes) {
  std::uint64_t word;
  std::memcpy(&word, bytes, sizeof word);
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
  word = __builtin_bswap64(word);
#endif
  return word;
}

void store_word(std::uint8_t* bytes, std::uint64_t word) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
  word = __builtin_bswap64(word);
#endif
  std::memcpy(bytes, &word, sizeof word);
}

// A field lies in one word: it ends within the 64 bits from its first byte, and that word within the
// payload. Every signal of the protocol does; the byte loops below take the rest.
bool in_one_word(unsigned start, unsigned length) {
  return start % 8 + length <= 64 && start / 8 + 8 <= kCanFdMaxLength;
}

// std::llround(x), half away from zero, without the library call where |x| < 2^62 (every signal's
// raw range): x less its truncation is exact there, so the comparison with 0.5 decides as llround does.
std::int64_t round_half_away(double x) {
  if (!(std::abs(x) < 0x1p62)) return std::llround(x);
  auto raw = static_cast<std::int64_t>(x);
  const double fraction = x - static_cast<double>(raw);
  if (fraction >= 0.5) ++raw;
  else if (fraction <= -0.5) --raw;
  return raw;
}

}  // namespace

std::uint8_t crc8_sae_j1850(const std::uint8_t* bytes, std::size_t length) {
  return static_cast<std::uint8_t>(crc8_update(0xFF, bytes, length) ^ 0xFF);
}

std::uint8_t frame_checksum(std::uint32_t id, const std::uint8_t* payload, std::size_t payload_bytes_before_crc) {
  std::uint8_t crc = 0xFF;
  crc = kCrc8Table.entry[crc ^ static_cast<std::uint8_t>(id & 0xFF)];
  crc = kCrc8Table.entry[crc ^ static_cast<std::uint8_t>((id >> 8) & 0xFF)];
  return static_cast<std::uint8_t>(crc8_update(crc, payload, payload_bytes_before_crc) ^ 0xFF);
}

std::uint64_t read_raw_bits(const CanFrame& frame, unsigned start, unsigned length) {
  if (length == 0 || length > 64 || start + length > 8u * kCanFdMaxLength) return 0;
  if (in_one_word(start, length)) return (load_word(frame.data + start / 8) >> (start % 8)) & mask_of(length);
  std::uint64_t raw = 0;
  unsigned got = 0;
  while (got < length) {
    const unsigned bit = start + got;
    const unsigned offset = bit % 8;
    const unsigned take = (8 - offset) < (length - got) ? (8 - offset) : (length - got);
    const std::uint64_t chunk = (frame.data[bit / 8] >> offset) & mask_of(take);
    raw |= chunk << got;
    got += take;
  }
  return raw;
}

void write_raw_bits(CanFrame& frame, unsigned start, unsigned length, std::uint64_t raw) {
  if (length == 0 || length > 64 || start + length > 8u * kCanFdMaxLength) return;
  if (in_one_word(start, length)) {
    std::uint8_t* bytes = frame.data + start / 8;
    const std::uint64_t field = mask_of(length) << (start % 8);
    store_word(bytes, (load_word(bytes) & ~field) | ((raw << (start % 8)) & field));
    return;
  }
  unsigned put = 0;
  while (put < length) {
    const unsigned bit = start + put;
    const unsigned offset = bit % 8;
    const unsigned take = (8 - offset) < (length - put) ? (8 - offset) : (length - put);
    const auto field = static_cast<std::uint8_t>(mask_of(take) << offset);
    const auto value = static_cast<std::uint8_t>(((raw >> put) & mask_of(take)) << offset);
    std::uint8_t& byte = frame.data[bit / 8];
    byte = static_cast<std::uint8_t>((byte & ~field) | value);
    put += take;
  }
}

namespace {

// encode_signal's work, inlined into encode_message's loop: the value's raw field (saturated, the
// non-finite replaced), written as write_raw_bits writes it. One definition for both callers, so a
// single signal and a whole message encode alike.
[[gnu::always_inline]] inline void encode_into(CanFrame& frame, const SignalSpec& signal, double value,
                                               EncodeReport& report) {
  if (!std::isfinite(value)) {
    ++report.non_finite;
    value = signal.min > 0 ? signal.min : (signal.max < 0 ? signal.max : 0.0);
  }
  if (value < signal.min) {
    value = signal.min;
    ++report.saturated;
  } else if (value > signal.max) {
    value = signal.max;
    ++report.saturated;
  }
  std::int64_t raw = round_half_away((value - signal.offset) / signal.factor);
  // Rounding at a range end must not step outside what the field can hold.
  if (raw < signal.raw_min) raw = signal.raw_min;
  if (raw > signal.raw_max) raw = signal.raw_max;
  const unsigned start = signal.start;
  if (signal.one_word) {
    // write_raw_bits's one-word path, without the call and its repeated checks.
    std::uint8_t* bytes = frame.data + start / 8;
    const std::uint64_t field = signal.raw_mask << (start % 8);
    store_word(bytes, (load_word(bytes) & ~field) | ((static_cast<std::uint64_t>(raw) << (start % 8)) & field));
  } else {
    write_raw_bits(frame, start, signal.length, static_cast<std::uint64_t>(raw));
  }
}

[[gnu::always_inline]] inline double decode_from(const CanFrame& frame, const SignalSpec& signal) {
  const unsigned start = signal.start, length = signal.length;
  const std::uint64_t raw = signal.one_word ? (load_word(frame.data + start / 8) >> (start % 8)) & signal.raw_mask
                                            : read_raw_bits(frame, start, length);
  std::int64_t value = static_cast<std::int64_t>(raw);
  if (signal.is_signed && (raw >> (length - 1)) != 0) {
    value = static_cast<std::int64_t>(raw | ~signal.raw_mask);  // two's complement sign extension
  }
  return static_cast<double>(value) * signal.factor + signal.offset;
}

}  // namespace

EncodeReport encode_signal(CanFrame& frame, const SignalSpec& signal, double value) {
  EncodeReport report;
  encode_into(frame, signal, value, report);
  return report;
}

double decode_signal(const CanFrame& frame, const SignalSpec& signal) { return decode_from(frame, signal); }

EncodeReport encode_message(const MessageSpec& message, std::uint8_t counter, const double* values, CanFrame& out) {
  out.id = message.id;
  out.len = message.length;
  out.fd = message.fd;
  out.brs = message.brs;
  for (auto& byte : out.data) byte = 0;
  out.timestamp_ns = 0;
  EncodeReport report;
  out.data[0] = static_cast<std::uint8_t>(counter & 0x0F);  // the Counter signal, bits 0..3 of the zeroed payload
  const std::size_t n = message.data_signal_count();
  for (std::size_t i = 0; i < n; ++i) encode_into(out, message.data_signal(i), values[i], report);
  out.data[message.length - 1] = frame_checksum(out.id, out.data, message.length - 1u);
  return report;
}

void decode_message(const MessageSpec& message, const CanFrame& frame, double* values) {
  const std::size_t n = message.data_signal_count();
  for (std::size_t i = 0; i < n; ++i) values[i] = decode_from(frame, message.data_signal(i));
}

std::uint8_t frame_counter(const CanFrame& frame) { return frame.data[0] & 0x0F; }

const char* to_string(RxVerdict verdict) {
  switch (verdict) {
    case RxVerdict::ok: return "ok";
    case RxVerdict::unknown_id: return "unknown_id";
    case RxVerdict::wrong_format: return "wrong_format";
    case RxVerdict::corrupt: return "corrupt";
    case RxVerdict::repeated: return "repeated";
    case RxVerdict::stale: return "stale";
  }
  return "?";
}

void RxStats::record(RxVerdict verdict) {
  switch (verdict) {
    case RxVerdict::ok: ++ok; break;
    case RxVerdict::unknown_id: ++unknown_id; break;
    case RxVerdict::wrong_format: ++wrong_format; break;
    case RxVerdict::corrupt: ++corrupt; break;
    case RxVerdict::repeated: ++repeated; break;
    case RxVerdict::stale: ++stale; break;
  }
}

CanFrameCodec::CanFrameCodec() : CanFrameCodec(Config{}) {}
CanFrameCodec::CanFrameCodec(Config config) : config_(config) {}

void CanFrameCodec::restart_sequences() { sequences_ = {}; }

RxVerdict CanFrameCodec::accept(const CanFrame& frame, const MessageSpec*& message) {
  message = nullptr;
  RxVerdict verdict = RxVerdict::ok;
  const int index = message_index(frame.id);
  if (index < 0) {
    verdict = RxVerdict::unknown_id;
  } else {
    const MessageSpec& spec = protocol_messages()[static_cast<std::size_t>(index)];
    if (frame.len != spec.length || frame.fd != spec.fd) {
      verdict = RxVerdict::wrong_format;
    } else if (frame.data[spec.length - 1] != frame_checksum(frame.id, frame.data, spec.length - 1u)) {
      verdict = RxVerdict::corrupt;
    } else {
      Sequence& seq = sequences_[static_cast<std::size_t>(index)];
      const std::uint8_t counter = frame_counter(frame);
      const bool paused = seq.started && frame.timestamp_ns != 0 && seq.last_ns != 0 &&
                          frame.timestamp_ns - seq.last_ns > config_.fresh_after_ns;
      if (seq.started && !paused) {
        const unsigned delta = (counter - seq.last) & 0x0Fu;
        if (delta == 0) {
          verdict = RxVerdict::repeated;
        } else if (delta > config_.max_counter_gap) {
          verdict = RxVerdict::stale;
        }
      }
      if (verdict == RxVerdict::stale) {
        // A sender that restarted (or a long loss) would otherwise be locked out for good.
        if (++seq.stale_run >= config_.resync_after) {
          seq.last = counter;
          seq.stale_run = 0;
        }
      } else if (verdict == RxVerdict::ok) {
        seq.started = true;
        seq.last = counter;
        seq.stale_run = 0;
        seq.last_ns = frame.timestamp_ns;
        message = &spec;
      }
    }
  }
  stats_.record(verdict);
  return verdict;
}

}  // namespace exc::hal
