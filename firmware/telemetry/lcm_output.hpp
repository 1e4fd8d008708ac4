#pragma once
// An open LCM provider that publishes raw, already encoded bytes. Several telemetry publishers may
// share one (two controllers' runs into one log file); publish() serialises them with a mutex, so
// it is for the telemetry threads only, never for the real-time loop.
#include <cstddef>
#include <memory>
#include <mutex>
#include <string>

typedef struct _lcm_t lcm_t;

namespace exc::telemetry {

class LcmOutput {
 public:
  // Opens the provider named by `url`: udpm://239.255.76.67:7667?ttl=0 for live use with
  // lcm-logger and lcm-spy, file://run.lcm?mode=w to write a log file with no other process.
  // Returns nullptr and sets `error` (naming the URL and the accepted forms) if LCM refuses it.
  static std::shared_ptr<LcmOutput> open(const std::string& url, std::string* error);

  ~LcmOutput();  // closes the provider (a log file is flushed and closed)
  LcmOutput(const LcmOutput&) = delete;
  LcmOutput& operator=(const LcmOutput&) = delete;

  // Returns false if LCM reported an error.
  bool publish(const char* channel, const void* data, std::size_t size);
  const std::string& url() const { return url_; }

 private:
  LcmOutput(lcm_t* lcm, std::string url) : lcm_(lcm), url_(std::move(url)) {}
  lcm_t* lcm_;
  std::string url_;
  std::mutex mutex_;
};

}  // namespace exc::telemetry
