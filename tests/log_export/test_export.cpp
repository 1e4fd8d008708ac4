// excavator-log's export: every column named as in the .lcm files, every value read back exactly.
// The expected values come from the test's own encoder of LCM's wire format (lcm_schema.hpp), not
// from lcm-gen's classes or the exporter's field table.
#include <doctest/doctest.h>

#include <lcm/lcm-cpp.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "exlcm/can_stats_t.hpp"
#include "exlcm/command_t.hpp"
#include "exlcm/controller_state_t.hpp"
#include "exlcm/fault_t.hpp"
#include "exlcm/machine_state_t.hpp"
#include "exlcm/telemetry_stats_t.hpp"
#include "exlcm/timing_t.hpp"
#include "lcm_schema.hpp"
#include "log_export.hpp"
#include "scratch_files.hpp"

namespace fs = std::filesystem;
using exc::test::LcmStruct;

namespace {

// One CSV line split into fields ("..." quoting with "" for a quote).
std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

std::vector<std::vector<std::string>> read_csv(const fs::path& path) {
  std::ifstream in(path);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  while (std::getline(in, line)) rows.push_back(split_csv(line));
  return rows;
}

// A random message of a struct: its wire bytes and, per CSV column, the exact expected value.
struct Sample {
  std::vector<std::uint8_t> bytes;
  std::vector<double> numbers;        // doubles and integers (all exact in a double here)
  std::vector<bool> is_nan;
  std::string text;                   // the text column, if the struct has one
};

double random_double(std::mt19937_64& rng) {
  std::uniform_int_distribution<int> kind(0, 9);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-300, 300);
  switch (kind(rng)) {
    case 0: return std::numeric_limits<double>::quiet_NaN();
    case 1: return std::numeric_limits<double>::denorm_min() * 3;
    case 2: return -0.0;
    case 3: return 0.1;  // not exact in binary: needs all 17 digits
    default: return std::ldexp(unit(rng), exponent(rng) / 4) * (1 + 1e-15);
  }
}

Sample random_sample(const LcmStruct& s, std::int64_t hash, std::mt19937_64& rng) {
  Sample sample;
  exc::test::write_big_endian(sample.bytes, static_cast<std::uint64_t>(hash), 8);
  std::uniform_int_distribution<std::int64_t> any64(std::numeric_limits<std::int64_t>::min() / 2,
                                                    std::numeric_limits<std::int64_t>::max() / 2);
  for (const auto& f : s.fields) {
    if (f.name == "text" && f.type == "int8_t") {
      const std::string text = "valve \"boom\", stuck";  // a quote and a comma
      for (int i = 0; i < f.count; ++i) {
        sample.bytes.push_back(i < static_cast<int>(text.size()) ? text[i] : 0);
      }
      sample.text = text;
      sample.numbers.push_back(0);
      sample.is_nan.push_back(false);
      continue;
    }
    for (int i = 0; i < f.count; ++i) {
      double expected = 0;
      if (f.type == "double") {
        const double x = random_double(rng);
        std::uint64_t bits;
        std::memcpy(&bits, &x, 8);
        exc::test::write_big_endian(sample.bytes, bits, 8);
        expected = x;
      } else if (f.type == "boolean") {
        const int b = static_cast<int>(rng() % 2);
        sample.bytes.push_back(static_cast<std::uint8_t>(b));
        expected = b;
      } else {
        const int size = exc::test::wire_size_of(f.type);
        // int64 values stay within 2^53 so that the double comparison below is exact.
        std::int64_t v = any64(rng) >> (size == 8 ? 11 : 64 - 8 * size);
        exc::test::write_big_endian(sample.bytes, static_cast<std::uint64_t>(v), size);
        expected = static_cast<double>(v);
      }
      sample.numbers.push_back(expected);
      sample.is_nan.push_back(std::isnan(expected));
    }
  }
  return sample;
}

struct TypeUnderTest {
  const char* lcm_file;
  std::int64_t hash;
  const char* channel;
};

}  // namespace

TEST_CASE("telemetry/export writes every channel with the .lcm field names and exact values") {
  const std::vector<TypeUnderTest> types = {
      {"machine_state_t.lcm", exlcm::machine_state_t::getHash(), "EXC_STATE/pid"},
      {"command_t.lcm", exlcm::command_t::getHash(), "EXC_COMMAND/adaptive"},
      {"controller_state_t.lcm", exlcm::controller_state_t::getHash(), "EXC_CONTROLLER"},
      {"timing_t.lcm", exlcm::timing_t::getHash(), "EXC_TIMING"},
      {"can_stats_t.lcm", exlcm::can_stats_t::getHash(), "EXC_CAN_STATS"},
      {"fault_t.lcm", exlcm::fault_t::getHash(), "EXC_FAULT"},
      {"telemetry_stats_t.lcm", exlcm::telemetry_stats_t::getHash(), "EXC_TELEMETRY_STATS"},
  };
  // Every .lcm file of the project is covered here.
  std::size_t lcm_files = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(EXC_SOURCE_DIR) / "lcmtypes")) {
    if (entry.path().extension() == ".lcm") ++lcm_files;
  }
  CHECK(lcm_files == types.size());

  const fs::path dir = fs::temp_directory_path() / ("exc-export-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path log_path = dir / "roundtrip.lcm";
  constexpr int per_channel = 50;
  std::mt19937_64 rng(20261122);
  std::vector<LcmStruct> schemas;
  std::vector<std::vector<Sample>> samples(types.size());
  std::vector<std::vector<std::int64_t>> log_times(types.size());
  {
    lcm::LogFile log(log_path.string(), "w");
    REQUIRE(log.good());
    std::int64_t t = 1700000000000000;
    for (const auto& type : types) {
      schemas.push_back(exc::test::parse_lcm_file(
          (fs::path(EXC_SOURCE_DIR) / "lcmtypes" / type.lcm_file).string()));
      REQUIRE(!schemas.back().fields.empty());
      CHECK(schemas.back().fields[0].name == "utime");  // the project's rule: utime first
      CHECK(schemas.back().fields[1].name == "seq");
    }
    for (int n = 0; n < per_channel; ++n) {
      for (std::size_t i = 0; i < types.size(); ++i) {
        samples[i].push_back(random_sample(schemas[i], types[i].hash, rng));
        lcm::LogEvent event{};
        event.timestamp = t += 137;
        event.channel = types[i].channel;
        event.datalen = static_cast<std::int32_t>(samples[i].back().bytes.size());
        event.data = samples[i].back().bytes.data();
        REQUIRE(log.writeEvent(&event) == 0);
        log_times[i].push_back(event.timestamp);
      }
    }
  }

  exc::log::LogSummary summary;
  std::string error;
  REQUIRE_MESSAGE(exc::log::export_log_to_csv(log_path.string(), (dir / "csv").string(), &summary,
                                              &error),
                  error);
  CHECK(summary.events == types.size() * per_channel);

  for (std::size_t i = 0; i < types.size(); ++i) {
    CAPTURE(types[i].channel);
    const fs::path csv = dir / "csv" / exc::log::csv_file_name(types[i].channel);
    REQUIRE(fs::exists(csv));
    const auto rows = read_csv(csv);
    REQUIRE(rows.size() == per_channel + 1);
    std::vector<std::string> header = {"log_utime"};
    for (const auto& c : exc::test::expected_columns(schemas[i])) header.push_back(c);
    CHECK(rows[0] == header);
    std::size_t mismatches = 0;
    for (int n = 0; n < per_channel; ++n) {
      const auto& row = rows[n + 1];
      const Sample& s = samples[i][n];
      REQUIRE(row.size() == s.numbers.size() + 1);
      if (std::stoll(row[0]) != log_times[i][n]) ++mismatches;
      for (std::size_t c = 0; c < s.numbers.size(); ++c) {
        if (header[c + 1] == "text") {
          if (row[c + 1] != s.text) ++mismatches;
          continue;
        }
        const double parsed = std::strtod(row[c + 1].c_str(), nullptr);
        if (s.is_nan[c]) {
          if (!std::isnan(parsed)) ++mismatches;
        } else if (std::memcmp(&parsed, &s.numbers[c], sizeof parsed) != 0) {
          ++mismatches;  // bit for bit: -0.0, denormals and 0.1 included
          MESSAGE(header[c + 1] << ": wrote " << s.numbers[c] << ", read " << row[c + 1]);
        }
      }
    }
    CHECK(mismatches == 0);
  }
  CHECK(exc::log::csv_file_name("EXC_STATE/pid") == "EXC_STATE__pid.csv");
  fs::remove_all(dir);
}

TEST_CASE("telemetry/export names the file when the log is missing") {
  exc::log::LogSummary summary;
  std::string error;
  CHECK_FALSE(exc::log::export_log_to_csv("/nonexistent/run.lcm", "/tmp/unused", &summary, &error));
  CHECK(error.find("/nonexistent/run.lcm") != std::string::npos);
}

namespace {

// A column of a CSV read by read_csv, by its header name.
double cell(const std::vector<std::vector<std::string>>& rows, std::size_t row, const std::string& column) {
  const auto& header = rows.at(0);
  const auto at = std::find(header.begin(), header.end(), column);
  REQUIRE_MESSAGE(at != header.end(), "no column " << column);
  return std::strtod(rows.at(row).at(static_cast<std::size_t>(at - header.begin())).c_str(), nullptr);
}

}  // namespace

TEST_CASE("telemetry/export writes a long channel's bucketed view (min, max, first, last and exact sums per bucket) in place of its rows beyond full_rows, beside them beyond bucket_rows, and its detail rows around the largest error, around each moment the run's summary names and at the end") {
  const fs::path dir = fs::temp_directory_path() / ("exc-export-buckets-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path log_path = dir / "long.lcm";
  // 10 s at 1 kHz: q_active_0 = k, a tracking error peaking at 7.0 s (larger in wait_sensors, mode
  // 1, before 1 s: not a tracking error), and 10 timing messages (short: one row each).
  constexpr int kMessages = 10000;
  const auto error_at = [](int k) { return k < 1000 ? 10.0 : 0.1 - 1e-5 * std::abs(k - 7000); };
  {
    lcm::LogFile log(log_path.string(), "w");
    REQUIRE(log.good());
    std::vector<std::uint8_t> buffer(4096);
    const auto write = [&](const char* channel, std::int64_t stamp, const auto& message) {
      const int size = message.encode(buffer.data(), 0, static_cast<int>(buffer.size()));
      REQUIRE(size > 0);
      lcm::LogEvent event{};
      event.timestamp = stamp;
      event.channel = channel;
      event.datalen = size;
      event.data = buffer.data();
      REQUIRE(log.writeEvent(&event) == 0);
    };
    for (int k = 0; k < kMessages; ++k) {
      exlcm::machine_state_t state{};
      state.utime = state.seq = k;
      state.utime *= 1000;
      state.q_active[0] = k;
      state.q_active[1] = std::nan("");  // no finite value: min and max nan, n 0
      write("EXC_STATE/pid", 1700000000000000 + k, state);
      exlcm::controller_state_t ctrl{};
      ctrl.utime = state.utime;
      ctrl.mode = k < 1000 ? 1 : 3;
      for (double& e : ctrl.error) e = error_at(k);
      write("EXC_CONTROLLER/pid", 1700000000000000 + k, ctrl);
      if (k % 1000 == 0) {
        exlcm::timing_t timing{};
        timing.utime = state.utime;
        write("EXC_TIMING/pid", 1700000000000000 + k, timing);
      }
    }
  }
  // Beyond full_rows the bucketed view replaces the rows; beyond bucket_rows it joins them (buckets/).
  exc::log::ExportOptions replaced, joined;
  replaced.full_rows = joined.bucket_rows = 1000;
  replaced.buckets = joined.buckets = 10;
  for (const auto& [options, view_dir] : {std::pair{replaced, fs::path("csv")}, std::pair{joined, fs::path("csv/buckets")}}) {
    const fs::path out = dir / (options.full_rows == 1000 ? "replaced" : "joined");
    CAPTURE(out);
    exc::log::LogSummary summary;
    std::string error;
    REQUIRE_MESSAGE(exc::log::export_log_to_csv(log_path.string(), (out / "csv").string(), &summary, &error, options),
                    error);
    CHECK(summary.channels["EXC_STATE/pid"].bucketed);
    CHECK(summary.channels["EXC_STATE/pid"].rows_written == (options.full_rows > kMessages));
    CHECK_FALSE(summary.channels["EXC_TIMING/pid"].bucketed);
    CHECK(read_csv(out / "csv" / "EXC_TIMING__pid.csv").size() == 1 + 10);
    if (summary.channels["EXC_STATE/pid"].rows_written) CHECK(read_csv(out / "csv" / "EXC_STATE__pid.csv").size() == 1 + kMessages);

    const auto view = read_csv(out / view_dir / "EXC_STATE__pid.csv");
    REQUIRE(view.size() == 1 + 10);
    const std::vector<std::string> first_columns = {"bucket", "rows", "log_utime_first", "log_utime_last", "utime_first"};
    CHECK(std::vector<std::string>(view[0].begin(), view[0].begin() + 5) == first_columns);
    double sum_sq = 0, n = 0;
    for (int b = 0; b < 10; ++b) {
      CAPTURE(b);
      const std::size_t r = static_cast<std::size_t>(b) + 1;
      const double k0 = 1000.0 * b, k1 = k0 + 999;
      CHECK(cell(view, r, "bucket") == b);
      CHECK(cell(view, r, "rows") == 1000);
      CHECK(cell(view, r, "log_utime_first") == 1700000000000000 + k0);
      CHECK(cell(view, r, "q_active_0_first") == k0);
      CHECK(cell(view, r, "q_active_0_last") == k1);
      CHECK(cell(view, r, "q_active_0_min") == k0);
      CHECK(cell(view, r, "q_active_0_max") == k1);
      CHECK(cell(view, r, "q_active_0_sum") == 1000 * (k0 + k1) / 2);  // exact in doubles
      CHECK(cell(view, r, "q_active_0_n") == 1000);
      CHECK(std::isnan(cell(view, r, "q_active_1_min")));
      CHECK(cell(view, r, "q_active_1_n") == 0);
      sum_sq += cell(view, r, "q_active_0_sumsq");
      n += cell(view, r, "q_active_0_n");
    }
    // The RMS over every message, from the buckets' sums.
    double exact = 0;
    for (int k = 0; k < kMessages; ++k) exact += double(k) * k;
    CHECK(std::sqrt(sum_sq / n) == doctest::Approx(std::sqrt(exact / kMessages)).epsilon(1e-14));

    // Detail rows: every message within 2 s of the largest tracking error (7.0 s) and in the last
    // second (8.999 .. 9.999 s): 5.0 .. 9.999 s, one row each, on both channels of the controller.
    for (const char* channel : {"EXC_STATE__pid.csv", "EXC_CONTROLLER__pid.csv"}) {
      CAPTURE(channel);
      const auto detail = read_csv(out / "csv" / "detail" / channel);
      REQUIRE(detail.size() == 1 + 5000);
      CHECK(cell(detail, 1, "utime") == 5000000);
      CHECK(cell(detail, 5000, "utime") == 9999000);
    }
  }
  // A summary's moment (the plant's worst error, not in the log) keeps its 2 s either side too:
  // 0 .. 4.0 s besides 5.0 .. 9.999 s; another controller's moment keeps none of pid's rows.
  exc::log::ExportOptions with_moment = joined;
  with_moment.detail_moments = {{"pid", {2.0}}, {"adaptive", {4.5}}};
  const fs::path out = dir / "moment";
  exc::log::LogSummary summary;
  std::string error;
  REQUIRE_MESSAGE(exc::log::export_log_to_csv(log_path.string(), out.string(), &summary, &error, with_moment), error);
  const auto detail = read_csv(out / "detail" / "EXC_CONTROLLER__pid.csv");
  REQUIRE(detail.size() == 1 + 4001 + 5000);
  CHECK(cell(detail, 1, "utime") == 0);
  CHECK(cell(detail, 4001, "utime") == 4000000);
  CHECK(cell(detail, 4002, "utime") == 5000000);
  fs::remove_all(dir);
}

namespace {

// An exlcm message as LCM's encoder writes it.
template <class Message>
std::vector<std::uint8_t> encoded(const Message& message) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(message.getEncodedSize()));
  REQUIRE(message.encode(bytes.data(), 0, static_cast<int>(bytes.size())) >= 0);
  return bytes;
}

std::vector<std::uint8_t> timing_message(std::int64_t utime, std::int64_t seq) {
  exlcm::timing_t msg{};
  msg.utime = utime;
  msg.seq = seq;
  return encoded(msg);
}

struct Event {
  std::string channel;
  std::vector<std::uint8_t> data;
  std::int64_t timestamp = 0;
};

// Written with LCM's own log writer. Each event takes 28 header bytes + channel + data (LCM's format).
void write_log(const fs::path& path, const std::vector<Event>& events) {
  lcm::LogFile log(path.string(), "w");
  REQUIRE(log.good());
  for (const Event& e : events) {
    lcm::LogEvent event{};
    event.timestamp = e.timestamp;
    event.channel = e.channel;
    event.datalen = static_cast<std::int32_t>(e.data.size());
    event.data = const_cast<std::uint8_t*>(e.data.data());
    REQUIRE(log.writeEvent(&event) == 0);
  }
}

std::string file_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// excavator-log with `args`, its output and errors kept in `dir`; status -1 when it did not exit
// (killed by a signal: a crash).
struct ToolRun {
  int status = -1;
  std::string out, err;
};
ToolRun run_excavator_log(const std::string& args, const fs::path& dir) {
  const fs::path out = dir / "tool.out", err = dir / "tool.err";
  const std::string cmd = std::string(EXC_EXCAVATOR_LOG) + " " + args + " > '" + out.string() + "' 2> '" +
                          err.string() + "'";
  const int raw = std::system(cmd.c_str());
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, file_text(out), file_text(err)};
}

// The row of `channel` in excavator-log info's table, split at blanks (channel, type, messages,
// rate_hz, undecodable); empty when the table has none.
std::vector<std::string> info_row(const std::string& out, const std::string& channel) {
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind(channel + " ", 0) != 0) continue;
    std::istringstream fields(line);
    std::vector<std::string> row;
    for (std::string f; fields >> f;) row.push_back(f);
    return row;
  }
  return {};
}

// Ten timing_t events on one channel, all of one size; returns that size.
std::uint64_t write_ten_timing_events(const fs::path& path, const std::string& channel) {
  std::vector<Event> events;
  for (int k = 0; k < 10; ++k) events.push_back({channel, timing_message(1000 * k, k), 1700000000000000 + k});
  write_log(path, events);
  const std::uint64_t event_size = 28 + channel.size() + events[0].data.size();
  REQUIRE(fs::file_size(path) == 10 * event_size);
  return event_size;
}

}  // namespace

TEST_CASE("tools/excavator-log info gives each channel's rate per second of the run, not of the wall clock") {
  // A simulated run logs far faster than real time: 101 messages 1 ms apart in the run, all written
  // within 2 ms of wall time, must read 1000 Hz (the wall clock would say 50 kHz).
  const fs::path dir = exc::test::scratch_dir(fs::temp_directory_path() / ("exc-info-" + std::to_string(::getpid())));
  const fs::path log_path = dir / "run.lcm";
  std::vector<Event> events;
  for (int k = 0; k <= 100; ++k)  // utime: us since the run started
    events.push_back({"EXC_TIMING/pid", timing_message(50000 + 1000 * k, k), 1700000000000000 + 20 * k});
  events.push_back({"OTHER", {1, 2, 3, 0, 0, 0, 0, 0, 0, 0, 0, 0}, 1700000000003000});
  write_log(log_path, events);
  const ToolRun run = run_excavator_log("info '" + log_path.string() + "'", dir);
  REQUIRE(run.status == 0);
  const std::string& out = run.out;
  INFO(out);
  CHECK(out.find("102 events, run time 0.050 to 0.150 s (the messages' utime), logged in 0.003 s of wall time") !=
        std::string::npos);
  const std::vector<std::string> timing = info_row(out, "EXC_TIMING/pid"), other = info_row(out, "OTHER");
  REQUIRE(timing.size() == 5);
  CHECK(timing[1] == "timing_t");
  CHECK(timing[2] == "101");
  CHECK(timing[3] == "1000.0");
  REQUIRE(other.size() == 5);
  CHECK(other[1] == "unknown");
  CHECK(other[3] == "-");  // no time of its own to count by
}

TEST_CASE("tools/excavator-log says how many bytes of a log cut short are in no complete event, and reads the events before them") {
  // A logger killed mid-event leaves a partial last event: LCM's reader stops before it. The count of
  // unread bytes is what the file holds beyond the complete events, known here from what was written.
  const fs::path dir = exc::test::scratch_dir(fs::temp_directory_path() / ("exc-unread-" + std::to_string(::getpid())));
  const fs::path whole = dir / "whole.lcm", cut = dir / "cut.lcm";
  const std::uint64_t event_size = write_ten_timing_events(whole, "EXC_TIMING/pid");
  // Cut in the middle of the eighth event: seven complete ones, the rest unread.
  const std::uint64_t keep = 7 * event_size + event_size / 2;
  std::ofstream(cut, std::ios::binary) << file_text(whole).substr(0, keep);
  const ToolRun whole_run = run_excavator_log("info '" + whole.string() + "'", dir);
  CHECK(whole_run.status == 0);
  CHECK(whole_run.err.empty());  // the control: a whole log has nothing unread
  const ToolRun cut_run = run_excavator_log("info '" + cut.string() + "'", dir);
  INFO(cut_run.err);
  CHECK(cut_run.status == 0);
  CHECK(cut_run.err.find(cut.string() + ": " + std::to_string(keep - 7 * event_size) +
                         " bytes are in no complete event") != std::string::npos);
  CHECK(cut_run.err.find("the 7 complete events are used") != std::string::npos);
}

TEST_CASE("tools/excavator-log reads past a damaged event header, and counts the bytes it lost") {
  // Ten events of one size; one header damaged in place. Each damage must cost what the log format
  // says it costs (the damaged event; for a damaged sync word also the event before it, which LCM's
  // reader drops when no sync word follows it), never the rest of the log. A data length of 2^31 - 1
  // crashed LCM 1.3.1's reader (its +1 wraps negative: calloc fails and it reads into the null).
  const fs::path dir = exc::test::scratch_dir(fs::temp_directory_path() / ("exc-damaged-" + std::to_string(::getpid())));
  const fs::path whole = dir / "whole.lcm";
  const std::uint64_t event_size = write_ten_timing_events(whole, "EXC_TIMING/pid");
  struct Damage {
    const char* what;
    std::size_t offset;  // in the fourth event's header: 0 sync word, 20 channel length, 24 data length
    std::uint32_t value;
    int events_lost;
  };
  const Damage damages[] = {
      {"data length 2^31 - 1", 24, 0x7FFFFFFF, 1},
      {"negative data length", 24, 0xFFFFFFFB, 1},
      {"data length beyond the file's end", 24, 0x00100000, 1},
      {"channel length 5000", 20, 5000, 1},
      {"channel length 0", 20, 0, 1},
      {"sync word", 0, 0, 2},
  };
  const std::string bytes = file_text(whole);
  for (const Damage& d : damages) {
    INFO("damage: " << d.what);
    std::string damaged = bytes;
    const std::size_t at = 3 * event_size + d.offset;
    for (int i = 0; i < 4; ++i) damaged[at + i] = static_cast<char>((d.value >> (24 - 8 * i)) & 0xFF);
    const fs::path log = dir / "damaged.lcm";
    std::ofstream(log, std::ios::binary | std::ios::trunc) << damaged;
    const ToolRun run = run_excavator_log("info '" + log.string() + "'", dir);
    INFO(run.out << run.err);
    REQUIRE(run.status == 0);
    const int read = 10 - d.events_lost;
    CHECK(run.out.find(": " + std::to_string(read) + " events") != std::string::npos);
    CHECK(run.err.find(std::to_string(d.events_lost * event_size) + " bytes are in no complete event") !=
          std::string::npos);
    CHECK(run.err.find("the " + std::to_string(read) + " complete events are used") != std::string::npos);
  }
}

TEST_CASE("tools/excavator-log exits 2 for bad input (no such file, not a log, an empty log), explains a damaged sync word in its own words and flags gaps in a channel's sequence numbers") {
  const fs::path dir = exc::test::scratch_dir(fs::temp_directory_path() / ("exc-input-" + std::to_string(::getpid())));
  const fs::path text = dir / "notes.txt", empty = dir / "empty.lcm";
  std::ofstream(text) << "not a log\n";
  std::ofstream{empty};
  for (const char* sub : {"info", "export", "report"}) {
    const std::string tail = std::string(sub) == "info" ? "" : std::string(sub) == "export" ? " --csv csv" : " --out rep";
    INFO(sub);
    const ToolRun missing = run_excavator_log(std::string(sub) + " '" + (dir / "none.lcm").string() + "'" + tail, dir);
    CHECK(missing.status == 2);
    CHECK(missing.err.find("none.lcm: no such file") != std::string::npos);
    const ToolRun not_log = run_excavator_log(std::string(sub) + " '" + text.string() + "'" + tail, dir);
    CHECK(not_log.status == 2);
    CHECK(not_log.err.find("notes.txt: not an LCM log") != std::string::npos);
    const ToolRun nothing = run_excavator_log(std::string(sub) + " '" + empty.string() + "'" + tail, dir);
    INFO(nothing.err);
    CHECK(nothing.status == 2);
    CHECK(nothing.err.find("empty.lcm: an empty log (0 bytes): nothing was logged") != std::string::npos);
    CHECK(nothing.err.find("plot-run") == std::string::npos);
  }
  // Ten events with sequence numbers 0..11, 3 and 7 not published into the log: two gaps, two missing.
  const fs::path gappy = dir / "gappy.lcm";
  std::vector<Event> events;
  for (int k = 0; k < 12; ++k)
    if (k != 3 && k != 7) events.push_back({"EXC_TIMING/pid", timing_message(1000 * k, k), 1700000000000000 + k});
  write_log(gappy, events);
  const ToolRun gaps = run_excavator_log("info '" + gappy.string() + "'", dir);
  INFO(gaps.out);
  CHECK(gaps.status == 0);
  CHECK(gaps.out.find("EXC_TIMING/pid: 2 of 12 messages missing (sequence numbers 0 to 11, 2 gaps)") != std::string::npos);
  // The control: ten events without a gap say nothing of one.
  const fs::path whole = dir / "whole.lcm";
  const std::uint64_t event_size = write_ten_timing_events(whole, "EXC_TIMING/pid");
  const ToolRun whole_run = run_excavator_log("info '" + whole.string() + "'", dir);
  CHECK(whole_run.out.find("missing") == std::string::npos);
  // A damaged sync word: LCM's own reader would print a bare "Invalid header after log data"; the
  // event before it and the damaged one are counted unread, in excavator-log's words.
  std::string damaged = file_text(whole);
  for (int i = 0; i < 4; ++i) damaged[4 * event_size + i] = 0;
  std::ofstream(whole, std::ios::binary | std::ios::trunc) << damaged;
  const ToolRun sync = run_excavator_log("info '" + whole.string() + "'", dir);
  INFO(sync.err);
  CHECK(sync.status == 0);
  CHECK(sync.err.find("Invalid header") == std::string::npos);
  CHECK(sync.err.find(std::to_string(2 * event_size) + " bytes are in no complete event") != std::string::npos);
}

TEST_CASE("tools/excavator-log export and report refuse a summary whose worst moment is not a number of seconds, naming the file and field, exit 2") {
  const fs::path dir = exc::test::scratch_dir(fs::temp_directory_path() / ("exc-moments-" + std::to_string(::getpid())));
  const fs::path log = dir / "ten.lcm";
  write_ten_timing_events(log, "EXC_TIMING/pid");
  for (const auto& [json, field] : {std::pair<std::string, std::string>{R"({"pid": {"phases": {"hold": {"worst_time": {"arm": "soon"}}}}})",
                                                                        "pid.phases.hold.worst_time.arm: not a number"},
                                    {R"({"pid": {"phases": {"stop": {"worst_time": {"boom": 1e300}}}}})",
                                     "pid.phases.stop.worst_time.boom: 1e+300 is outside 0 .. 1e6 s"},
                                    {"{\"pid\": ", "summary.json: not a JSON summary"}}) {
    std::ofstream(dir / "summary.json", std::ios::trunc) << json;
    for (const char* sub : {"export --csv csv", "report --out rep"}) {
      INFO(sub << " " << json);
      const ToolRun run = run_excavator_log(std::string(sub) + " '" + log.string() + "' --summary '" + (dir / "summary.json").string() + "'", dir);
      CHECK(run.status == 2);
      CHECK(run.err.find("summary.json: ") != std::string::npos);
      CHECK(run.err.find(field) != std::string::npos);
    }
  }
  // Every phase's moment a number, -1 for a phase without samples, another summary's keys ignored: read.
  std::ofstream(dir / "summary.json", std::ios::trunc)
      << R"({"scene": "dig", "pid": {"phases": {"tracking": {"worst_time": {"arm": 0.004, "swing": -1}}, "hold": null}}})";
  const ToolRun fine = run_excavator_log("export '" + log.string() + "' --csv csv --summary '" + (dir / "summary.json").string() + "'", dir);
  INFO(fine.err);
  CHECK(fine.status == 0);
}

TEST_CASE("telemetry/export keeps a channel's type through an event of another or no type, and leaves that event out") {
  // One channel of timing_t with, in its middle, an event whose fingerprint is damaged and one of
  // another exlcm type (two publishers on one channel): both are counted undecodable; the channel
  // stays timing_t (one damaged event made it "unknown", and its rate "-") and its CSV holds only
  // timing_t rows under timing_t's header.
  const fs::path dir = exc::test::scratch_dir(fs::temp_directory_path() / ("exc-retype-" + std::to_string(::getpid())));
  const std::string channel = "EXC_TIMING/pid";
  std::vector<Event> events;
  for (int k = 0; k < 10; ++k) events.push_back({channel, timing_message(1000 * k, k), 1700000000000000 + k});
  events[0].data[0] ^= 0x40;  // the first message's fingerprint: the type must come from the next
  exlcm::fault_t fault{};
  fault.utime = 4500;
  events.insert(events.begin() + 5, Event{channel, encoded(fault), 1700000000000004});
  write_log(dir / "run.lcm", events);
  exc::log::LogSummary summary;
  std::string error;
  REQUIRE(exc::log::export_log_to_csv((dir / "run.lcm").string(), (dir / "csv").string(), &summary, &error));
  const exc::log::ChannelSummary& c = summary.channels.at(channel);
  CHECK(c.type_name == "timing_t");
  CHECK(c.messages == 11);
  CHECK(c.undecodable == 2);
  CHECK(c.min_utime == 1000);  // the first decoded message's, not a default of 0
  CHECK(c.max_utime == 9000);
  const auto rows = read_csv(dir / "csv" / exc::log::csv_file_name(channel));
  REQUIRE(rows.size() == 1 + 9);
  for (std::size_t r = 1; r < rows.size(); ++r) {
    CHECK(rows[r].size() == rows[0].size());
    CHECK(cell(rows, r, "seq") == static_cast<double>(r));
  }
}

TEST_CASE("tools/excavator-log takes stamps at int64's ends and channel names with control bytes from a damaged log") {
  // Stamps at the ends of int64: their differences wrapped (signed overflow: a negative duration, a
  // rate of "-", a detail window that never matched). A channel name holding ESC and a newline is
  // printed escaped, not sent to the terminal.
  const fs::path dir = exc::test::scratch_dir(fs::temp_directory_path() / ("exc-extremes-" + std::to_string(::getpid())));
  constexpr std::int64_t lo = std::numeric_limits<std::int64_t>::min(), hi = std::numeric_limits<std::int64_t>::max();
  const std::string odd = std::string("EXC\x1b[2J\nX");
  std::vector<Event> events{{odd, timing_message(0, 0), lo}};
  for (int k = 0; k < 3; ++k) {
    exlcm::controller_state_t state{};
    state.utime = k == 0 ? lo : (k == 1 ? 0 : hi);
    state.seq = k;
    state.mode = 3;                        // tracking: its errors count
    state.error[1] = k == 0 ? 0.5 : 0.01;  // the largest error at the lowest stamp
    events.push_back({"EXC_CONTROLLER/pid", encoded(state), k == 0 ? lo : (k == 1 ? 0 : hi)});
  }
  write_log(dir / "run.lcm", events);
  exc::log::LogSummary summary;
  std::string error;
  exc::log::ExportOptions options;
  options.bucket_rows = 1;  // a bucketed view and detail rows for three messages
  REQUIRE(exc::log::export_log_to_csv((dir / "run.lcm").string(), (dir / "csv").string(), &summary, &error, options));
  CHECK(summary.duration_s() == doctest::Approx(std::ldexp(1.0, 64) * 1e-6));
  // The detail window around the largest error (at int64's lowest stamp) holds its row.
  const auto detail = read_csv(dir / "csv" / "detail" / exc::log::csv_file_name("EXC_CONTROLLER/pid"));
  REQUIRE(detail.size() >= 2);
  CHECK(cell(detail, 1, "seq") == 0);
  const ToolRun run = run_excavator_log("info '" + (dir / "run.lcm").string() + "'", dir);
  INFO(run.out << run.err);
  CHECK(run.status == 0);
  CHECK(run.out.find("EXC\\x1B[2J\\x0AX") != std::string::npos);
  CHECK(run.out.find('\x1b') == std::string::npos);
  const std::vector<std::string> row = info_row(run.out, "EXC_CONTROLLER/pid");
  REQUIRE(row.size() == 5);
  CHECK(row[3] != "-");  // a rate over the span (~1.8e13 s), not a wrapped negative one
}

TEST_CASE("tools/excavator-log reads 300 seeded damaged logs without a crash, each event and byte accounted for") {
  // A log of every kind of message, damaged at random (bits flipped, 4 or 8 bytes overwritten with
  // extremes, cut short) and read by info and export in this process: a crash ends the test run.
  // Every event read is counted on its channel, no more bytes are unread than the file holds, and
  // export either succeeds or names the log.
  const fs::path dir = exc::test::scratch_dir(fs::temp_directory_path() / ("exc-log-mutants-" + std::to_string(::getpid())));
  std::vector<Event> events;
  for (int k = 0; k < 20; ++k) {
    const std::int64_t utime = 1000 * k, stamp = 1700000000000000 + k;
    exlcm::controller_state_t state{};
    state.utime = utime;
    state.mode = 3;
    state.error[0] = 0.001 * k;
    exlcm::machine_state_t machine{};
    machine.utime = utime;
    exlcm::fault_t fault{};
    fault.utime = utime;
    events.push_back({"EXC_CONTROLLER/pid", encoded(state), stamp});
    events.push_back({"EXC_STATE/pid", encoded(machine), stamp});
    events.push_back({"EXC_TIMING/pid", timing_message(utime, k), stamp});
    if (k % 5 == 0) events.push_back({"EXC_FAULT/pid", encoded(fault), stamp});
  }
  write_log(dir / "whole.lcm", events);
  const std::string whole = file_text(dir / "whole.lcm");
  std::vector<std::size_t> headers;  // where each event starts (LCM's format: 28 bytes, channel, data)
  std::size_t next = 0;
  for (const Event& e : events) {
    headers.push_back(next);
    next += 28 + e.channel.size() + e.data.size();
  }
  constexpr std::size_t kHeaderFields[] = {0, 4, 12, 20, 24};  // sync, number, stamp, channel and data length
  std::mt19937_64 random(20261125);
  const auto pick = [&](std::uint64_t n) { return static_cast<std::size_t>(random() % n); };
  // Lengths and stamps at their ends, a NaN, sync words.
  const std::uint64_t extremes64[] = {0, ~0ULL, 0x7FFFFFFFFFFFFFFFULL, 0x8000000000000000ULL, 0x7FF8000000000000ULL,
                                      0xEDA1DA01EDA1DA01ULL};
  const std::uint32_t extremes32[] = {0, 0xFFFFFFFFU, 0x7FFFFFFFU, 0x80000000U, 0xEDA1DA01U, 1000U};
  for (int m = 0; m < 300; ++m) {
    CAPTURE(m);
    std::string bytes = whole;
    const int edits = 1 + static_cast<int>(pick(12));
    for (int e = 0; e < edits; ++e) {
      // Half the overwrites on a header's field, where the reader's trust is tested.
      const std::size_t at = m % 4 != 0 && m % 4 != 3 && random() % 2 == 0
                                 ? headers[pick(headers.size())] + kHeaderFields[pick(std::size(kHeaderFields))]
                                 : pick(bytes.size() - 8);
      switch (m % 4) {
        case 0: bytes[at] = static_cast<char>(bytes[at] ^ (1 << pick(8))); break;
        case 1: {
          const std::uint32_t v = extremes32[pick(std::size(extremes32))];
          for (int i = 0; i < 4; ++i) bytes[at + i] = static_cast<char>(v >> (8 * (3 - i)));
          break;
        }
        case 2: {
          const std::uint64_t v = extremes64[pick(std::size(extremes64))];
          for (int i = 0; i < 8; ++i) bytes[at + i] = static_cast<char>(v >> (8 * (7 - i)));
          break;
        }
        default: bytes.resize(at + 1); e = edits; break;
      }
    }
    const fs::path log = dir / "damaged.lcm";
    std::ofstream(log, std::ios::binary | std::ios::trunc) << bytes;
    exc::log::LogSummary summary;
    std::string error;
    if (!exc::log::summarize_log(log.string(), &summary, &error)) {
      CHECK(error.find(log.string()) == 0);  // only a log with no event left is refused
      continue;
    }
    std::uint64_t on_channels = 0;
    for (const auto& [name, channel] : summary.channels) {
      on_channels += channel.messages;
      CHECK(channel.undecodable <= channel.messages);
    }
    CHECK(on_channels == summary.events);
    CHECK(summary.unread_bytes <= bytes.size());
    CHECK(std::isfinite(summary.duration_s()));
    exc::log::LogSummary exported;
    const bool ok = exc::log::export_log_to_csv(log.string(), (dir / "csv").string(), &exported, &error);
    CHECK_MESSAGE((ok || error.find(log.string()) == 0), error);
    CHECK(exported.events == summary.events);
  }
}

TEST_CASE("telemetry/export gives two channels of one CSV file name two files") {
  // EXC_TIMING/pid and EXC_TIMING__pid both map to EXC_TIMING__pid.csv: both were opened for writing
  // at once and their rows interleaved in one file. The second now gets EXC_TIMING__pid~2.csv.
  const fs::path dir = exc::test::scratch_dir(fs::temp_directory_path() / ("exc-same-name-" + std::to_string(::getpid())));
  std::vector<Event> events;
  for (int k = 0; k < 4; ++k) {
    events.push_back({"EXC_TIMING/pid", timing_message(1000 * k, k), 1700000000000000 + k});
    events.push_back({"EXC_TIMING__pid", timing_message(1000 * k, 100 + k), 1700000000000000 + k});
  }
  write_log(dir / "run.lcm", events);
  exc::log::LogSummary summary;
  std::string error;
  REQUIRE(exc::log::export_log_to_csv((dir / "run.lcm").string(), (dir / "csv").string(), &summary, &error));
  CHECK(summary.channels.at("EXC_TIMING/pid").csv_file == "EXC_TIMING__pid.csv");
  CHECK(summary.channels.at("EXC_TIMING__pid").csv_file == "EXC_TIMING__pid~2.csv");
  const auto first = read_csv(dir / "csv" / "EXC_TIMING__pid.csv");
  const auto second = read_csv(dir / "csv" / "EXC_TIMING__pid~2.csv");
  REQUIRE(first.size() == 5);
  REQUIRE(second.size() == 5);
  for (std::size_t r = 1; r < 5; ++r) {
    CHECK(cell(first, r, "seq") == static_cast<double>(r - 1));
    CHECK(cell(second, r, "seq") == static_cast<double>(100 + r - 1));
  }
}
