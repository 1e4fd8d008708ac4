#include "hal/link_records.hpp"

#include <array>

namespace exc::hal {
namespace {

// One table lookup per byte (512 bytes of read-only data on the target).
constexpr std::array<std::uint16_t, 256> make_crc_table() {
  std::array<std::uint16_t, 256> table{};
  for (unsigned byte = 0; byte < 256; ++byte) {
    std::uint16_t crc = static_cast<std::uint16_t>(byte << 8);
    for (int bit = 0; bit < 8; ++bit) {
      crc = static_cast<std::uint16_t>((crc & 0x8000) ? (crc << 1) ^ 0x1021 : crc << 1);
    }
    table[byte] = crc;
  }
  return table;
}
constexpr std::array<std::uint16_t, 256> kCrcTable = make_crc_table();

std::uint16_t crc_step(std::uint16_t crc, std::uint8_t byte) {
  return static_cast<std::uint16_t>((crc << 8) ^ kCrcTable[((crc >> 8) ^ byte) & 0xFF]);
}

}  // namespace

std::uint16_t crc16_ccitt_false(const std::uint8_t* bytes, std::size_t n, std::uint16_t crc) {
  for (std::size_t i = 0; i < n; ++i) crc = crc_step(crc, bytes[i]);
  return crc;
}

std::size_t encode_link_record(std::uint8_t type, const std::uint8_t* payload, std::size_t n, std::uint8_t* out,
                               std::size_t capacity) {
  if (n > kLinkRecordMaxPayload || capacity < link_record_bytes(n) || out == nullptr) return 0;
  if (n > 0 && payload == nullptr) return 0;
  out[0] = kLinkRecordStart;
  out[1] = type;
  out[2] = static_cast<std::uint8_t>(n & 0xFF);
  out[3] = static_cast<std::uint8_t>(n >> 8);
  for (std::size_t i = 0; i < n; ++i) out[kLinkRecordHeaderBytes + i] = payload[i];
  const std::uint16_t crc = crc16_ccitt_false(out + 1, 3 + n);
  out[kLinkRecordHeaderBytes + n] = static_cast<std::uint8_t>(crc & 0xFF);
  out[kLinkRecordHeaderBytes + n + 1] = static_cast<std::uint8_t>(crc >> 8);
  return link_record_bytes(n);
}

const char* to_string(LinkDecodeError error) {
  switch (error) {
    case LinkDecodeError::none: return "none";
    case LinkDecodeError::not_a_start_byte: return "not a start byte";
    case LinkDecodeError::length_over_limit: return "length over limit";
    case LinkDecodeError::crc_mismatch: return "CRC mismatch";
  }
  return "unknown";
}

LinkRecordDecoder::LinkRecordDecoder(std::uint8_t* payload_storage, std::size_t capacity)
    : storage_(payload_storage), capacity_(payload_storage == nullptr ? 0 : capacity) {}

void LinkRecordDecoder::reset() {
  state_ = State::start;
  type_ = 0;
  length_ = 0;
  filled_ = 0;
  crc_ = 0xFFFF;
  crc_received_ = 0;
  partial_ = 0;
  record_offset_ = 0;
  offset_ = 0;
  records_ = 0;
  errors_ = 0;
  skipped_ = 0;
  fault_ = LinkDecodeFault{};
}

std::size_t LinkRecordDecoder::partial_record_bytes() const {
  return state_ == State::payload || state_ == State::crc_low || state_ == State::crc_high ? link_record_bytes(length_)
                                                                                            : 0;
}

LinkRecordDecoder::Step LinkRecordDecoder::fail(std::size_t consumed, LinkDecodeError error, std::uint64_t offset,
                                                std::uint32_t found, std::uint32_t limit) {
  fault_.error = error;
  fault_.offset = offset;
  fault_.type = type_;
  fault_.found = found;
  fault_.limit = limit;
  ++errors_;
  partial_ = 0;
  return {Event::error, consumed};
}

LinkRecordDecoder::Step LinkRecordDecoder::feed(const std::uint8_t* bytes, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t b = bytes[i];
    const std::uint64_t at = offset_++;
    switch (state_) {
      case State::start:
      case State::resynchronising:
        if (b == kLinkRecordStart) {
          record_offset_ = at;
          state_ = State::type;
          partial_ = 1;
          crc_ = 0xFFFF;
        } else {
          ++skipped_;
          if (state_ == State::start) {  // the first stray byte of a run names it; the rest are counted
            state_ = State::resynchronising;
            type_ = 0;
            return fail(i + 1, LinkDecodeError::not_a_start_byte, at, b, 0);
          }
        }
        break;
      case State::type:
        type_ = b;
        crc_ = crc_step(crc_, b);
        ++partial_;
        state_ = State::length_low;
        break;
      case State::length_low:
        length_ = b;
        crc_ = crc_step(crc_, b);
        ++partial_;
        state_ = State::length_high;
        break;
      case State::length_high:
        length_ |= static_cast<std::size_t>(b) << 8;
        crc_ = crc_step(crc_, b);
        ++partial_;
        if (length_ > capacity_) {
          // Its payload is not read as records: skipped while looking for the next start byte.
          state_ = State::resynchronising;
          return fail(i + 1, LinkDecodeError::length_over_limit, record_offset_, static_cast<std::uint32_t>(length_),
                      static_cast<std::uint32_t>(capacity_));
        }
        filled_ = 0;
        state_ = length_ > 0 ? State::payload : State::crc_low;
        break;
      case State::payload: {
        // Copy as much of the payload as this input holds in one go.
        std::size_t take = length_ - filled_;
        if (take > n - i) take = n - i;
        for (std::size_t k = 0; k < take; ++k) {
          storage_[filled_ + k] = bytes[i + k];
          crc_ = crc_step(crc_, bytes[i + k]);
        }
        filled_ += take;
        partial_ += take;
        offset_ += take - 1;
        i += take - 1;
        if (filled_ == length_) state_ = State::crc_low;
        break;
      }
      case State::crc_low:
        crc_received_ = b;
        ++partial_;
        state_ = State::crc_high;
        break;
      case State::crc_high:
        crc_received_ = static_cast<std::uint16_t>(crc_received_ | (b << 8));
        state_ = State::start;
        if (crc_received_ != crc_) {
          return fail(i + 1, LinkDecodeError::crc_mismatch, record_offset_, crc_received_, crc_);
        }
        partial_ = 0;
        ++records_;
        return {Event::record, i + 1};
    }
  }
  return {Event::need_more, n};
}

}  // namespace exc::hal
