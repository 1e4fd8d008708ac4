#pragma once
// What the firmware on an emulated target and the host that runs its plant say to each other, one
// record of hal/link_records at a time (docs/target.md, "Processor in the loop"). Both ends compile
// this file; the payloads are little-endian with fixed-width fields, whatever either end's layout.
//
// A run:
//   host   settings_chunk ... settings_chunk (empty)         the settings blob, in pieces of at most 4000 bytes
//   target ready | refused (text)                           the blob checked at boot
//   per cycle k:
//   host   begin                                            the harness's cycle k begins
//   target frame ... awaiting_inputs                        begin_cycle: SYNC (and heartbeat, stop)
//   host   frame ... inputs_done                            the plant's answer and the operator's frames
//   target frame ... telemetry ... cycle_done (status)      end_cycle: commands, messages, the cycle's state
//   host   run_end begin                                    the run is over (no cycle begins)
//   target telemetry ... summary                            the last counters, the run's outcome; exit 0
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "hal/can_frame.hpp"

namespace exc::app {

enum class PilRecord : std::uint8_t {
  // host to target
  settings_chunk = 0x01,  // an empty one ends the blob
  frame_in = 0x03,
  inputs_done = 0x04,
  run_end = 0x05,
  begin = 0x06,
  // target to host
  ready = 0x10,
  refused = 0x11,
  frame_out = 0x12,
  awaiting_inputs = 0x13,
  cycle_done = 0x14,
  telemetry = 0x15,
  summary = 0x16,
};

// Little-endian field writer and reader over a caller's buffer: a write past the end or a read past
// the payload sets ok() false instead of touching memory outside it.
class RecordWriter {
 public:
  RecordWriter(std::uint8_t* out, std::size_t capacity) : out_(out), capacity_(capacity) {}
  void u8(std::uint8_t v) { bytes(&v, 1); }
  void u16(std::uint16_t v) { le(v, 2); }
  void u32(std::uint32_t v) { le(v, 4); }
  void u64(std::uint64_t v) { le(v, 8); }
  void i64(std::int64_t v) { le(static_cast<std::uint64_t>(v), 8); }
  void f64(double v) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &v, 8);
    le(bits, 8);
  }
  void bytes(const void* p, std::size_t n) {
    if (!ok_ || n > capacity_ - size_) {
      ok_ = false;
      return;
    }
    std::memcpy(out_ + size_, p, n);
    size_ += n;
  }
  bool ok() const { return ok_; }
  std::size_t size() const { return size_; }

 private:
  void le(std::uint64_t v, int n) {
    std::uint8_t b[8];
    for (int i = 0; i < n; ++i) b[i] = static_cast<std::uint8_t>(v >> (8 * i));
    bytes(b, static_cast<std::size_t>(n));
  }
  std::uint8_t* out_;
  std::size_t capacity_, size_ = 0;
  bool ok_ = true;
};

class RecordReader {
 public:
  RecordReader(const std::uint8_t* in, std::size_t n) : in_(in), n_(n) {}
  std::uint8_t u8() { return static_cast<std::uint8_t>(le(1)); }
  std::uint16_t u16() { return static_cast<std::uint16_t>(le(2)); }
  std::uint32_t u32() { return static_cast<std::uint32_t>(le(4)); }
  std::uint64_t u64() { return le(8); }
  std::int64_t i64() { return static_cast<std::int64_t>(le(8)); }
  double f64() {
    const std::uint64_t bits = le(8);
    double v = 0;
    std::memcpy(&v, &bits, 8);
    return v;
  }
  void bytes(void* p, std::size_t n) {
    if (!ok_ || n > n_ - at_) {
      ok_ = false;
      std::memset(p, 0, n);
      return;
    }
    std::memcpy(p, in_ + at_, n);
    at_ += n;
  }
  bool ok() const { return ok_; }
  bool done() const { return ok_ && at_ == n_; }  // read whole, nothing left over

 private:
  std::uint64_t le(int n) {
    std::uint8_t b[8] = {};
    bytes(b, static_cast<std::size_t>(n));
    std::uint64_t v = 0;
    for (int i = n - 1; i >= 0; --i) v = v << 8 | b[i];
    return v;
  }
  const std::uint8_t* in_;
  std::size_t n_, at_ = 0;
  bool ok_ = true;
};

// A CAN frame with its bus times: frame_in and frame_out.
inline constexpr std::size_t kFrameRecordMaxBytes = 8 + 8 + 4 + 1 + 1 + hal::kCanFdMaxLength;
inline std::size_t encode_frame(const hal::CanFrame& f, std::uint8_t* out, std::size_t capacity) {
  if (f.len > hal::kCanFdMaxLength) return 0;
  RecordWriter w(out, capacity);
  w.i64(f.timestamp_ns);
  w.i64(f.wire_ns);
  w.u32(f.id);
  w.u8(static_cast<std::uint8_t>((f.fd ? 1 : 0) | (f.brs ? 2 : 0)));
  w.u8(f.len);
  w.bytes(f.data, f.len);
  return w.ok() ? w.size() : 0;
}
inline bool decode_frame(const std::uint8_t* in, std::size_t n, hal::CanFrame& f) {
  RecordReader r(in, n);
  f = hal::CanFrame{};
  f.timestamp_ns = r.i64();
  f.wire_ns = r.i64();
  f.id = r.u32();
  const std::uint8_t flags = r.u8();
  f.fd = (flags & 1) != 0;
  f.brs = (flags & 2) != 0;
  f.len = r.u8();
  if (f.len > hal::kCanFdMaxLength) return false;
  r.bytes(f.data, f.len);
  return r.done();
}

// The loop stages whose instructions a cycle_done record carries, in this order: begin_cycle, then
// end_cycle's read, estimate, law, actuation, monitors, write and telemetry, and the whole cycle
// (begin_cycle and end_cycle, the link's transfers left out).
inline constexpr int kTargetStages = 9;
inline constexpr const char* kTargetStageNames[kTargetStages] = {"begin_cycle", "read", "estimate", "law", "actuation",
                                                                 "monitors", "write", "telemetry", "cycle"};

// What the harness reads of the firmware after each cycle (cycle_done).
struct CycleStatus {
  std::uint64_t cycle = 0;
  std::uint8_t mode = 0;  // safety::Mode
  bool tracking = false;
  double task_time = -1;
  double q_desired[4] = {0, 0, 0, 0};
  double theta_hat[6] = {0, 0, 0, 0, 0, 0};
  std::uint64_t safe_stops = 0;
  double fault_detected_time = -1;
  std::uint16_t last_fault = 0;
  std::uint32_t instructions[kTargetStages] = {};  // this cycle's, per stage
};

inline std::size_t encode_status(const CycleStatus& s, std::uint8_t* out, std::size_t capacity) {
  RecordWriter w(out, capacity);
  w.u64(s.cycle);
  w.u8(s.mode);
  w.u8(s.tracking ? 1 : 0);
  w.f64(s.task_time);
  for (double v : s.q_desired) w.f64(v);
  for (double v : s.theta_hat) w.f64(v);
  w.u64(s.safe_stops);
  w.f64(s.fault_detected_time);
  w.u16(s.last_fault);
  for (std::uint32_t v : s.instructions) w.u32(v);
  return w.ok() ? w.size() : 0;
}
inline bool decode_status(const std::uint8_t* in, std::size_t n, CycleStatus& s) {
  RecordReader r(in, n);
  s.cycle = r.u64();
  s.mode = r.u8();
  s.tracking = r.u8() != 0;
  s.task_time = r.f64();
  for (double& v : s.q_desired) v = r.f64();
  for (double& v : s.theta_hat) v = r.f64();
  s.safe_stops = r.u64();
  s.fault_detected_time = r.f64();
  s.last_fault = r.u16();
  for (std::uint32_t& v : s.instructions) v = r.u32();
  return r.done();
}

// The run's outcome as the firmware saw it (summary), and the image's own figures.
struct RunSummaryRecord {
  bool emergency_sent = false;
  std::int64_t tracking_samples = 0;
  double measured_rms[4] = {0, 0, 0, 0}, measured_max[4] = {0, 0, 0, 0};
  std::uint64_t pump_limited_cycles = 0;
  bool trajectory_finished = false;
  double finish_time = 0;
  std::uint64_t rx_rejected = 0;
  std::uint8_t mode = 0;
  char last_fault_text[160] = "";
  std::uint64_t heap_calls_after_start_up = 0;
  std::uint64_t stack_bytes_used = 0;  // high-water mark of the painted stack
  std::uint64_t heap_bytes_used = 0;   // the heap's break: what start-up took of it
  std::uint64_t start_up_instructions = 0;
};

inline std::size_t encode_summary(const RunSummaryRecord& s, std::uint8_t* out, std::size_t capacity) {
  RecordWriter w(out, capacity);
  w.u8(s.emergency_sent ? 1 : 0);
  w.i64(s.tracking_samples);
  for (double v : s.measured_rms) w.f64(v);
  for (double v : s.measured_max) w.f64(v);
  w.u64(s.pump_limited_cycles);
  w.u8(s.trajectory_finished ? 1 : 0);
  w.f64(s.finish_time);
  w.u64(s.rx_rejected);
  w.u8(s.mode);
  w.bytes(s.last_fault_text, sizeof s.last_fault_text);
  w.u64(s.heap_calls_after_start_up);
  w.u64(s.stack_bytes_used);
  w.u64(s.heap_bytes_used);
  w.u64(s.start_up_instructions);
  return w.ok() ? w.size() : 0;
}
inline bool decode_summary(const std::uint8_t* in, std::size_t n, RunSummaryRecord& s) {
  RecordReader r(in, n);
  s.emergency_sent = r.u8() != 0;
  s.tracking_samples = r.i64();
  for (double& v : s.measured_rms) v = r.f64();
  for (double& v : s.measured_max) v = r.f64();
  s.pump_limited_cycles = r.u64();
  s.trajectory_finished = r.u8() != 0;
  s.finish_time = r.f64();
  s.rx_rejected = r.u64();
  s.mode = r.u8();
  r.bytes(s.last_fault_text, sizeof s.last_fault_text);
  s.last_fault_text[sizeof s.last_fault_text - 1] = 0;
  s.heap_calls_after_start_up = r.u64();
  s.stack_bytes_used = r.u64();
  s.heap_bytes_used = r.u64();
  s.start_up_instructions = r.u64();
  return r.done();
}

}  // namespace exc::app
