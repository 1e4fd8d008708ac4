#pragma once
// Reading LCM logs of exlcm messages with LCM's own log reader (lcm::LogFile): a per-channel summary,
// and an export of every channel to its own CSV file.
#include <cstdint>
#include <map>
#include <string>

namespace exc::log {

struct ChannelSummary {
  std::string type_name;       // exlcm type, or "unknown" if the fingerprint is not an exlcm type
  std::uint64_t messages = 0;  // events on the channel
  std::uint64_t undecodable = 0;  // events whose payload did not decode as that type
  std::int64_t first_log_utime = 0;  // log timestamps, microseconds since the UNIX epoch
  std::int64_t last_log_utime = 0;
};

struct LogSummary {
  std::map<std::string, ChannelSummary> channels;  // by channel name
  std::uint64_t events = 0;
  std::int64_t first_log_utime = 0;
  std::int64_t last_log_utime = 0;
  double duration_s() const { return events ? (last_log_utime - first_log_utime) * 1e-6 : 0.0; }
};

// Reads the whole log. Returns false and sets `error` (naming the file) if it cannot be read.
bool summarize_log(const std::string& log_path, LogSummary* summary, std::string* error);

// The CSV file name of a channel: '/' (the controller suffix separator) becomes "__", so
// EXC_STATE/pid goes to EXC_STATE__pid.csv; other characters outside [A-Za-z0-9_.-] become '_'.
std::string csv_file_name(const std::string& channel);

// Writes one CSV per channel of a known exlcm type into `out_dir` (created if missing). Header
// row: log_utime, then the message fields in .lcm order, arrays expanded as name_0, name_1, ...
// Doubles are written with 17 significant digits (%.17g) so that they read back exactly; booleans
// as 0/1; the fault text as a quoted string. Channels of unknown types are skipped (listed in
// the summary as "unknown"). Returns false and sets `error` on a read or write failure.
bool export_log_to_csv(const std::string& log_path, const std::string& out_dir,
                       LogSummary* summary, std::string* error);

}  // namespace exc::log
