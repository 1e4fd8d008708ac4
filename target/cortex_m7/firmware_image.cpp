// The firmware's image for the emulated Cortex-M7 (docs/target.md, "Processor in the loop"): the
// same FirmwareNode as on a host, its bus and telemetry on the link to the host that runs the plant
// (app/pil_records.hpp says the records). Start-up: the settings blob arrives in pieces, is checked
// (a bad one is refused, named, and the image exits without running a cycle), the model is built and
// the node made; then the heap is closed (every allocator call after it is counted and reported) and
// the cycles run in lockstep with the host until it ends the run.
//
//   firmware_image --link-in PATH --link-out PATH       (the host's harness starts it under QEMU)
//
// Exit status: 0 run ended by the host; 2 bad arguments or link; 3 settings refused; 4 link broken.
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "app/firmware_node.hpp"
#include "app/pil_records.hpp"
#include "app/settings_blob.hpp"
#include "hal/can_ports.hpp"
#include "heap_calls.hpp"
#include "instruction_clock.hpp"
#include "link_can_bus.hpp"
#include "link_telemetry.hpp"
#include "model/model.hpp"
#include "stack_usage.hpp"
#include "target_link.hpp"

namespace {

using exc::app::PilRecord;
using exc::target::InstructionClock;
using exc::target::TargetLink;

constexpr int kBadLink = 2, kRefused = 3, kLinkBroken = 4;
constexpr std::size_t kMaxBlobBytes = 4u << 20;

std::uint8_t type_of(PilRecord r) { return static_cast<std::uint8_t>(r); }

[[noreturn]] void broken(const TargetLink& link, TargetLink::Status status, const char* while_doing) {
  std::fprintf(stderr, "firmware_image: link %s while %s (host errno %d, last record type %d)\n", TargetLink::to_string(status),
               while_doing, link.host_errno(), link.last_record_type());
  std::exit(kLinkBroken);
}

void flush(TargetLink& link) {
  const TargetLink::Status s = link.flush();
  if (s != TargetLink::Status::ok) broken(link, s, "flushing");
}

// A record into the outbound buffer; a full one goes to the host first (the host reads records, not
// writes: a batch may take several).
void send(TargetLink& link, PilRecord type, const void* bytes, std::size_t n) {
  TargetLink::Status s = link.send(type_of(type), bytes, n);
  if (s == TargetLink::Status::outbound_full) {
    flush(link);
    s = link.send(type_of(type), bytes, n);
  }
  if (s != TargetLink::Status::ok) broken(link, s, "sending");
}

// The frames the firmware sent and the messages it published, onto the link.
void forward_outputs(TargetLink& link, exc::target::LinkCanBus& bus, exc::target::LinkTelemetry& telemetry) {
  std::uint8_t frame[exc::app::kFrameRecordMaxBytes];
  for (std::size_t i = 0; i < bus.sent_count(); ++i) send(link, PilRecord::frame_out, frame, exc::app::encode_frame(bus.sent()[i], frame, sizeof frame));
  bus.clear_sent();
  const std::uint8_t* p = telemetry.staged();
  const std::uint8_t* const end = p + telemetry.staged_bytes();
  while (p < end) {
    const std::size_t size = static_cast<std::size_t>(p[0]) | static_cast<std::size_t>(p[1]) << 8;
    send(link, PilRecord::telemetry, p + 2, size + 1);  // [channel, message]
    p += size + 3;
  }
  telemetry.clear();
}

std::uint32_t instructions(const exc::diagnostics::PerfCounter& c) { return static_cast<std::uint32_t>(c.last_us() * 1e3 + 0.5); }

}  // namespace

int main(int argc, char** argv) {
  const std::uint64_t boot = InstructionClock::instructions();
  static TargetLink link;  // its buffers are large: not on the stack
  if (const TargetLink::Status s = link.open_from_arguments(argc, argv); s != TargetLink::Status::ok) {
    std::fprintf(stderr, "firmware_image: the link did not open: %s (host errno %d)\n", TargetLink::to_string(s), link.host_errno());
    return kBadLink;
  }

  // The settings, piece by piece (each its own batch: the blob is larger than the link's buffer), up
  // to an empty piece.
  std::vector<std::uint8_t> blob;
  for (bool more = true; more;) {
    if (const TargetLink::Status s = link.receive_until(type_of(PilRecord::settings_chunk)); s != TargetLink::Status::ok)
      broken(link, s, "receiving the settings");
    for (exc::hal::LinkRecordView r; link.next(r);) {
      if (r.type != type_of(PilRecord::settings_chunk)) continue;
      if (r.payload_bytes == 0) more = false;
      // Sized once from the blob's own length field (bytes 8-11), not grown by doubling: the heap's
      // break is part of the image's RAM, and the decoder checks that length anyway.
      if (blob.empty() && r.payload_bytes >= 12) {
        const std::size_t total = static_cast<std::size_t>(r.payload[8]) | static_cast<std::size_t>(r.payload[9]) << 8 |
                                  static_cast<std::size_t>(r.payload[10]) << 16 | static_cast<std::size_t>(r.payload[11]) << 24;
        if (total <= kMaxBlobBytes) blob.reserve(total);
      }
      if (blob.size() + r.payload_bytes > kMaxBlobBytes) {
        const char why[] = "settings blob over the image's limit (4 MiB)";
        send(link, PilRecord::refused, why, sizeof why - 1);
        flush(link);
        return kRefused;
      }
      blob.insert(blob.end(), r.payload, r.payload + r.payload_bytes);
    }
  }
  auto settings = std::make_unique<exc::app::FirmwareImageSettings>();
  std::string error;
  if (!exc::app::decode_settings_blob(blob.data(), blob.size(), *settings, error)) {
    std::fprintf(stderr, "firmware_image: settings refused: %s\n", error.c_str());
    send(link, PilRecord::refused, error.data(), error.size());
    flush(link);
    return kRefused;
  }
  std::vector<std::uint8_t>().swap(blob);

  const auto model = std::make_unique<exc::Model>(exc::build_model(settings->machine));
  static exc::target::LinkCanBus bus;
  static exc::target::LinkTelemetry telemetry;
  exc::hal::FirmwareCanPort port(bus);
  std::unique_ptr<exc::app::FirmwareNode> node;
  try {
    node = std::make_unique<exc::app::FirmwareNode>(*model, settings->task, settings->node, port, &telemetry);
  } catch (const std::exception& e) {
    send(link, PilRecord::refused, e.what(), std::strlen(e.what()));
    flush(link);
    return kRefused;
  }
  // newlib's printf of a double allocates its conversion buffers on first use: taken now, at
  // start-up, so that a fault's text later costs no allocation.
  char warm[64];
  std::snprintf(warm, sizeof warm, "%.3f %.4f %.17g", 1.5, -0.25, 1e-300);
  send(link, PilRecord::ready, nullptr, 0);
  flush(link);
  const std::uint64_t start_up = InstructionClock::instructions() - boot;
  exc::target::mark_start_up_over();

  const exc::diagnostics::LoopCounters& c = node->counters();
  exc::app::CycleStatus status;
  std::uint8_t payload[256];
  for (;;) {
    // The host begins each cycle, or ends the run (run_end, then begin).
    if (const TargetLink::Status s = link.receive_until(type_of(PilRecord::begin)); s != TargetLink::Status::ok)
      broken(link, s, "waiting for the cycle's begin");
    bool ended = false;
    for (exc::hal::LinkRecordView r; link.next(r);) ended = ended || r.type == type_of(PilRecord::run_end);
    if (ended) break;
    const std::uint64_t begin_at = InstructionClock::instructions();
    node->begin_cycle();
    const std::uint64_t begun_at = InstructionClock::instructions();
    forward_outputs(link, bus, telemetry);
    send(link, PilRecord::awaiting_inputs, nullptr, 0);
    flush(link);

    // The plant's answer (or the run's end), into the mailboxes.
    if (const TargetLink::Status s = link.receive_until(type_of(PilRecord::inputs_done)); s != TargetLink::Status::ok)
      broken(link, s, "waiting for the cycle's inputs");
    for (exc::hal::LinkRecordView r; link.next(r);) {
      exc::hal::CanFrame f;
      if (r.type == type_of(PilRecord::frame_in) && exc::app::decode_frame(r.payload, r.payload_bytes, f) && !bus.deliver(f))
        std::fprintf(stderr, "firmware_image: inbound mailboxes full, a frame dropped\n");
    }

    const std::uint64_t end_at = InstructionClock::instructions();
    node->end_cycle();
    const std::uint64_t ended_at = InstructionClock::instructions();

    status.cycle = node->cycle();
    status.mode = static_cast<std::uint8_t>(node->mode());
    status.tracking = node->tracking();
    status.task_time = node->task_time();
    for (int j = 0; j < 4; ++j) status.q_desired[j] = node->q_desired()[j];
    for (int i = 0; i < 6; ++i) status.theta_hat[i] = node->last_output().theta_hat[i];
    status.safe_stops = node->supervisor().safe_stops();
    status.fault_detected_time = node->supervisor().fault_detected_time();
    status.last_fault = static_cast<std::uint16_t>(node->supervisor().last_fault());
    const bool commanded = node->mode() == exc::safety::Mode::hold || node->mode() == exc::safety::Mode::track;
    status.instructions[0] = static_cast<std::uint32_t>(begun_at - begin_at);
    status.instructions[1] = instructions(c.read);
    status.instructions[2] = commanded ? instructions(c.estimate) : 0;
    status.instructions[3] = commanded ? instructions(c.law) : 0;
    status.instructions[4] = commanded ? instructions(c.actuation) : 0;
    status.instructions[5] = commanded ? instructions(c.monitors) : 0;
    status.instructions[6] = instructions(c.write);
    status.instructions[7] = instructions(c.telemetry);
    status.instructions[8] = static_cast<std::uint32_t>((begun_at - begin_at) + (ended_at - end_at));
    forward_outputs(link, bus, telemetry);
    send(link, PilRecord::cycle_done, payload, exc::app::encode_status(status, payload, sizeof payload));
    flush(link);
  }

  // The run's end: the last counters and the outcome.
  node->publish_counters();
  forward_outputs(link, bus, telemetry);
  exc::app::RunSummaryRecord summary;
  const exc::app::TrackingMetrics& m = node->measured_tracking();
  summary.emergency_sent = node->supervisor().emergency_sent();
  summary.tracking_samples = m.samples();
  for (int j = 0; j < 4; ++j) {
    summary.measured_rms[j] = m.rms(j);
    summary.measured_max[j] = m.max_abs(j);
  }
  summary.pump_limited_cycles = node->supervisor().pump_limited_cycles();
  summary.trajectory_finished = node->trajectory_finished();
  summary.finish_time = node->finish_time();
  summary.rx_rejected = port.rx_stats().rejected();
  summary.mode = static_cast<std::uint8_t>(node->mode());
  std::snprintf(summary.last_fault_text, sizeof summary.last_fault_text, "%s", node->supervisor().last_fault_text());
  summary.heap_calls_after_start_up = exc::target::heap_calls_after_start_up().total();
  summary.stack_bytes_used = exc::target::stack_high_water_bytes();
  summary.heap_bytes_used = exc::target::heap_break_bytes();
  summary.start_up_instructions = start_up;
  std::uint8_t out[512];
  send(link, PilRecord::summary, out, exc::app::encode_summary(summary, out, sizeof out));
  flush(link);
  return 0;
}
