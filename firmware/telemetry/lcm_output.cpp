#include "telemetry/lcm_output.hpp"

#include <lcm/eventlog.h>
#include <lcm/lcm.h>
#include <stdio_ext.h>

#include <cstdio>
#include <ctime>

namespace exc::telemetry {

namespace {

// "file://PATH?mode=w" -> PATH; empty for every other URL (those go through lcm_create).
std::string log_path_of(const std::string& url) {
  const std::string scheme = "file://", query = "?mode=w";
  if (url.size() <= scheme.size() + query.size() || url.compare(0, scheme.size(), scheme) != 0 ||
      url.compare(url.size() - query.size(), query.size(), query) != 0)
    return {};
  std::string path = url.substr(scheme.size(), url.size() - scheme.size() - query.size());
  if (path.find_first_of("?&") != std::string::npos) return {};  // other options: LCM's provider reads them
  return path;
}

}  // namespace

std::shared_ptr<LcmOutput> LcmOutput::open(const std::string& url, std::string* error) {
  // A log file is written by LCM's own log writer (eventlog.h), the one its file provider's publish
  // calls, held here directly: the provider copies every message into a fresh heap block and takes
  // the stdio lock once per field (nine writes a message); with the writer held the bytes go from the
  // ring's buffer to the file, and the stdio lock is left to publish()'s mutex, which every write
  // already holds. The file is the same, event for event (eventnum, wall-clock timestamp in us,
  // channel, data).
  const std::string path = log_path_of(url);
  if (!path.empty()) {
    lcm_eventlog_t* log = lcm_eventlog_create(path.c_str(), "w");
    if (log == nullptr) {
      if (error != nullptr) *error = "telemetry: cannot open the LCM log '" + path + "' for writing (from '" + url + "')";
      return nullptr;
    }
    __fsetlocking(log->f, FSETLOCKING_BYCALLER);
    // A larger stdio buffer than the default 4 KiB: a system call per 64 KiB of log (about 100
    // messages) instead of per 6. Set before the first write, as setvbuf requires; the buffer is the
    // output's and outlives the file (the destructor closes the log first).
    std::unique_ptr<char[]> buffer(new char[kLogBufferBytes]);
    if (setvbuf(log->f, buffer.get(), _IOFBF, kLogBufferBytes) != 0) buffer.reset();
    auto output = std::shared_ptr<LcmOutput>(new LcmOutput(nullptr, log, url));
    output->buffer_ = std::move(buffer);
    return output;
  }
  lcm_t* lcm = lcm_create(url.c_str());
  if (lcm == nullptr) {
    if (error != nullptr) {
      *error = "telemetry: LCM cannot open provider '" + url +
               "' (expected udpm://GROUP:PORT?ttl=N, e.g. udpm://239.255.76.67:7667?ttl=0, or "
               "file://PATH?mode=w; for udpm the loopback may need multicast: "
               "ip link set lo multicast on; ip route add 239.255.0.0/16 dev lo)";
    }
    return nullptr;
  }
  return std::shared_ptr<LcmOutput>(new LcmOutput(lcm, nullptr, url));
}

LcmOutput::~LcmOutput() {
  if (log_ != nullptr) lcm_eventlog_destroy(log_);
  if (lcm_ != nullptr) lcm_destroy(lcm_);
}

bool LcmOutput::publish(const char* channel, const void* data, std::size_t size) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (log_ != nullptr) {
    // The event as LCM's file provider fills it: the wall clock in microseconds since the epoch.
    timespec now{};
    clock_gettime(CLOCK_REALTIME, &now);
    lcm_eventlog_event_t event{};
    event.timestamp = static_cast<std::int64_t>(now.tv_sec) * 1000000 + now.tv_nsec / 1000;
    event.channellen = static_cast<std::int32_t>(std::char_traits<char>::length(channel));
    event.datalen = static_cast<std::int32_t>(size);
    event.channel = const_cast<char*>(channel);  // LCM's API is not const; it only reads them
    event.data = const_cast<void*>(data);
    return lcm_eventlog_write_event(log_, &event) == 0;
  }
  return lcm_publish(lcm_, channel, data, static_cast<unsigned int>(size)) == 0;
}

}  // namespace exc::telemetry
