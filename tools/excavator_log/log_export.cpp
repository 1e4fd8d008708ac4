#include "log_export.hpp"

#include <lcm/lcm-cpp.hpp>

#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

#include "message_fields.hpp"  // generated from the .lcm files by message_fields.cmake

namespace exc::log {

namespace {

// LCM's wire format starts every message with its 8-byte big-endian fingerprint.
bool fingerprint_of(const void* data, std::int32_t size, std::int64_t* hash) {
  if (size < 8) return false;
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  std::uint64_t value = 0;
  for (int i = 0; i < 8; ++i) value = value << 8 | bytes[i];
  *hash = static_cast<std::int64_t>(value);
  return true;
}

// Writes the header row.
struct HeaderWriter {
  std::FILE* file;
  void column(const char* name, int index, int count) {
    if (count == 1) {
      std::fprintf(file, ",%s", name);
    } else {
      std::fprintf(file, ",%s_%d", name, index);
    }
  }
  template <class T>
  void number(const char* name, const T*, int count) {
    for (int i = 0; i < count; ++i) column(name, i, count);
  }
  void boolean(const char* name, const std::int8_t*, int count) {
    for (int i = 0; i < count; ++i) column(name, i, count);
  }
  void text(const char* name, const std::int8_t*, int) { column(name, 0, 1); }
};

// Writes one data row.
struct RowWriter {
  std::FILE* file;
  void value(double x) { std::fprintf(file, ",%.17g", x); }
  void value(std::int64_t x) { std::fprintf(file, ",%" PRId64, x); }
  void value(std::int32_t x) { std::fprintf(file, ",%" PRId32, x); }
  void value(std::int8_t x) { std::fprintf(file, ",%d", static_cast<int>(x)); }
  template <class T>
  void number(const char*, const T* values, int count) {
    for (int i = 0; i < count; ++i) value(values[i]);
  }
  void boolean(const char*, const std::int8_t* values, int count) {
    for (int i = 0; i < count; ++i) std::fprintf(file, ",%d", values[i] ? 1 : 0);
  }
  void text(const char*, const std::int8_t* chars, int capacity) {
    std::fputs(",\"", file);
    for (int i = 0; i < capacity && chars[i] != 0; ++i) {
      const char c = static_cast<char>(chars[i]);
      if (c == '"') {
        std::fputs("\"\"", file);
      } else if (c >= 0x20 && c < 0x7f) {
        std::fputc(c, file);
      } else {
        std::fputc('?', file);  // the CSV stays one line per message
      }
    }
    std::fputc('"', file);
  }
};

struct FileCloser {
  void operator()(std::FILE* f) const {
    if (f != nullptr) std::fclose(f);
  }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

struct ChannelWriter {
  File file;
  std::string path;
};

// Reads every event of the log into `summary`; calls on_event(event, decoded message) for each
// event that decodes as a known exlcm type.
template <class OnEvent>
bool read_log(const std::string& log_path, LogSummary* summary, std::string* error,
              OnEvent&& on_event) {
  if (!std::filesystem::exists(log_path)) {
    *error = log_path + ": no such file";
    return false;
  }
  lcm::LogFile log(log_path, "r");
  if (!log.good()) {
    *error = log_path + ": cannot be opened as an LCM log";
    return false;
  }
  *summary = LogSummary{};
  while (const lcm::LogEvent* event = log.readNextEvent()) {
    if (summary->events == 0) summary->first_log_utime = event->timestamp;
    summary->last_log_utime = event->timestamp;
    ++summary->events;
    ChannelSummary& channel = summary->channels[event->channel];
    if (channel.messages == 0) channel.first_log_utime = event->timestamp;
    channel.last_log_utime = event->timestamp;
    ++channel.messages;
    std::int64_t hash = 0;
    const bool known = fingerprint_of(event->data, event->datalen, &hash) &&
        with_type_of_fingerprint(hash, [&](auto prototype) {
          channel.type_name = prototype.getTypeName();
          if (prototype.decode(event->data, 0, event->datalen) < 0) {
            ++channel.undecodable;
            return;
          }
          on_event(*event, prototype);
        });
    if (!known) channel.type_name = "unknown";
  }
  std::error_code ec;
  if (summary->events == 0 && std::filesystem::file_size(log_path, ec) > 0 && !ec) {
    *error = log_path + ": not an LCM log (no event found where LCM's log reader expects one)";
    return false;
  }
  return true;
}

}  // namespace

bool summarize_log(const std::string& log_path, LogSummary* summary, std::string* error) {
  return read_log(log_path, summary, error, [](const lcm::LogEvent&, const auto&) {});
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

bool export_log_to_csv(const std::string& log_path, const std::string& out_dir,
                       LogSummary* summary, std::string* error) {
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) {
    *error = out_dir + ": cannot create the CSV directory (" + ec.message() + ")";
    return false;
  }
  std::map<std::string, ChannelWriter> writers;
  bool write_failed = false;
  const bool read_ok = read_log(log_path, summary, error,
      [&](const lcm::LogEvent& event, const auto& message) {
        auto it = writers.find(event.channel);
        if (it == writers.end()) {
          ChannelWriter writer;
          writer.path = (std::filesystem::path(out_dir) / csv_file_name(event.channel)).string();
          writer.file.reset(std::fopen(writer.path.c_str(), "w"));
          if (!writer.file) {
            if (!write_failed) {
              *error = writer.path + ": cannot write (" + std::strerror(errno) + ")";
            }
            write_failed = true;
            return;
          }
          std::fputs("log_utime", writer.file.get());
          HeaderWriter header{writer.file.get()};
          visit_fields(message, header);
          std::fputc('\n', writer.file.get());
          it = writers.emplace(event.channel, std::move(writer)).first;
        }
        std::FILE* file = it->second.file.get();
        std::fprintf(file, "%" PRId64, event.timestamp);
        RowWriter row{file};
        visit_fields(message, row);
        std::fputc('\n', file);
      });
  if (!read_ok) return false;
  for (auto& [channel, writer] : writers) {
    if (std::ferror(writer.file.get()) || std::fclose(writer.file.release()) != 0) {
      *error = writer.path + ": write failed";
      return false;
    }
  }
  return !write_failed;
}

}  // namespace exc::log
