#include "candump_log.hpp"

#include <cctype>
#include <cstdio>

namespace exc::test {
namespace {

using hal::kCanFdMaxLength;
using hal::kCanMaxLength;
using hal::valid_length;

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool fail(std::string& error, const std::string& what, std::size_t column) {
  error = what + " at column " + std::to_string(column + 1);
  return false;
}

}  // namespace

bool parse_candump_line(const std::string& line, CandumpLine& out, std::string& error) {
  out = CandumpLine{};
  std::size_t i = 0;
  if (line.empty() || line[0] != '(') return fail(error, "expected '(' opening the time stamp", 0);
  ++i;
  // Seconds up to 9e9 (the year 2255): their nanoseconds fit an int64, and more digits would overflow.
  constexpr std::int64_t kMaxSeconds = 9'000'000'000;
  std::int64_t seconds = 0;
  std::size_t digits = 0;
  while (i < line.size() && std::isdigit(static_cast<unsigned char>(line[i]))) {
    if (seconds > kMaxSeconds) return fail(error, "time stamp beyond 9e9 s", 1);
    seconds = seconds * 10 + (line[i++] - '0');
    ++digits;
  }
  if (seconds > kMaxSeconds) return fail(error, "time stamp beyond 9e9 s", 1);
  if (digits == 0 || i >= line.size() || line[i] != '.') return fail(error, "expected seconds.fraction time stamp", i);
  ++i;
  std::int64_t fraction_ns = 0;
  std::int64_t scale = 100'000'000;
  digits = 0;
  while (i < line.size() && std::isdigit(static_cast<unsigned char>(line[i]))) {
    fraction_ns += (line[i++] - '0') * scale;
    scale /= 10;
    ++digits;
  }
  if (digits == 0 || digits > 9 || i >= line.size() || line[i] != ')') return fail(error, "bad time stamp fraction", i);
  out.frame.timestamp_ns = seconds * 1'000'000'000 + fraction_ns;
  ++i;
  if (i >= line.size() || line[i] != ' ') return fail(error, "expected ' ' after the time stamp", i);
  ++i;
  const std::size_t name_start = i;
  while (i < line.size() && line[i] != ' ') ++i;
  if (i == name_start || i >= line.size()) return fail(error, "expected an interface name and ' '", name_start);
  out.interface_name = line.substr(name_start, i - name_start);
  ++i;

  const std::size_t id_start = i;
  std::uint32_t id = 0;
  while (i < line.size() && line[i] != '#') {
    const int v = hex_value(line[i]);
    if (v < 0) return fail(error, "bad hex digit in the identifier", i);
    id = (id << 4) | static_cast<std::uint32_t>(v);
    ++i;
  }
  const std::size_t id_digits = i - id_start;
  if (i >= line.size()) return fail(error, "expected '#' after the identifier", i);
  if (id_digits == 3) {
    if (id > 0x7FF) return fail(error, "standard identifier above 0x7FF", id_start);
  } else if (id_digits == 8) {
    out.extended = true;
    if (id > 0x1FFFFFFF) return fail(error, "extended identifier above 0x1FFFFFFF", id_start);
  } else {
    return fail(error, "identifier must have 3 (standard) or 8 (extended) hex digits", id_start);
  }
  out.frame.id = id;
  ++i;  // '#'
  if (i < line.size() && line[i] == '#') {
    out.frame.fd = true;
    ++i;
    const int flags = i < line.size() ? hex_value(line[i]) : -1;
    if (flags < 0) return fail(error, "expected a hex digit of CAN FD flags after '##'", i);
    out.fd_flags = static_cast<std::uint8_t>(flags);
    out.frame.brs = (flags & 1) != 0;
    ++i;
  } else if (i < line.size() && (line[i] == 'R' || line[i] == 'r')) {
    out.remote = true;
    return true;
  }
  const std::size_t data_start = i;
  std::size_t bytes = 0;
  while (i < line.size() && line[i] != ' ' && line[i] != '\r' && line[i] != '\n') {
    if (line[i] == '.') {  // optional byte separator
      ++i;
      continue;
    }
    const int high = hex_value(line[i]);
    const int low = i + 1 < line.size() ? hex_value(line[i + 1]) : -1;
    if (high < 0 || low < 0) return fail(error, "data must be pairs of hex digits", i);
    if (bytes >= static_cast<std::size_t>(out.frame.fd ? kCanFdMaxLength : kCanMaxLength)) {
      return fail(error, "too many data bytes", i);
    }
    out.frame.data[bytes++] = static_cast<std::uint8_t>(high * 16 + low);
    i += 2;
  }
  out.frame.len = static_cast<std::uint8_t>(bytes);
  if (!valid_length(out.frame.len, out.frame.fd)) {
    return fail(error, std::to_string(bytes) + " data bytes is not a CAN FD length (0..8, 12, 16, 20, 24, 32, 48, 64)",
                data_start);
  }
  return true;
}

std::string candump_line(const hal::CanFrame& frame, const std::string& interface_name, std::int64_t timestamp_ns) {
  char text[64];
  std::snprintf(text, sizeof text, "(%lld.%06lld) ", static_cast<long long>(timestamp_ns / 1'000'000'000),
                static_cast<long long>((timestamp_ns % 1'000'000'000) / 1000));
  std::string line = text;
  line += interface_name;
  if (frame.fd) {
    std::snprintf(text, sizeof text, " %03X##%X", frame.id, frame.brs ? 1u : 0u);
  } else {
    std::snprintf(text, sizeof text, " %03X#", frame.id);
  }
  line += text;
  for (int b = 0; b < frame.len; ++b) {
    std::snprintf(text, sizeof text, "%02X", frame.data[b]);
    line += text;
  }
  return line;
}

}  // namespace exc::test
