// The link's record framing (hal/link_records): the CRC's check value, round trips fed whole and byte
// by byte, every truncation, every flipped bit, garbage between records, oversized lengths and the
// encoder's refusals.
#include <doctest/doctest.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "hal/link_records.hpp"

using namespace exc::hal;

namespace {

using Bytes = std::vector<std::uint8_t>;

struct Record {
  std::uint8_t type = 0;
  Bytes payload;
  bool operator==(const Record& o) const { return type == o.type && payload == o.payload; }
};

Bytes encoded(const Record& r) {
  Bytes out(link_record_bytes(r.payload.size()));
  const std::size_t n = encode_link_record(r.type, r.payload.data(), r.payload.size(), out.data(), out.size());
  REQUIRE(n == out.size());
  return out;
}

Record random_record(std::mt19937& rng, std::size_t size) {
  Record r;
  r.type = static_cast<std::uint8_t>(rng());
  r.payload.resize(size);
  for (auto& b : r.payload) b = static_cast<std::uint8_t>(rng());
  return r;
}

// What a decoder makes of a stream fed in pieces of `piece` bytes: its records and its errors.
struct Decoded {
  std::vector<Record> records;
  std::vector<LinkDecodeFault> faults;
  bool mid_record = false;
};

Decoded decode(const Bytes& stream, std::size_t capacity, std::size_t piece) {
  Bytes storage(capacity);
  LinkRecordDecoder decoder(storage.data(), storage.size());
  Decoded d;
  for (std::size_t at = 0; at < stream.size();) {
    const std::size_t n = std::min(piece, stream.size() - at);
    std::size_t used = 0;
    while (used < n) {
      const auto step = decoder.feed(stream.data() + at + used, n - used);
      CHECK(step.consumed <= n - used);
      used += step.consumed;
      if (step.event == LinkRecordDecoder::Event::record) {
        const LinkRecordView v = decoder.record();
        d.records.push_back({v.type, Bytes(v.payload, v.payload + v.payload_bytes)});
      } else if (step.event == LinkRecordDecoder::Event::error) {
        d.faults.push_back(decoder.fault());
      }
    }
    at += n;
  }
  d.mid_record = decoder.mid_record();
  CHECK(decoder.bytes_consumed() == stream.size());
  return d;
}

}  // namespace

TEST_CASE("hal/link records: CRC-16/CCITT-FALSE of \"123456789\" is 0x29B1, the header and trailer take 6 bytes") {
  const std::string check = "123456789";
  CHECK(crc16_ccitt_false(reinterpret_cast<const std::uint8_t*>(check.data()), check.size()) == 0x29B1);
  const Bytes empty = encoded({0x07, {}});
  REQUIRE(empty.size() == 6);
  CHECK(empty[0] == kLinkRecordStart);
  CHECK(empty[1] == 0x07);
  CHECK(empty[2] == 0);
  CHECK(empty[3] == 0);
  const Bytes one = encoded({0x07, Bytes(0x123, 0x5C)});
  CHECK(one[2] == 0x23);  // length little-endian
  CHECK(one[3] == 0x01);
  const std::uint16_t crc = crc16_ccitt_false(one.data() + 1, 3 + 0x123);
  CHECK(one[4 + 0x123] == (crc & 0xFF));
  CHECK(one[5 + 0x123] == (crc >> 8));
}

TEST_CASE("hal/link records: a stream of records of every size and type round-trips, fed whole, byte by byte and in odd pieces") {
  std::mt19937 rng(11);
  std::vector<Record> records;
  for (std::size_t size : {0, 1, 2, 63, 64, 65, 255, 256, 1000, 4096}) records.push_back(random_record(rng, size));
  for (int type = 0; type < 256; ++type) records.push_back({static_cast<std::uint8_t>(type), Bytes(type % 7, 0xA5)});
  Bytes stream;
  for (const auto& r : records) {
    const Bytes e = encoded(r);
    stream.insert(stream.end(), e.begin(), e.end());
  }
  for (std::size_t piece : {stream.size(), std::size_t{1}, std::size_t{7}, std::size_t{4099}}) {
    CAPTURE(piece);
    const Decoded d = decode(stream, 4096, piece);
    CHECK(d.faults.empty());
    CHECK_FALSE(d.mid_record);
    REQUIRE(d.records.size() == records.size());
    for (std::size_t i = 0; i < records.size(); ++i) CHECK(d.records[i] == records[i]);
  }
}

TEST_CASE("hal/link records: every truncation of a record leaves the decoder mid-record with no record and no error, and the rest completes it") {
  std::mt19937 rng(12);
  const Record r = random_record(rng, 40);
  const Bytes e = encoded(r);
  for (std::size_t cut = 0; cut < e.size(); ++cut) {
    CAPTURE(cut);
    Bytes storage(64);
    LinkRecordDecoder decoder(storage.data(), storage.size());
    const auto first = decoder.feed(e.data(), cut);
    CHECK(first.event == LinkRecordDecoder::Event::need_more);
    CHECK(first.consumed == cut);
    CHECK(decoder.mid_record() == (cut > 0));
    CHECK(decoder.partial_bytes() == cut);
    CHECK(decoder.partial_record_bytes() == (cut >= 4 ? e.size() : 0));
    const auto rest = decoder.feed(e.data() + cut, e.size() - cut);
    REQUIRE(rest.event == LinkRecordDecoder::Event::record);
    CHECK(rest.consumed == e.size() - cut);
    CHECK(decoder.record().type == r.type);
    CHECK(Bytes(decoder.record().payload, decoder.record().payload + decoder.record().payload_bytes) == r.payload);
  }
}

TEST_CASE("hal/link records: a flipped bit anywhere in a record is an error, never a record read with other contents") {
  std::mt19937 rng(13);
  const Record bad = random_record(rng, 24);
  const Record next = random_record(rng, 10);
  const Bytes e = encoded(bad);
  const Bytes f = encoded(next);
  unsigned crc_errors = 0, start_errors = 0, length_errors = 0, swallowed = 0;
  for (std::size_t bit = 0; bit < 8 * e.size(); ++bit) {
    CAPTURE(bit);
    Bytes stream = e;
    stream[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    stream.insert(stream.end(), f.begin(), f.end());
    const Decoded d = decode(stream, 64, stream.size());
    // The damaged record never comes out: an error names it, or (a length made longer) the decoder
    // still waits for its end. Whatever record does come out is the good one that followed it.
    CHECK((!d.faults.empty() || d.mid_record));
    for (const auto& r : d.records) CHECK(r == next);
    for (const auto& fault : d.faults) {
      crc_errors += fault.error == LinkDecodeError::crc_mismatch;
      start_errors += fault.error == LinkDecodeError::not_a_start_byte;
      length_errors += fault.error == LinkDecodeError::length_over_limit;
    }
    if (d.records.empty()) swallowed += 1;
  }
  // Every kind shows up: the start byte (8 bits), the length's high byte (over the 64-byte limit),
  // and the CRC for the rest.
  CHECK(start_errors >= 8);
  CHECK(length_errors >= 1);
  CHECK(crc_errors >= 8 * (e.size() - 4));
  MESSAGE("flipped bits: " << crc_errors << " CRC mismatches, " << start_errors << " stray start bytes, "
                           << length_errors << " lengths over the limit, " << swallowed
                           << " cases where the next record was swallowed by a longer length");
}

TEST_CASE("hal/link records: garbage between records is one error per run, naming its first byte and offset, and the records around it decode") {
  std::mt19937 rng(14);
  const Record a = random_record(rng, 5), b = random_record(rng, 300), c = random_record(rng, 0);
  const Bytes ea = encoded(a), eb = encoded(b), ec = encoded(c);
  const Bytes garbage1 = {0x00, 0x11, 0x22, 0x33};
  const Bytes garbage2 = {0xFF};
  Bytes stream = garbage1;
  stream.insert(stream.end(), ea.begin(), ea.end());
  stream.insert(stream.end(), garbage2.begin(), garbage2.end());
  stream.insert(stream.end(), eb.begin(), eb.end());
  stream.insert(stream.end(), ec.begin(), ec.end());
  for (std::size_t piece : {stream.size(), std::size_t{1}, std::size_t{3}}) {
    CAPTURE(piece);
    const Decoded d = decode(stream, 512, piece);
    REQUIRE(d.records.size() == 3);
    CHECK(d.records[0] == a);
    CHECK(d.records[1] == b);
    CHECK(d.records[2] == c);
    REQUIRE(d.faults.size() == 2);
    CHECK(d.faults[0].error == LinkDecodeError::not_a_start_byte);
    CHECK(d.faults[0].offset == 0);
    CHECK(d.faults[0].found == 0x00);
    CHECK(d.faults[1].error == LinkDecodeError::not_a_start_byte);
    CHECK(d.faults[1].offset == garbage1.size() + ea.size());
    CHECK(d.faults[1].found == 0xFF);
  }
  Bytes storage(512);
  LinkRecordDecoder decoder(storage.data(), storage.size());
  std::size_t used = 0;
  while (used < stream.size()) used += decoder.feed(stream.data() + used, stream.size() - used).consumed;
  CHECK(decoder.skipped_bytes() == garbage1.size() + garbage2.size());
  CHECK(decoder.records() == 3);
  CHECK(decoder.errors() == 2);
  CHECK(std::string(to_string(LinkDecodeError::not_a_start_byte)) == "not a start byte");
}

TEST_CASE("hal/link records: a length over the decoder's limit is an error naming the length, the limit and the type, and the next record decodes") {
  std::mt19937 rng(15);
  const Record big = random_record(rng, 100);
  const Record small = random_record(rng, 20);
  Bytes stream = encoded(big);
  const Bytes es = encoded(small);
  stream.insert(stream.end(), es.begin(), es.end());
  // The big record's payload holds no start byte, so nothing in it is taken for a record.
  for (std::size_t i = 4; i < 4 + big.payload.size(); ++i) {
    if (stream[i] == kLinkRecordStart) stream[i] = 0;
  }
  const Decoded d = decode(stream, 99, stream.size());
  REQUIRE(d.faults.size() == 1);
  CHECK(d.faults[0].error == LinkDecodeError::length_over_limit);
  CHECK(d.faults[0].offset == 0);
  CHECK(d.faults[0].found == 100);
  CHECK(d.faults[0].limit == 99);
  CHECK(d.faults[0].type == big.type);
  REQUIRE(d.records.size() == 1);
  CHECK(d.records[0] == small);
  // A decoder with no storage takes empty records only.
  const Decoded none = decode(encoded({3, {}}), 0, 6);
  CHECK(none.faults.empty());
  REQUIRE(none.records.size() == 1);
  CHECK(none.records[0].type == 3);
}

TEST_CASE("hal/link records: the encoder refuses a record that does not fit the caller's buffer or a payload over 65535 bytes, writing nothing") {
  const Bytes payload(kLinkRecordMaxPayload + 1, 0x42);
  Bytes out(link_record_bytes(payload.size()), 0xEE);
  CHECK(encode_link_record(1, payload.data(), payload.size(), out.data(), out.size()) == 0);
  CHECK(encode_link_record(1, payload.data(), 10, out.data(), link_record_bytes(10) - 1) == 0);
  CHECK(encode_link_record(1, nullptr, 10, out.data(), out.size()) == 0);
  for (auto b : out) REQUIRE(b == 0xEE);
  CHECK(encode_link_record(1, payload.data(), kLinkRecordMaxPayload, out.data(), out.size()) ==
        link_record_bytes(kLinkRecordMaxPayload));
  CHECK(encode_link_record(1, nullptr, 0, out.data(), 6) == 6);
}
