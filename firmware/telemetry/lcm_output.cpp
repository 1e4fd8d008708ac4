#include "telemetry/lcm_output.hpp"

#include <lcm/lcm.h>
#include <sys/time.h>

#include <cstring>

namespace exc::telemetry {
namespace {

constexpr std::size_t kLogBuffer = 256 * 1024;  // bytes written to the file at once
constexpr std::uint32_t kEventMagic = 0xEDA1DA01u;

// The path of a log-writing URL (file://PATH?mode=w), or "" for anything else.
std::string log_path_of(const std::string& url) {
  const std::string scheme = "file://", query = "?mode=w";
  if (url.rfind(scheme, 0) != 0 || url.size() <= scheme.size() + query.size()) return "";
  if (url.compare(url.size() - query.size(), query.size(), query) != 0) return "";
  return url.substr(scheme.size(), url.size() - scheme.size() - query.size());
}

std::uint8_t* put_big_endian(std::uint8_t* out, std::uint64_t value, int bytes) {
  for (int i = bytes - 1; i >= 0; --i) *out++ = static_cast<std::uint8_t>(value >> (8 * i));
  return out;
}

std::int64_t wall_clock_us() {  // LCM's event time: gettimeofday in microseconds
  timeval tv{};
  gettimeofday(&tv, nullptr);
  return static_cast<std::int64_t>(tv.tv_sec) * 1000000 + tv.tv_usec;
}

}  // namespace

std::shared_ptr<LcmOutput> LcmOutput::open(const std::string& url, std::string* error) {
  const std::string path = log_path_of(url);
  lcm_t* lcm = nullptr;
  std::FILE* log = nullptr;
  if (!path.empty()) log = std::fopen(path.c_str(), "wb");
  else lcm = lcm_create(url.c_str());
  if (lcm == nullptr && log == nullptr) {
    if (error != nullptr) {
      *error = "telemetry: LCM cannot open provider '" + url +
               "' (expected udpm://GROUP:PORT?ttl=N, e.g. udpm://239.255.76.67:7667?ttl=0, or "
               "file://PATH?mode=w; for udpm the loopback may need multicast: "
               "ip link set lo multicast on; ip route add 239.255.0.0/16 dev lo)";
    }
    return nullptr;
  }
  return std::shared_ptr<LcmOutput>(new LcmOutput(lcm, log, url));
}

LcmOutput::LcmOutput(lcm_t* lcm, std::FILE* log, std::string url) : lcm_(lcm), log_(log), url_(std::move(url)) {
  if (log_ != nullptr) {
    std::setvbuf(log_, nullptr, _IONBF, 0);  // the buffer below is the only one
    buffer_.resize(kLogBuffer);
  }
}

LcmOutput::~LcmOutput() {
  if (log_ != nullptr) {
    flush_log();
    std::fclose(log_);
  }
  if (lcm_ != nullptr) lcm_destroy(lcm_);
}

bool LcmOutput::publish(const char* channel, const void* data, std::size_t size) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (log_ != nullptr) return write_event(channel, data, size);
  return lcm_publish(lcm_, channel, data, static_cast<unsigned int>(size)) == 0;
}

bool LcmOutput::flush() {
  std::lock_guard<std::mutex> lock(mutex_);
  return log_ == nullptr || pending_ == 0 || flush_log();
}

bool LcmOutput::write_event(const char* channel, const void* data, std::size_t size) {
  const std::size_t channel_length = std::strlen(channel);
  const std::size_t event = 28 + channel_length + size;
  if (pending_ + event > buffer_.size() && !flush_log()) return false;
  if (event > buffer_.size()) buffer_.resize(event);  // larger than any telemetry message: never in a run
  std::uint8_t* out = buffer_.data() + pending_;
  out = put_big_endian(out, kEventMagic, 4);
  out = put_big_endian(out, static_cast<std::uint64_t>(events_), 8);
  out = put_big_endian(out, static_cast<std::uint64_t>(wall_clock_us()), 8);
  out = put_big_endian(out, channel_length, 4);
  out = put_big_endian(out, size, 4);
  std::memcpy(out, channel, channel_length);
  std::memcpy(out + channel_length, data, size);
  pending_ += event;
  ++events_;
  return true;
}

bool LcmOutput::flush_log() {
  const bool ok = std::fwrite(buffer_.data(), 1, pending_, log_) == pending_;
  pending_ = 0;
  return ok;
}

}  // namespace exc::telemetry
