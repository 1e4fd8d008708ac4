#include "telemetry/telemetry_publisher.hpp"

#include <algorithm>
#include <vector>

#include "exlcm/telemetry_stats_t.hpp"

namespace exc::telemetry {

static_assert(sizeof(exlcm::telemetry_stats_t::dropped_full) / sizeof(std::int64_t) == channel_count,
              "telemetry_stats_t.dropped_full has one entry per channel");

namespace {

// Every exlcm type starts with the 8-byte fingerprint and then int64_t utime, big-endian (LCM's
// wire format), so the thread can read the run clock from the bytes without knowing the type.
std::int64_t utime_of(const std::uint8_t* bytes, std::uint32_t size) {
  if (size < 16) return 0;
  std::uint64_t value = 0;
  for (int i = 8; i < 16; ++i) value = value << 8 | bytes[i];
  return static_cast<std::int64_t>(value);
}

bool starts_with(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

}  // namespace

const char* to_string(OverflowPolicy policy) {
  return policy == OverflowPolicy::block ? "block" : "drop_newest";
}

TelemetryPublisher::TelemetryPublisher(TelemetryConfig config)
    : TelemetrySink(config.per_cycle_every),
      config_(std::move(config)),
      ring_storage_(std::make_unique<Ring>()),
      ring_(*ring_storage_),
      message_(std::make_unique<Ring::Message>()) {
  for (std::size_t i = 0; i < channel_count; ++i) {
    channel_names_[i] =
        std::string(channel_base_name(static_cast<Channel>(i))) + config_.channel_suffix;
  }
}

TelemetryPublisher::~TelemetryPublisher() { stop(); }

bool TelemetryPublisher::start(std::string* error) {
  if (thread_.joinable()) return true;
  output_ = config_.shared_output;
  if (!output_) output_ = LcmOutput::open(config_.lcm_url, error);
  if (!output_) return false;
  stop_requested_.store(false);
  running_.store(true);
  thread_ = std::thread([this] { run(); });
  return true;
}

void TelemetryPublisher::stop() {
  if (!thread_.joinable()) return;
  stop_requested_.store(true);
  thread_.join();
  running_.store(false);
  output_.reset();
}

bool TelemetryPublisher::make_room() {
  if (config_.overflow != OverflowPolicy::block || !running_.load(std::memory_order_relaxed)) return false;
  blocked_.fetch_add(1, std::memory_order_relaxed);
  // The thread drains at least once per wake period; sleeping a fraction of it keeps the wait short
  // without spinning on the core the thread needs.
  const auto nap = std::max(std::chrono::microseconds(20), config_.wake_period / 20);
  while (ring_.full()) {
    if (!running_.load(std::memory_order_relaxed)) return false;
    std::this_thread::sleep_for(nap);
  }
  return true;
}

void TelemetryPublisher::run() {
  auto next_stats = std::chrono::steady_clock::now() + config_.stats_period;
  const bool paced = starts_with(output_->url(), "udpm");
  const std::size_t burst = paced ? std::max<std::size_t>(1, config_.udpm_burst) : Ring::slot_count;
  while (!stop_requested_.load(std::memory_order_relaxed)) {
    drain(burst);
    const auto now = std::chrono::steady_clock::now();
    if (now >= next_stats) {
      publish_stats();
      next_stats = now + config_.stats_period;
    }
    std::this_thread::sleep_for(config_.wake_period);
  }
  // The loop has stopped publishing (stop() is called after the last publish): take everything,
  // still in bursts.
  while (drain(burst) == burst) std::this_thread::sleep_for(config_.wake_period);
  publish_stats();
}

std::size_t TelemetryPublisher::drain(std::size_t limit) {
  Ring::Message& message = *message_;
  std::size_t taken = 0;
  while (taken < limit && ring_.pop(message)) {
    ++taken;
    if (message.tag >= channel_count) continue;
    last_utime_ = utime_of(message.bytes, message.size);
    if (output_->publish(channel_names_[message.tag].c_str(), message.bytes, message.size)) {
      published_.fetch_add(1, std::memory_order_relaxed);
    } else {
      publish_errors_.fetch_add(1, std::memory_order_relaxed);
    }
  }
  return taken;
}

void TelemetryPublisher::publish_stats() {
  const TelemetryCounters c = counters();
  exlcm::telemetry_stats_t stats{};
  stats.utime = last_utime_;
  stats.seq = stats_sequence_++;
  stats.enqueued = static_cast<std::int64_t>(c.enqueued);
  stats.published = static_cast<std::int64_t>(c.published);
  stats.dropped_overflow = static_cast<std::int64_t>(c.dropped_overflow);
  stats.dropped_too_large = static_cast<std::int64_t>(c.dropped_too_large);
  stats.publish_errors = static_cast<std::int64_t>(c.publish_errors);
  for (std::size_t i = 0; i < channel_count; ++i) stats.dropped_full[i] = static_cast<std::int64_t>(c.dropped_full[i]);
  stats.blocked = static_cast<std::int64_t>(c.blocked);
  stats.ring_high_water = static_cast<std::int64_t>(c.ring_high_water);
  stats.ring_capacity = static_cast<std::int64_t>(c.ring_capacity);
  stats.overflow_policy = static_cast<std::int8_t>(config_.overflow);
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(stats.getEncodedSize()));
  const int size = stats.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  if (size < 0) return;
  const auto index = static_cast<std::size_t>(Channel::telemetry_stats);
  if (!output_->publish(channel_names_[index].c_str(), bytes.data(), static_cast<std::size_t>(size))) {
    publish_errors_.fetch_add(1, std::memory_order_relaxed);
  }
}

TelemetryCounters TelemetryPublisher::counters() const {
  const RingCounters r = ring_.counters();
  TelemetryCounters c;
  c.enqueued = r.pushed;
  c.dropped_overflow = r.dropped_overflow;
  c.dropped_too_large = r.dropped_too_large;
  c.published = published_.load(std::memory_order_relaxed);
  c.publish_errors = publish_errors_.load(std::memory_order_relaxed);
  for (std::size_t i = 0; i < channel_count; ++i) {
    c.dropped_full[i] = dropped_full_[i].load(std::memory_order_relaxed);
    c.dropped_full_total += c.dropped_full[i];
  }
  c.blocked = blocked_.load(std::memory_order_relaxed);
  c.ring_high_water = ring_.high_water();
  c.ring_capacity = Ring::slot_count;
  return c;
}

}  // namespace exc::telemetry
