#pragma once
// Reading LCM logs of exlcm messages with LCM's own log reader (lcm::LogFile): a per-channel summary,
// and an export of every channel to its own CSV file, read as a stream: memory does not grow with
// the log.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace exc::log {

struct ChannelSummary {
  std::string type_name;       // exlcm type, or "unknown" if the fingerprint is not an exlcm type
  std::uint64_t messages = 0;  // events on the channel
  std::uint64_t undecodable = 0;  // events not read as the channel's type: a payload that does not
                                  // decode, or of another or no exlcm type (see read_log)
  std::int64_t first_log_utime = 0;  // log timestamps, microseconds since the UNIX epoch
  std::int64_t last_log_utime = 0;
  std::int64_t min_utime = 0;  // the messages' own utime (us since the run started), decoded ones
  std::int64_t max_utime = 0;
  bool rows_written = false;   // export_log_to_csv wrote one row per message (see ExportOptions)
  bool bucketed = false;       // and/or its bucketed view
  std::string csv_file;        // its file name when exported: csv_file_name, numbered if another took it
  // The decoded messages' sequence numbers (+1 per message at the publisher): a jump of more than
  // one is a gap, messages published but not in the log (a receiver that dropped them, lcm-logger
  // over UDP); seq_missing counts them.
  std::int64_t first_seq = 0, last_seq = 0;
  std::uint64_t seq_gaps = 0, seq_missing = 0;
};

struct LogSummary {
  std::map<std::string, ChannelSummary> channels;  // by channel name
  std::uint64_t events = 0;
  std::int64_t first_log_utime = 0;
  std::int64_t last_log_utime = 0;
  // Bytes of the file in no complete event: a log cut short (its writer killed mid-event) or damaged
  // (an event whose header is damaged is skipped to the next sync word). The events read are whole;
  // their payloads are checked only by decoding (LCM's messages carry no checksum).
  std::uint64_t unread_bytes = 0;
  // The failure was the input's (no such file, not an LCM log, an empty one), not a write's.
  bool bad_input = false;
  // In doubles: a damaged log's stamps can lie at the ends of int64, where their difference wraps.
  double duration_s() const {
    return events ? (static_cast<double>(last_log_utime) - static_cast<double>(first_log_utime)) * 1e-6 : 0.0;
  }
};

// Reads the whole log. Returns false and sets `error` (naming the file) if it cannot be read.
bool summarize_log(const std::string& log_path, LogSummary* summary, std::string* error);

// A channel name as printed: bytes outside printable ASCII as \xNN (a damaged log's channel can hold
// control characters that would rewrite the terminal).
std::string printable_channel(const std::string& channel);

// The CSV file name of a channel: '/' (the controller suffix separator) becomes "__", so
// EXC_STATE/pid goes to EXC_STATE__pid.csv; other characters outside [A-Za-z0-9_.-] become '_'.
// A second channel of the same file name is exported as NAME~2.csv (~3, ...).
std::string csv_file_name(const std::string& channel);

// How export_log_to_csv writes a long channel.
struct ExportOptions {
  // A channel of at most full_rows messages is written one row per message, to <channel>.csv.
  // 120,000 is two minutes at 1 kHz: the shipped 10 s scenes and the 110 s truck loading keep one
  // row per cycle. A longer one is written as its bucketed view instead, to <channel>.csv.
  std::uint64_t full_rows = 120000;
  // A channel of more than bucket_rows messages gets its bucketed view (buckets/<channel>.csv when
  // its rows are written too) and its detail rows (detail/<channel>.csv): what plot-run draws a long
  // run from, in memory that does not grow with the run. 20,000 is 20 s at 1 kHz.
  std::uint64_t bucket_rows = 20000;
  // The bucketed view: this many buckets of equal length over the channel's utime span (see
  // csv_writers.hpp's BucketView). The detail rows: every message within detail_half_width_s of its
  // controller's largest tracking error on each joint, around each of its detail_moments, and in its
  // last detail_tail_s.
  int buckets = 2000;
  double detail_half_width_s = 2.0;
  double detail_tail_s = 1.0;
  // More moments (s of the run) whose detail rows are kept, detail_half_width_s either side, per
  // controller (a channel's suffix): the run summary's worst error per joint and phase, which is the
  // plant's truth and so not in the log, for the report's zoom on it (excavator-log report --summary).
  std::map<std::string, std::vector<double>> detail_moments;
};

// Writes one CSV per channel of a known exlcm type into `out_dir` (created if missing). Header
// row: log_utime, then the message fields in .lcm order, arrays expanded as name_0, name_1, ...
// Doubles are written with 17 significant digits (%.17g) so that they read back exactly; booleans
// as 0/1; the fault text as a quoted string. A long channel's bucketed view (header: bucket, rows,
// log_utime_first, log_utime_last, then per column c_first, c_last, c_min, c_max, c_sum, c_sumsq,
// c_n) and detail rows (one row per message, as above) are written as ExportOptions says. Its
// controller is the channel's suffix (EXC_STATE/pid: pid); the largest error is
// |controller_state_t.error| in hold and track. Reads the log twice (counts first). Channels of
// unknown types are skipped (listed in the summary as "unknown"). Returns false and sets `error` on
// a read or write failure.
bool export_log_to_csv(const std::string& log_path, const std::string& out_dir,
                       LogSummary* summary, std::string* error, const ExportOptions& options = {});

}  // namespace exc::log
