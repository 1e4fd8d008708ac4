#pragma once
// The record framing of the link between the firmware on an emulated target and the host that runs
// its plant (docs/target.md, "The link"). Both ends compile this file: the host's harness and the
// bare-metal Cortex-M7 image. No OS call, no heap, no exception: the caller owns every buffer.
//
// A record on the wire:
//
//   0xA5 | type | length, 2 bytes little-endian | payload (length bytes) | CRC-16, 2 bytes little-endian
//
// The CRC is CRC-16/CCITT-FALSE (polynomial 0x1021, initial 0xFFFF, no reflection, no final xor) over
// type, length and payload: it finds every 1- to 3-bit error and every burst up to 16 bits, so a
// stream that lost its place (a byte dropped or repeated, a reader starting mid-record) is named as an
// error instead of read as another record. Types are small integers whose meaning the link's users
// agree on; the framing gives none of them a meaning.
#include <cstddef>
#include <cstdint>

namespace exc::hal {

inline constexpr std::uint8_t kLinkRecordStart = 0xA5;
inline constexpr std::size_t kLinkRecordHeaderBytes = 4;   // start, type, length
inline constexpr std::size_t kLinkRecordTrailerBytes = 2;  // CRC
inline constexpr std::size_t kLinkRecordOverheadBytes = kLinkRecordHeaderBytes + kLinkRecordTrailerBytes;
inline constexpr std::size_t kLinkRecordMaxPayload = 0xFFFF;  // the length field's range

// Bytes on the wire of a record with this payload.
constexpr std::size_t link_record_bytes(std::size_t payload_bytes) { return payload_bytes + kLinkRecordOverheadBytes; }

// CRC-16/CCITT-FALSE of bytes[0, n), continuing from crc (check value of "123456789": 0x29B1).
std::uint16_t crc16_ccitt_false(const std::uint8_t* bytes, std::size_t n, std::uint16_t crc = 0xFFFF);

// Encodes one record into out[0, capacity). Returns the bytes written (link_record_bytes(n)), or 0
// with nothing written when the record does not fit or n is over kLinkRecordMaxPayload. payload may
// be null when n is 0.
std::size_t encode_link_record(std::uint8_t type, const std::uint8_t* payload, std::size_t n, std::uint8_t* out,
                               std::size_t capacity);

enum class LinkDecodeError : std::uint8_t {
  none,
  not_a_start_byte,   // a byte other than 0xA5 where a record begins: garbage, or a stream out of step
  length_over_limit,  // a record longer than the decoder's payload storage
  crc_mismatch,       // the CRC does not match the type, length and payload received
};
// "not a start byte", "length over limit", "CRC mismatch" ("none" for none).
const char* to_string(LinkDecodeError error);

// What an error was found in, for its message: where in the stream and what was read.
struct LinkDecodeFault {
  LinkDecodeError error = LinkDecodeError::none;
  std::uint64_t offset = 0;  // stream offset of the stray byte, or of the bad record's start byte
  std::uint8_t type = 0;     // the bad record's type (length_over_limit, crc_mismatch)
  std::uint32_t found = 0;   // the stray byte, the length, or the CRC received
  std::uint32_t limit = 0;   // length_over_limit: the longest payload accepted; crc_mismatch: the CRC computed
};

// A decoded record; the payload lives in the decoder's storage until the next feed().
struct LinkRecordView {
  std::uint8_t type = 0;
  const std::uint8_t* payload = nullptr;
  std::size_t payload_bytes = 0;
};

// Incremental decoder: feed it bytes as they come, in pieces of any size, and it hands out each
// complete record or names each error. After an error it looks for the next start byte; the bytes it
// passes over on the way (a run of garbage, the rest of an oversized record) are counted in
// skipped_bytes() and reported once, by the error that began the run. It never reads or writes past
// the storage it was given.
class LinkRecordDecoder {
 public:
  enum class Event : std::uint8_t { need_more, record, error };
  struct Step {
    Event event = Event::need_more;
    std::size_t consumed = 0;  // bytes of the input taken (all of them when need_more)
  };

  // payload_storage[0, capacity): where a record's payload is assembled; capacity is the longest
  // payload accepted (at most kLinkRecordMaxPayload counts).
  LinkRecordDecoder(std::uint8_t* payload_storage, std::size_t capacity);

  // Consumes bytes up to and including the first one that completes a record or reveals an error,
  // or all of them. Call again with the rest after a record or an error.
  Step feed(const std::uint8_t* bytes, std::size_t n);

  // The record completed by the last feed() (Event::record).
  LinkRecordView record() const { return {type_, storage_, length_}; }
  // The error revealed by the last feed() (Event::error).
  const LinkDecodeFault& fault() const { return fault_; }

  // Whether part of a record has been read (the stream ending now would cut it).
  bool mid_record() const { return state_ != State::start && state_ != State::resynchronising; }
  // Bytes of that record read so far, and its full size on the wire once its length is known (0 before).
  std::size_t partial_bytes() const { return partial_; }
  std::size_t partial_record_bytes() const;

  std::uint64_t bytes_consumed() const { return offset_; }
  std::uint64_t records() const { return records_; }
  std::uint64_t errors() const { return errors_; }
  std::uint64_t skipped_bytes() const { return skipped_; }

  // Forgets any partial record and the counts (the storage stays).
  void reset();

 private:
  enum class State : std::uint8_t { start, resynchronising, type, length_low, length_high, payload, crc_low, crc_high };
  Step fail(std::size_t consumed, LinkDecodeError error, std::uint64_t offset, std::uint32_t found,
             std::uint32_t limit);

  std::uint8_t* storage_;
  std::size_t capacity_;
  State state_ = State::start;
  std::uint8_t type_ = 0;
  std::size_t length_ = 0;
  std::size_t filled_ = 0;
  std::uint16_t crc_ = 0xFFFF;  // over the record's type, length and payload so far
  std::uint16_t crc_received_ = 0;
  std::size_t partial_ = 0;
  std::uint64_t record_offset_ = 0;
  std::uint64_t offset_ = 0;
  std::uint64_t records_ = 0;
  std::uint64_t errors_ = 0;
  std::uint64_t skipped_ = 0;
  LinkDecodeFault fault_;
};

}  // namespace exc::hal
