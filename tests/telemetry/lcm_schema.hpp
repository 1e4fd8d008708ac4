#pragma once
// A small reader of the project's .lcm definitions and of LCM's wire format, written for the tests
// from the LCM type specification: it gives the tests an account of every type that does not come
// from the code under test (lcm-gen's output or the exporter's field table).
#include <cstdint>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace exc::test {

struct LcmField {
  std::string type;  // int8_t, int16_t, int32_t, int64_t, float, double, boolean
  std::string name;
  int count = 1;     // fixed array length, 1 for a scalar
  bool is_array = false;
};

struct LcmStruct {
  std::string name;
  std::vector<LcmField> fields;
};

inline LcmStruct parse_lcm_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  std::string source = text.str();
  // Drop comments.
  source = std::regex_replace(source, std::regex("//[^\n]*"), "");
  LcmStruct result;
  std::smatch m;
  if (std::regex_search(source, m, std::regex(R"(struct\s+(\w+))"))) result.name = m[1];
  const std::regex field(R"((int8_t|int16_t|int32_t|int64_t|float|double|boolean)\s+(\w+)\s*(\[\s*(\d+)\s*\])?\s*;)");
  for (auto it = std::sregex_iterator(source.begin(), source.end(), field);
       it != std::sregex_iterator(); ++it) {
    LcmField f;
    f.type = (*it)[1];
    f.name = (*it)[2];
    if ((*it)[4].matched) {
      f.count = std::stoi((*it)[4]);
      f.is_array = true;
    }
    result.fields.push_back(f);
  }
  return result;
}

inline int wire_size_of(const std::string& type) {
  if (type == "int8_t" || type == "boolean") return 1;
  if (type == "int16_t") return 2;
  if (type == "int32_t" || type == "float") return 4;
  return 8;
}

// The CSV header the exporter must write for a struct (after its log_utime column).
inline std::vector<std::string> expected_columns(const LcmStruct& s) {
  std::vector<std::string> columns;
  for (const auto& f : s.fields) {
    if (f.name == "text" && f.type == "int8_t" && f.is_array) {
      columns.push_back(f.name);  // a char array is one text column
    } else if (!f.is_array) {
      columns.push_back(f.name);
    } else {
      for (int i = 0; i < f.count; ++i) columns.push_back(f.name + "_" + std::to_string(i));
    }
  }
  return columns;
}

inline std::uint64_t read_big_endian(const std::uint8_t* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = v << 8 | p[i];
  return v;
}

inline void write_big_endian(std::vector<std::uint8_t>& out, std::uint64_t v, int bytes) {
  for (int i = bytes - 1; i >= 0; --i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

}  // namespace exc::test
