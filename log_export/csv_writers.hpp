#pragma once
// The exporter's two ways of writing a channel (visitors over message_fields.hpp's visit_fields):
// one row per message (RowWriter under a header of column names), or the bucketed view of a long
// channel (BucketView): a fixed number of time buckets, each keeping per column its first and last
// value, minimum, maximum and the sums for exact means and RMS over every message.
#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "message_fields.hpp"  // generated from the .lcm files by message_fields.cmake

namespace exc::log {

// Calls on_column(name, is_text) for every CSV column of a message type, in .lcm order, arrays
// expanded as name_0, name_1, ...
template <class OnColumn>
struct ColumnNames {
  OnColumn on_column;
  void column(const char* name, int index, int count, bool is_text) {
    on_column(count == 1 ? std::string(name) : std::string(name) + "_" + std::to_string(index), is_text);
  }
  template <class T>
  void number(const char* name, const T*, int count) {
    for (int i = 0; i < count; ++i) column(name, i, count, false);
  }
  void boolean(const char* name, const std::int8_t*, int count) {
    for (int i = 0; i < count; ++i) column(name, i, count, false);
  }
  void text(const char* name, const std::int8_t*, int) { column(name, 0, 1, true); }
};
template <class OnColumn>
ColumnNames<OnColumn> column_names(OnColumn on_column) {
  return {on_column};
}

// The header row of the one-row-per-message CSV: log_utime, then the message's columns.
template <class Message>
void write_header(std::FILE* file, const Message& m) {
  std::fputs("log_utime", file);
  auto names = column_names([file](const std::string& name, bool) { std::fprintf(file, ",%s", name.c_str()); });
  visit_fields(m, names);
  std::fputc('\n', file);
}

// The fault text as one quoted CSV field: printable ASCII, '"' doubled, anything else '?'.
inline std::string quoted_text(const std::int8_t* chars, int capacity) {
  std::string s = "\"";
  for (int i = 0; i < capacity && chars[i] != 0; ++i) {
    const char c = static_cast<char>(chars[i]);
    s += c == '"' ? std::string("\"\"") : std::string(1, c >= 0x20 && c < 0x7f ? c : '?');
  }
  return s + "\"";
}

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
    std::fprintf(file, ",%s", quoted_text(chars, capacity).c_str());
  }
};

template <class Message>
void write_row(std::FILE* file, std::int64_t log_utime, const Message& m) {
  std::fprintf(file, "%" PRId64, log_utime);
  RowWriter row{file};
  visit_fields(m, row);
  std::fputc('\n', file);
}

// The bucketed view of one channel: `buckets` buckets of equal length over [t0, t1] (the messages'
// utime, us). Columns: bucket (index), rows (messages in it), log_utime_first, log_utime_last, then
// per column c: c_first, c_last (the bucket's first and last message), c_min, c_max, c_sum, c_sumsq
// and c_n over its finite values (min and max nan if there is none); a text column: c_first, c_last.
// Messages arrive in utime order; one older than the open bucket is counted in it. Holds one bucket.
class BucketView {
 public:
  BucketView(std::FILE* file, std::int64_t t0, std::int64_t t1, int buckets)
      : file_(file), t0_(static_cast<double>(t0)), span_(static_cast<double>(t1) - t0 + 1), buckets_(buckets) {}

  template <class Message>
  void write_header(const Message& m) {
    std::fputs("bucket,rows,log_utime_first,log_utime_last", file_);
    auto names = column_names([this](const std::string& name, bool is_text) {
      for (const char* stat : {"first", "last", "min", "max", "sum", "sumsq", "n"}) {
        std::fprintf(file_, ",%s_%s", name.c_str(), stat);
        if (is_text && std::string(stat) == "last") break;
      }
    });
    visit_fields(m, names);
    std::fputc('\n', file_);
  }

  template <class Message>
  void add(std::int64_t log_utime, const Message& m) {
    const double at = (static_cast<double>(m.utime) - t0_) / span_ * buckets_;
    const int bucket = std::min(buckets_ - 1, std::max(0, static_cast<int>(at)));
    if (rows_ > 0 && bucket > bucket_) finish();
    if (rows_ == 0) {
      bucket_ = std::max(bucket, bucket_);
      log_first_ = log_utime;
    }
    log_last_ = log_utime;
    column_ = 0;
    visit_fields(m, *this);
    ++rows_;
  }

  // Writes the open bucket (if any message is in it).
  void finish() {
    if (rows_ == 0) return;
    std::fprintf(file_, "%d,%" PRIu64 ",%" PRId64 ",%" PRId64, bucket_, rows_, log_first_, log_last_);
    for (const Stat& s : stats_) {
      if (s.is_text) {
        std::fprintf(file_, ",%s,%s", s.first_text.c_str(), s.last_text.c_str());
        continue;
      }
      const bool any = s.n > 0;
      std::fprintf(file_, ",%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%" PRIu64, s.first, s.last, any ? s.min : NAN,
                   any ? s.max : NAN, s.sum, s.sumsq, s.n);
    }
    std::fputc('\n', file_);
    rows_ = 0;
  }

  // Visitor of one message's fields (through visit_fields).
  template <class T>
  void number(const char*, const T* values, int count) {
    for (int i = 0; i < count; ++i) value(static_cast<double>(values[i]));
  }
  void boolean(const char*, const std::int8_t* values, int count) {
    for (int i = 0; i < count; ++i) value(values[i] ? 1.0 : 0.0);
  }
  void text(const char*, const std::int8_t* chars, int capacity) {
    Stat& s = stat();
    s.is_text = true;
    s.last_text = quoted_text(chars, capacity);
    if (rows_ == 0) s.first_text = s.last_text;
  }

 private:
  struct Stat {
    bool is_text = false;
    double first = 0, last = 0, min = 0, max = 0, sum = 0, sumsq = 0;
    std::uint64_t n = 0;
    std::string first_text, last_text;
  };

  Stat& stat() {
    if (column_ == stats_.size()) stats_.emplace_back();
    return stats_[column_++];
  }

  void value(double x) {
    Stat& s = stat();
    if (rows_ == 0) {
      s.first = x;
      s.sum = s.sumsq = 0;
      s.n = 0;
    }
    s.last = x;
    if (!std::isfinite(x)) return;
    s.min = s.n == 0 ? x : std::min(s.min, x);
    s.max = s.n == 0 ? x : std::max(s.max, x);
    s.sum += x;
    s.sumsq += x * x;
    ++s.n;
  }

  std::FILE* file_;
  double t0_, span_;
  int buckets_;
  int bucket_ = 0;
  std::uint64_t rows_ = 0;
  std::int64_t log_first_ = 0, log_last_ = 0;
  std::size_t column_ = 0;
  std::vector<Stat> stats_;  // one per column
};

}  // namespace exc::log
