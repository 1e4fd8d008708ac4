#include "log_export.hpp"

#include <lcm/lcm-cpp.hpp>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <set>
#include <type_traits>
#include <utility>
#include <vector>

#include "csv_writers.hpp"
#include "exlcm/controller_state_t.hpp"

namespace exc::log {

namespace {

// LCM's log event: sync word, event number, timestamp, channel length, data length (big-endian), then
// the channel and the data.
constexpr std::uint32_t kSyncWord = 0xEDA1DA01;
constexpr std::uint64_t kEventHeaderBytes = 4 + 8 + 8 + 4 + 4;

std::uint64_t big_endian(const std::uint8_t* bytes, int n) {
  std::uint64_t value = 0;
  for (int i = 0; i < n; ++i) value = value << 8 | bytes[i];
  return value;
}

// Debian's LCM 1.3.1 reader trusts an event's data length up to its +1: at 2^31 - 1 (a damaged log)
// the sum wraps negative, calloc returns null and the data is read into it (a segfault); a large
// length allocates up to 2 GB before the file proves too short; and a damaged header, or a damaged
// sync word after an event (that event is dropped too), ends its reading. So the next event is
// found here as it finds one (the next sync word from the file position), its header checked, and a
// damaged one skipped for the sync word after it: the events after the damage are read too, and the
// bytes skipped are counted unread. The file is left at the sync word for LCM's reader. False: no
// sound event follows.
bool seek_next_sound_event(std::FILE* file, std::uint64_t file_bytes) {
  for (;;) {
    std::uint32_t window = 0;
    int c = 0;
    while (window != kSyncWord) {
      if ((c = std::fgetc(file)) == EOF) return false;
      window = window << 8 | static_cast<std::uint32_t>(c);
    }
    const off_t sync_at = ftello(file) - 4;
    if (sync_at < 0) return false;
    std::uint8_t header[kEventHeaderBytes - 4];
    if (std::fread(header, 1, sizeof header, file) != sizeof header) return false;
    const auto channel_bytes = static_cast<std::int32_t>(big_endian(header + 16, 4));
    const auto data_bytes = static_cast<std::int32_t>(big_endian(header + 20, 4));
    // LCM's own rule for the channel (1 to 999 bytes); the data must fit in what the file holds.
    const std::uint64_t end = static_cast<std::uint64_t>(sync_at) + kEventHeaderBytes +
                              static_cast<std::uint64_t>(channel_bytes) + static_cast<std::uint64_t>(data_bytes);
    bool sound = channel_bytes > 0 && channel_bytes < 1000 && data_bytes >= 0 && end <= file_bytes;
    // LCM's reader drops an event not followed by a sync word (or the file's end), printing a bare
    // "Invalid header after log data"; such an event is skipped here instead, its bytes counted
    // unread and said in our own words.
    if (sound && end + 4 <= file_bytes) {
      std::uint8_t next[4];
      sound = fseeko(file, static_cast<off_t>(end), SEEK_SET) == 0 && std::fread(next, 1, 4, file) == 4 &&
              big_endian(next, 4) == kSyncWord;
    }
    if (fseeko(file, sound ? sync_at : sync_at + 1, SEEK_SET) != 0) return false;
    if (sound) return true;
  }
}

// t + by, held at int64's ends: a damaged log's utime can lie there, where the sum would wrap.
std::int64_t shifted(std::int64_t t, std::int64_t by) {
  std::int64_t sum = 0;
  if (!__builtin_add_overflow(t, by, &sum)) return sum;
  return by > 0 ? std::numeric_limits<std::int64_t>::max() : std::numeric_limits<std::int64_t>::min();
}

// LCM's wire format starts every message with its 8-byte big-endian fingerprint.
bool fingerprint_of(const void* data, std::int32_t size, std::int64_t* hash) {
  if (size < 8) return false;
  *hash = static_cast<std::int64_t>(big_endian(static_cast<const std::uint8_t*>(data), 8));
  return true;
}

struct FileCloser {
  void operator()(std::FILE* f) const {
    if (f != nullptr) std::fclose(f);
  }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

// Opens `path` for writing; on failure sets `error` (once) and returns null.
File open_csv(const std::string& path, std::string* error, bool* failed) {
  File file(std::fopen(path.c_str(), "w"));
  if (!file) {
    if (!*failed) *error = path + ": cannot write (" + std::strerror(errno) + ")";
    *failed = true;
  }
  return file;
}

// A channel's outputs: its rows (one per message), its bucketed view (view, written to view_file)
// and its detail rows (for utimes within one of `windows`); each one null when not written.
struct ChannelWriter {
  std::string rows_path, view_path, detail_path;
  File rows, view_file, detail;
  std::unique_ptr<BucketView> view;
  std::vector<std::pair<std::int64_t, std::int64_t>> windows;
};

// The firmware's modes in which q_desired is commanded: hold and track (safety::Mode 2 and 3).
bool commanded_mode(std::int8_t mode) { return mode == 2 || mode == 3; }

// Each controller's largest tracking error per joint and its utime, by channel suffix.
struct Worst {
  double error = -1;
  std::int64_t utime = 0;
};
using WorstErrors = std::map<std::string, std::array<Worst, 4>>;

// The controller a channel belongs to: its suffix (EXC_STATE/pid: pid), "" without one.
std::string controller_of(const std::string& channel) {
  const auto slash = channel.rfind('/');
  return slash == std::string::npos ? std::string() : channel.substr(slash + 1);
}

// Reads every event of the log into `summary`; calls on_event(event, decoded message) for each
// event that decodes as a known exlcm type.
template <class OnEvent>
bool read_log(const std::string& log_path, LogSummary* summary, std::string* error,
              OnEvent&& on_event) {
  *summary = LogSummary{};
  summary->bad_input = true;  // until the log has been read
  if (!std::filesystem::exists(log_path)) {
    *error = log_path + ": no such file";
    return false;
  }
  lcm::LogFile log(log_path, "r");
  if (!log.good()) {
    *error = log_path + ": cannot be opened as an LCM log";
    return false;
  }
  std::error_code size_error;
  const std::uintmax_t file_bytes = std::filesystem::file_size(log_path, size_error);
  if (size_error) {
    *error = log_path + ": cannot read its size (" + size_error.message() + ")";
    return false;
  }
  // A channel's type is its first exlcm message's; an event of another or no exlcm type on a typed
  // channel (a damaged fingerprint, or two publishers sharing a channel) is counted undecodable and
  // left out, so that one damaged event neither retypes the channel nor puts foreign rows under its
  // header.
  struct Reading {
    std::int64_t hash = 0;
    bool typed = false;
    std::uint64_t decoded = 0, untyped = 0;
  };
  std::map<std::string, Reading> readings;
  std::uint64_t event_bytes = 0;
  while (seek_next_sound_event(log.getFilePtr(), file_bytes)) {
    const lcm::LogEvent* event = log.readNextEvent();
    if (event == nullptr) continue;  // no sync word right after it: LCM drops it; go on from there
    event_bytes += kEventHeaderBytes + event->channel.size() + static_cast<std::uint64_t>(event->datalen);
    if (summary->events == 0) summary->first_log_utime = event->timestamp;
    summary->last_log_utime = event->timestamp;
    ++summary->events;
    ChannelSummary& channel = summary->channels[event->channel];
    Reading& reading = readings[event->channel];
    if (channel.messages == 0) channel.first_log_utime = event->timestamp;
    channel.last_log_utime = event->timestamp;
    ++channel.messages;
    std::int64_t hash = 0;
    const bool known = fingerprint_of(event->data, event->datalen, &hash) &&
        with_type_of_fingerprint(hash, [&](auto prototype) {
          if (!reading.typed) {
            reading = Reading{hash, true, 0, reading.untyped};
            channel.type_name = prototype.getTypeName();
          }
          if (hash != reading.hash || prototype.decode(event->data, 0, event->datalen) < 0) {
            ++channel.undecodable;
            return;
          }
          const bool first = ++reading.decoded == 1;
          if (!first && prototype.seq > channel.last_seq + 1) {
            ++channel.seq_gaps;
            channel.seq_missing += static_cast<std::uint64_t>(prototype.seq - channel.last_seq - 1);
          }
          if (first) channel.first_seq = prototype.seq;
          channel.last_seq = first ? prototype.seq : std::max(channel.last_seq, prototype.seq);
          channel.min_utime = first ? prototype.utime : std::min(channel.min_utime, prototype.utime);
          channel.max_utime = first ? prototype.utime : std::max(channel.max_utime, prototype.utime);
          on_event(*event, prototype);
        });
    if (!known) ++reading.untyped;
  }
  for (auto& [name, channel] : summary->channels) {
    const Reading& reading = readings[name];
    if (reading.typed) {
      channel.undecodable += reading.untyped;
    } else {
      channel.type_name = "unknown";
    }
  }
  if (summary->events == 0 && file_bytes > 0) {
    *error = log_path + ": not an LCM log (no event found where LCM's log reader expects one)";
    return false;
  }
  if (file_bytes == 0) {
    *error = log_path + ": an empty log (0 bytes): nothing was logged (a run or lcm-logger stopped before its "
             "first message, or telemetry sent where no logger listened)";
    return false;
  }
  summary->bad_input = false;
  if (file_bytes > event_bytes) summary->unread_bytes = file_bytes - event_bytes;
  return true;
}

}  // namespace

bool summarize_log(const std::string& log_path, LogSummary* summary, std::string* error) {
  return read_log(log_path, summary, error, [](const lcm::LogEvent&, const auto&) {});
}

std::string printable_channel(const std::string& channel) {
  std::string out;
  for (const char c : channel) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte >= 0x20 && byte < 0x7f && c != '\\') {
      out += c;
    } else {
      char escaped[5];
      std::snprintf(escaped, sizeof escaped, "\\x%02X", byte);
      out += escaped;
    }
  }
  return out;
}

std::string csv_file_name(const std::string& channel) {
  std::string name;
  for (const char c : channel) {
    if (c == '/') {
      name += "__";
    } else if ((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
               c == '_' || c == '.' || c == '-') {
      name += c;
    } else {
      name += '_';
    }
  }
  return name + ".csv";
}

namespace {

// The channel's writer, opened at its first message (see ExportOptions): its rows up to
// options.full_rows messages, its bucketed view beyond options.bucket_rows (in buckets/ next to the
// rows, in place of them beyond full_rows), and then its detail rows around `worst` and at its end.
template <class Message>
ChannelWriter open_writer(const std::string& channel, const std::string& file_name, const ChannelSummary& counts,
                          const Message& message, const WorstErrors& worst, const std::string& out_dir,
                          const ExportOptions& options, std::string* error, bool* failed) {
  namespace fs = std::filesystem;
  const auto path_in = [&](const char* subdirectory) {
    std::error_code ec;
    fs::create_directories(fs::path(out_dir) / subdirectory, ec);
    return (fs::path(out_dir) / subdirectory / file_name).string();
  };
  ChannelWriter w;
  if (counts.messages <= options.full_rows) {
    w.rows_path = path_in("");
    w.rows = open_csv(w.rows_path, error, failed);
    if (w.rows) write_header(w.rows.get(), message);
  }
  if (w.rows && counts.messages <= options.bucket_rows) return w;
  w.view_path = path_in(w.rows_path.empty() ? "" : "buckets");
  w.view_file = open_csv(w.view_path, error, failed);
  if (w.view_file) {
    w.view = std::make_unique<BucketView>(w.view_file.get(), counts.min_utime, counts.max_utime, options.buckets);
    w.view->write_header(message);
  }
  const auto us = [](double s) { return static_cast<std::int64_t>(s * 1e6); };
  const auto found = worst.find(controller_of(channel));
  if (found != worst.end()) {
    for (const Worst& j : found->second) {
      if (j.error >= 0) {
        w.windows.push_back({shifted(j.utime, -us(options.detail_half_width_s)),
                             shifted(j.utime, us(options.detail_half_width_s))});
      }
    }
  }
  const auto moments = options.detail_moments.find(controller_of(channel));
  if (moments != options.detail_moments.end()) {
    for (const double t : moments->second) {
      const std::int64_t at = us(t);
      w.windows.push_back({shifted(at, -us(options.detail_half_width_s)), shifted(at, us(options.detail_half_width_s))});
    }
  }
  w.windows.push_back({shifted(counts.max_utime, -us(options.detail_tail_s)), counts.max_utime});
  w.detail_path = path_in("detail");
  w.detail = open_csv(w.detail_path, error, failed);
  if (w.detail) write_header(w.detail.get(), message);
  return w;
}

bool close_csv(File& file, const std::string& path, std::string* error) {
  if (!file) return true;
  if (std::ferror(file.get()) || std::fclose(file.release()) != 0) {
    *error = path + ": write failed";
    return false;
  }
  return true;
}

}  // namespace

bool export_log_to_csv(const std::string& log_path, const std::string& out_dir,
                       LogSummary* summary, std::string* error, const ExportOptions& options) {
  // First reading: the counts and utime spans of every channel, each controller's largest errors.
  WorstErrors worst;
  const bool counted = read_log(log_path, summary, error, [&](const lcm::LogEvent& event, const auto& message) {
    if constexpr (std::is_same_v<std::decay_t<decltype(message)>, exlcm::controller_state_t>) {
      if (!commanded_mode(message.mode)) return;
      std::array<Worst, 4>& w = worst[controller_of(event.channel)];
      for (int j = 0; j < 4; ++j) {
        if (std::abs(message.error[j]) > w[j].error) w[j] = {std::abs(message.error[j]), message.utime};
      }
    }
  });
  if (!counted) return false;
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) {
    *error = out_dir + ": cannot create the CSV directory (" + ec.message() + ")";
    return false;
  }
  // Second reading: the rows.
  std::map<std::string, ChannelWriter> writers;
  std::set<std::string> file_names;
  bool write_failed = false;
  LogSummary again;
  const bool read_ok = read_log(log_path, &again, error, [&](const lcm::LogEvent& event, const auto& message) {
    auto it = writers.find(event.channel);
    if (it == writers.end()) {
      ChannelSummary& counts = summary->channels[event.channel];
      // Two channels can map to one file name (EXC_STATE/pid and EXC_STATE__pid, or two damaged
      // names): the later one gets a numbered name rather than both writing one file.
      const std::string plain = csv_file_name(event.channel);
      std::string file_name = plain;
      for (int n = 2; !file_names.insert(file_name).second; ++n)
        file_name = plain.substr(0, plain.size() - 4) + "~" + std::to_string(n) + ".csv";
      it = writers.emplace(event.channel, open_writer(event.channel, file_name, counts, message, worst, out_dir,
                                                      options, error, &write_failed))
               .first;
      counts.csv_file = file_name;
      counts.rows_written = it->second.rows != nullptr;
      counts.bucketed = it->second.view != nullptr;
    }
    ChannelWriter& w = it->second;
    if (w.rows) write_row(w.rows.get(), event.timestamp, message);
    if (w.view) w.view->add(event.timestamp, message);
    for (const auto& [from, to] : w.windows) {
      if (w.detail && message.utime >= from && message.utime <= to) {
        write_row(w.detail.get(), event.timestamp, message);
        break;
      }
    }
  });
  if (!read_ok) return false;
  for (auto& [channel, w] : writers) {
    if (w.view) w.view->finish();
    if (!close_csv(w.rows, w.rows_path, error) || !close_csv(w.view_file, w.view_path, error) ||
        !close_csv(w.detail, w.detail_path, error)) {
      return false;
    }
  }
  return !write_failed;
}

}  // namespace exc::log
