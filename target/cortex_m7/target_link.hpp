#pragma once
// The target's end of the link to the host (docs/target.md, "The link"): records (hal/link_records)
// over two host FIFOs opened through semihosting, one per direction. Lockstep: the target sends its
// cycle's records into a RAM buffer, flushes them in one write at the cycle's edge, then blocks in
// receive_until() until the host's batch has arrived whole; the firmware's timed stages touch only
// RAM. Under QEMU's -icount the blocking read costs no emulated instructions, however long the host
// takes. All buffers are members: no heap, before or after start-up. Not for interrupt handlers.
#include <cstddef>
#include <cstdint>

#include "hal/link_records.hpp"

namespace exc::target {

class TargetLink {
 public:
  static constexpr std::size_t kBufferBytes = 8 * 1024;       // each way: a cycle's records, encoded (a settings piece, 4 KiB, inbound)
  static constexpr std::size_t kMaxPayloadBytes = 4 * 1024;   // the longest record received
  static constexpr std::size_t kReadChunkBytes = 4 * 1024;    // raw bytes taken from the FIFO per read

  enum class Status : std::uint8_t {
    ok,
    not_open,          // send/flush/receive before open() succeeded
    no_link_arguments, // open_from_arguments: no --link-in PATH and --link-out PATH on the command line
    open_failed,       // the host could not open a FIFO (host_errno() says why)
    outbound_full,     // send: the record does not fit what is left of the outbound buffer
    payload_too_long,  // send: over kMaxPayloadBytes, which the host would refuse as well
    write_failed,      // flush: the host's write failed or stopped (host_errno())
    read_failed,       // receive_until: the host's read failed (host_errno())
    closed_by_host,    // receive_until: the host closed its end (end of file) before the batch ended
    decode_error,      // receive_until: the inbound stream broke the framing (fault() says how)
    inbound_full,      // receive_until: the batch does not fit the inbound buffer
  };
  static const char* to_string(Status status);

  TargetLink();
  TargetLink(const TargetLink&) = delete;
  TargetLink& operator=(const TargetLink&) = delete;

  // Opens the FIFOs: inbound (host to target) for reading, outbound (target to host) for writing.
  // Each open blocks until the host has opened the other end.
  Status open(const char* inbound_path, const char* outbound_path);
  // The same with the paths the host put on the command line: --link-in PATH --link-out PATH.
  Status open_from_arguments(int argc, char** argv);
  bool is_open() const { return inbound_ >= 0 && outbound_ >= 0; }

  // Appends a record to the outbound buffer (nothing is written to the host yet).
  Status send(std::uint8_t type, const void* bytes, std::size_t n);
  // Writes the outbound buffer to the host in one write, and empties it.
  Status flush();
  std::size_t outbound_bytes() const { return outbound_fill_; }

  // Blocks until a record of end_type has arrived, keeping every record up to and including it; then
  // next() hands them out in arrival order. Bytes that came after the end record stay for the next
  // call. On an error the batch is empty.
  Status receive_until(std::uint8_t end_type);
  // The batch's next record (valid until the next receive_until); false when none is left.
  bool next(hal::LinkRecordView& record);
  std::size_t batch_records() const { return batch_records_; }

  // Details of the last error: the host's errno (open, read, write) and the framing fault.
  int host_errno() const { return host_errno_; }
  const hal::LinkDecodeFault& fault() const { return decoder_.fault(); }
  // The last record received whole (type and size), for an error's message; type -1 before any.
  int last_record_type() const { return last_type_; }
  std::size_t last_record_bytes() const { return last_bytes_; }
  std::uint64_t records_received() const { return decoder_.records(); }

 private:
  Status fail(Status status);
  bool store(const hal::LinkRecordView& record);

  int inbound_ = -1;
  int outbound_ = -1;
  int host_errno_ = 0;
  int last_type_ = -1;
  std::size_t last_bytes_ = 0;

  std::uint8_t outbound_buffer_[kBufferBytes];
  std::size_t outbound_fill_ = 0;

  // Raw bytes read from the FIFO, [raw_begin_, raw_end_) not yet decoded.
  std::uint8_t raw_[kReadChunkBytes];
  std::size_t raw_begin_ = 0;
  std::size_t raw_end_ = 0;
  std::uint8_t payload_storage_[kMaxPayloadBytes];
  hal::LinkRecordDecoder decoder_;
  // The batch: per record its type, its length (2 bytes, little-endian) and its payload, back to back.
  std::uint8_t batch_[kBufferBytes];
  std::size_t batch_fill_ = 0;
  std::size_t batch_read_ = 0;
  std::size_t batch_records_ = 0;
};

}  // namespace exc::target
