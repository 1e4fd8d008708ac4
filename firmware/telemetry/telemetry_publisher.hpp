#pragma once
// Telemetry without breaking the 1 kHz loop (realtime_tools' RealtimePublisher idea, LCM flavour).
// The loop calls publish(channel, msg): it stamps the per-channel sequence number, encodes the
// message with the lcm-gen encoder into a preallocated buffer and pushes the bytes into a lock-free
// ring. It never calls LCM (whose C++ publish(channel, &msg) allocates on every call), never locks,
// never blocks and never allocates. A telemetry thread drains the ring and hands the raw bytes to
// lcm_publish, and publishes the path's own counters on EXC_TELEMETRY_STATS about once a second.
#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "telemetry/lcm_output.hpp"
#include "telemetry/spsc_ring.hpp"
#include "telemetry/telemetry_channels.hpp"
#include "telemetry/telemetry_sink.hpp"

namespace exc::telemetry {

// What publish() does when the ring is full.
enum class OverflowPolicy : std::uint8_t {
  // Wait for the telemetry thread to make room: every message of every cycle is recorded. For runs
  // that are not paced by the wall clock (lockstep, in-process, benchmarks), where no deadline exists.
  block,
  // Refuse the new message and count it per channel: the loop never waits. For --realtime runs.
  drop_newest,
};
const char* to_string(OverflowPolicy policy);

struct TelemetryConfig {
  // LCM provider, opened by start() unless `shared_output` is given.
  std::string lcm_url = "file://run.lcm?mode=w";
  // Use this already open provider instead (several publishers into one log).
  std::shared_ptr<LcmOutput> shared_output;
  // Appended to every channel name: "/pid" gives EXC_STATE/pid.
  std::string channel_suffix;
  // How often the telemetry thread publishes telemetry_stats_t.
  std::chrono::milliseconds stats_period{1000};
  OverflowPolicy overflow = OverflowPolicy::block;
  // Record the per-cycle channels (per_cycle(): EXC_STATE, EXC_COMMAND, EXC_CONTROLLER) every Nth
  // message only, from the first (for a long run's log: 10 gives a tenth of their volume). The others
  // are recorded whole. A message left out is not sent and not counted as sent or dropped; seq counts
  // the recorded ones, so a gap in seq still means a lost message, and utime says which cycle it is.
  std::uint32_t per_cycle_every = 1;
  // The telemetry thread wakes this often and drains the ring. To a file:// provider it hands
  // everything (no receiver to outrun). To a udpm:// provider at most `udpm_burst` messages per wake:
  // an LCM subscriber (lcm-logger, lcm-spy) queues at most 30 messages per subscription by default
  // and drops the rest, so a backlog sent in one go would be lost at the receiver. The ring holds the
  // backlog instead (and, blocking, slows the loop to the receivers' pace); waking once per ms rather
  // than per message also spares the receivers a wake-up per message.
  std::chrono::microseconds wake_period{1000};
  std::size_t udpm_burst = 4;
};

struct TelemetryCounters {
  std::uint64_t enqueued = 0;           // messages pushed into the ring by the loop
  std::uint64_t published = 0;          // messages handed to LCM successfully
  std::uint64_t dropped_overflow = 0;   // oldest messages overwritten (never with the publisher's policies)
  std::array<std::uint64_t, channel_count> dropped_full{};  // per channel: refused, ring full (drop_newest)
  std::uint64_t dropped_full_total = 0;
  std::uint64_t blocked = 0;            // publish() calls that waited for room (block)
  std::size_t ring_high_water = 0;      // most messages waiting at once
  std::size_t ring_capacity = 0;
  std::uint64_t dropped_too_large = 0;  // messages whose encoding did not fit a ring slot
  std::uint64_t publish_errors = 0;     // lcm_publish calls that failed
};

class TelemetryPublisher final : public TelemetrySink {
 public:
  // 1 KiB slots hold every exlcm type (timing_t, the largest, is 593 bytes); 1024 slots buffer
  // about a quarter of a second of the loop's ~4 messages per cycle.
  using Ring = SpscRing<1024, TelemetrySink::kMaxMessageBytes>;

  explicit TelemetryPublisher(TelemetryConfig config);
  ~TelemetryPublisher();  // stop()
  TelemetryPublisher(const TelemetryPublisher&) = delete;
  TelemetryPublisher& operator=(const TelemetryPublisher&) = delete;

  // Opens the provider (unless shared) and starts the telemetry thread. On failure returns false
  // and sets `error`; publish() still works (messages stay in the ring, the oldest dropped).
  bool start(std::string* error);
  // Drains what is left in the ring, publishes the final counters, joins the thread and releases
  // the provider (a log file not shared with another publisher is closed).
  void stop();

  TelemetryCounters counters() const;
  // The full LCM channel name, suffix included.
  const std::string& channel_name(Channel channel) const {
    return channel_names_[static_cast<std::size_t>(channel)];
  }

 private:
  // The loop's encoded message into the ring: a full ring waits (block: not for real-time loops) or
  // refuses the message and counts it (drop_newest).
  bool put(std::size_t channel, const std::uint8_t* bytes, std::size_t size) override {
    if (ring_.full() && !make_room()) {
      dropped_full_[channel].fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    return ring_.push(static_cast<std::uint16_t>(channel), bytes, size);
  }
  void note_too_large() override { ring_.note_too_large(); }
  void run();
  // Ring full: with `block` and a running thread, waits until there is room (true); else false.
  bool make_room();
  // Publishes up to `limit` messages; returns how many it took from the ring.
  std::size_t drain(std::size_t limit);
  void publish_stats();

  TelemetryConfig config_;
  std::array<std::string, channel_count> channel_names_;
  std::unique_ptr<Ring> ring_storage_;  // ~1 MiB: on the heap, allocated once at construction
  Ring& ring_;
  // Telemetry-thread state.
  std::shared_ptr<LcmOutput> output_;
  std::unique_ptr<Ring::Message> message_;
  std::thread thread_;
  std::atomic<bool> stop_requested_{false};
  std::atomic<bool> running_{false};
  std::array<std::atomic<std::uint64_t>, channel_count> dropped_full_{};
  std::atomic<std::uint64_t> blocked_{0};
  std::atomic<std::uint64_t> published_{0};
  std::atomic<std::uint64_t> publish_errors_{0};
  std::int64_t last_utime_ = 0;
  std::int64_t stats_sequence_ = 0;
};

}  // namespace exc::telemetry
