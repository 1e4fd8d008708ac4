#pragma once
// An open LCM provider that publishes raw, already encoded bytes. Several telemetry publishers may
// share one (two controllers' runs into one log file); publish() serialises them with a mutex, so
// it is for the telemetry threads only, never for the real-time loop.
#include <cstddef>
#include <memory>
#include <mutex>
#include <string>

typedef struct _lcm_t lcm_t;
typedef struct _lcm_eventlog_t lcm_eventlog_t;

namespace exc::telemetry {

class LcmOutput {
 public:
  // Opens the provider named by `url`: udpm://239.255.76.67:7667?ttl=0 for live use with
  // lcm-logger and lcm-spy, file://run.lcm?mode=w to write a log file with no other process (by
  // LCM's log writer, eventlog.h, directly: the same file as its file provider writes).
  // Returns nullptr and sets `error` (naming the URL and the accepted forms) if LCM refuses it.
  static std::shared_ptr<LcmOutput> open(const std::string& url, std::string* error);

  ~LcmOutput();  // closes the provider (a log file is flushed and closed)
  LcmOutput(const LcmOutput&) = delete;
  LcmOutput& operator=(const LcmOutput&) = delete;

  // Returns false if LCM reported an error.
  bool publish(const char* channel, const void* data, std::size_t size);
  const std::string& url() const { return url_; }

 private:
  LcmOutput(lcm_t* lcm, lcm_eventlog_t* log, std::string url) : lcm_(lcm), log_(log), url_(std::move(url)) {}
  lcm_t* lcm_;           // a provider (udpm://, memq://, file:// with options), or
  lcm_eventlog_t* log_;  // for file://PATH?mode=w, LCM's log writer itself (lcm_output.cpp)
  static constexpr std::size_t kLogBufferBytes = 64 * 1024;
  std::unique_ptr<char[]> buffer_;  // the log file's stdio buffer
  std::string url_;
  std::mutex mutex_;
};

}  // namespace exc::telemetry
