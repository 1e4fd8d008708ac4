#include "hal/candump_log.hpp"

#include <cctype>

namespace exc::hal {
namespace {

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
  std::int64_t seconds = 0;
  std::size_t digits = 0;
  while (i < line.size() && std::isdigit(static_cast<unsigned char>(line[i]))) {
    seconds = seconds * 10 + (line[i++] - '0');
    ++digits;
  }
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
    out.fd = true;
    i += 2;  // '#' and the FD flags nibble
    if (i > line.size()) return fail(error, "expected CAN FD flags after '##'", i);
  } else if (i < line.size() && (line[i] == 'R' || line[i] == 'r')) {
    out.remote = true;
    return true;
  }
  std::size_t bytes = 0;
  while (i < line.size() && line[i] != ' ' && line[i] != '\r' && line[i] != '\n') {
    if (line[i] == '.') {  // optional byte separator
      ++i;
      continue;
    }
    const int high = hex_value(line[i]);
    const int low = i + 1 < line.size() ? hex_value(line[i + 1]) : -1;
    if (high < 0 || low < 0) return fail(error, "data must be pairs of hex digits", i);
    if (bytes >= (out.fd ? 64u : 8u)) return fail(error, "too many data bytes", i);
    if (bytes < 8) out.frame.data[bytes] = static_cast<std::uint8_t>(high * 16 + low);
    ++bytes;
    i += 2;
  }
  out.frame.dlc = static_cast<std::uint8_t>(bytes < 8 ? bytes : 8);
  if (bytes > 8) out.frame.dlc = 9;  // an FD payload longer than classical: never a valid protocol frame
  return true;
}

}  // namespace exc::hal
