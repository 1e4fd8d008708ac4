#pragma once
// An open LCM provider that publishes raw, already encoded bytes. Several telemetry publishers may
// share one (two controllers' runs into one log file); publish() serialises them with a mutex, so
// it is for the telemetry threads only, never for the real-time loop.
//
// A log file (file://PATH?mode=w) is written here, in LCM's log format (lcm/eventlog.c: per event the
// magic 0xEDA1DA01, the event number, the wall-clock time in us, the channel's and the data's length,
// big-endian, then the channel and the data), through one buffer: LCM's own file provider copies
// every event into a fresh allocation and writes it in seven fwrite calls, the larger part of the
// telemetry thread's work in a fast run. The file is the one LCM writes (its readers, lcm-logplayer
// and excavator-log read it), written out after every drain of the telemetry thread. Every other URL
// goes to LCM.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

typedef struct _lcm_t lcm_t;

namespace exc::telemetry {

class LcmOutput {
 public:
  // Opens the provider named by `url`: udpm://239.255.76.67:7667?ttl=0 for live use with
  // lcm-logger and lcm-spy, file://run.lcm?mode=w to write a log file with no other process.
  // Returns nullptr and sets `error` (naming the URL and the accepted forms) if it cannot be opened.
  static std::shared_ptr<LcmOutput> open(const std::string& url, std::string* error);

  ~LcmOutput();  // closes the provider (a log file is flushed and closed)
  LcmOutput(const LcmOutput&) = delete;
  LcmOutput& operator=(const LcmOutput&) = delete;

  // Returns false if LCM (or the log file) reported an error.
  bool publish(const char* channel, const void* data, std::size_t size);
  // Writes what a log file holds in its buffer (the telemetry thread does after each drain, so a
  // process that dies loses at most one wake period of messages). Nothing for other providers.
  bool flush();
  const std::string& url() const { return url_; }

 private:
  LcmOutput(lcm_t* lcm, std::FILE* log, std::string url);
  bool write_event(const char* channel, const void* data, std::size_t size);
  bool flush_log();

  lcm_t* lcm_ = nullptr;    // every provider but a log file
  std::FILE* log_ = nullptr;  // file://PATH?mode=w
  std::vector<std::uint8_t> buffer_;  // the log's pending bytes (allocated once at open)
  std::size_t pending_ = 0;
  std::int64_t events_ = 0;
  std::string url_;
  std::mutex mutex_;
};

}  // namespace exc::telemetry
