// excavator-log's export: every column named as in the .lcm files, every value read back exactly.
// The expected values come from the test's own encoder of LCM's wire format (lcm_schema.hpp), not
// from lcm-gen's classes or the exporter's field table.
#include <doctest/doctest.h>

#include <lcm/lcm-cpp.hpp>

#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
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
