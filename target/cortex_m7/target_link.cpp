#include "target_link.hpp"

#include <cstring>

#include "semihosting.hpp"

namespace exc::target {

const char* TargetLink::to_string(Status status) {
  switch (status) {
    case Status::ok: return "ok";
    case Status::not_open: return "the link is not open";
    case Status::no_link_arguments: return "no --link-in PATH and --link-out PATH on the command line";
    case Status::open_failed: return "the host could not open a FIFO";
    case Status::outbound_full: return "the outbound buffer is full";
    case Status::payload_too_long: return "a payload over the link's limit";
    case Status::write_failed: return "the host's write to the outbound FIFO failed";
    case Status::read_failed: return "the host's read from the inbound FIFO failed";
    case Status::closed_by_host: return "the host closed the inbound FIFO before the batch ended";
    case Status::decode_error: return "the inbound stream broke the record framing";
    case Status::inbound_full: return "the inbound batch is over the buffer";
  }
  return "unknown";
}

TargetLink::TargetLink() : decoder_(payload_storage_, kMaxPayloadBytes) {}

TargetLink::Status TargetLink::fail(Status status) {
  batch_fill_ = batch_read_ = batch_records_ = 0;
  return status;
}

TargetLink::Status TargetLink::open(const char* inbound_path, const char* outbound_path) {
  // The host opens its read end first and its write end second (harness/emulated_target.cpp), so
  // the target's order, inbound then outbound, cannot deadlock against it.
  inbound_ = semihosting::open(inbound_path, semihosting::OpenMode::read_binary);
  if (inbound_ < 0) {
    host_errno_ = semihosting::errno_of_last_call();
    return Status::open_failed;
  }
  outbound_ = semihosting::open(outbound_path, semihosting::OpenMode::write_binary);
  if (outbound_ < 0) {
    host_errno_ = semihosting::errno_of_last_call();
    semihosting::close(inbound_);
    inbound_ = -1;
    return Status::open_failed;
  }
  return Status::ok;
}

TargetLink::Status TargetLink::open_from_arguments(int argc, char** argv) {
  const char* inbound = nullptr;
  const char* outbound = nullptr;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::strcmp(argv[i], "--link-in") == 0) inbound = argv[i + 1];
    if (std::strcmp(argv[i], "--link-out") == 0) outbound = argv[i + 1];
  }
  if (inbound == nullptr || outbound == nullptr) return Status::no_link_arguments;
  return open(inbound, outbound);
}

TargetLink::Status TargetLink::send(std::uint8_t type, const void* bytes, std::size_t n) {
  if (!is_open()) return Status::not_open;
  if (n > kMaxPayloadBytes) return Status::payload_too_long;
  const std::size_t written = hal::encode_link_record(type, static_cast<const std::uint8_t*>(bytes), n,
                                                      outbound_buffer_ + outbound_fill_, kBufferBytes - outbound_fill_);
  if (written == 0) return Status::outbound_full;
  outbound_fill_ += written;
  return Status::ok;
}

TargetLink::Status TargetLink::flush() {
  if (!is_open()) return Status::not_open;
  std::size_t done = 0;
  while (done < outbound_fill_) {
    const std::size_t left = semihosting::write(outbound_, outbound_buffer_ + done, outbound_fill_ - done);
    const std::size_t wrote = (outbound_fill_ - done) - left;
    if (left > outbound_fill_ - done || wrote == 0) {
      host_errno_ = semihosting::errno_of_last_call();
      outbound_fill_ = 0;
      return Status::write_failed;
    }
    done += wrote;
  }
  outbound_fill_ = 0;
  return Status::ok;
}

bool TargetLink::store(const hal::LinkRecordView& record) {
  const std::size_t need = 3 + record.payload_bytes;
  if (need > kBufferBytes - batch_fill_) return false;
  std::uint8_t* out = batch_ + batch_fill_;
  out[0] = record.type;
  out[1] = static_cast<std::uint8_t>(record.payload_bytes & 0xFF);
  out[2] = static_cast<std::uint8_t>(record.payload_bytes >> 8);
  if (record.payload_bytes > 0) std::memcpy(out + 3, record.payload, record.payload_bytes);
  batch_fill_ += need;
  ++batch_records_;
  last_type_ = record.type;
  last_bytes_ = record.payload_bytes;
  return true;
}

TargetLink::Status TargetLink::receive_until(std::uint8_t end_type) {
  batch_fill_ = batch_read_ = batch_records_ = 0;
  if (!is_open()) return Status::not_open;
  for (;;) {
    // Decode what is there; stop at the end record.
    while (raw_begin_ < raw_end_) {
      const auto step = decoder_.feed(raw_ + raw_begin_, raw_end_ - raw_begin_);
      raw_begin_ += step.consumed;
      if (step.event == hal::LinkRecordDecoder::Event::error) return fail(Status::decode_error);
      if (step.event == hal::LinkRecordDecoder::Event::record) {
        const hal::LinkRecordView record = decoder_.record();
        if (!store(record)) return fail(Status::inbound_full);
        if (record.type == end_type) return Status::ok;
      }
    }
    // Then wait for more: the read blocks until the host has written something.
    raw_begin_ = raw_end_ = 0;
    const long got = semihosting::read(inbound_, raw_, kReadChunkBytes);
    if (got < 0) {
      host_errno_ = semihosting::errno_of_last_call();
      return fail(Status::read_failed);
    }
    if (got == 0) return fail(Status::closed_by_host);
    raw_end_ = static_cast<std::size_t>(got);
  }
}

bool TargetLink::next(hal::LinkRecordView& record) {
  if (batch_read_ >= batch_fill_) return false;
  const std::uint8_t* in = batch_ + batch_read_;
  record.type = in[0];
  record.payload_bytes = static_cast<std::size_t>(in[1]) | (static_cast<std::size_t>(in[2]) << 8);
  record.payload = in + 3;
  batch_read_ += 3 + record.payload_bytes;
  return true;
}

}  // namespace exc::target
