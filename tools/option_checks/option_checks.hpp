#pragma once
// The programs' command lines: the parse with their exit convention, and checks of numeric options
// with the settings files' wording ("is -1 s; allowed range [0.001, 28800] s"). CLI11's own Range and
// PositiveNumber let "nan" through (every comparison with NaN is false), and a NaN duration then
// reads as "not given": a silent default. These refuse it.
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "settings/section_reader.hpp"

namespace exc::cli {

// Parses the command line. --help prints and gives 0; an error CLI11 finds (an unknown option, a value
// out of range or not a number, a missing argument) prints its message and gives 2, the status of
// every refused input (CLI11's own codes are 100-114). Nothing: the program goes on.
//   if (const auto status = exc::cli::parse_command_line(app, argc, argv)) return *status;
inline std::optional<int> parse_command_line(CLI::App& app, int argc, const char* const* argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  return std::nullopt;
}

// A finite number in [bounds.lo, bounds.hi] (inclusive), in `unit`.
inline CLI::Validator number_in(settings::Bounds bounds, const std::string& unit) {
  const std::string range = "[" + settings::format_number(bounds.lo) + ", " + settings::format_number(bounds.hi) +
                            "]" + (unit.empty() ? "" : " " + unit);
  return CLI::Validator(
      [bounds, range, unit](std::string& text) -> std::string {
        char* end = nullptr;
        errno = 0;
        const double v = std::strtod(text.c_str(), &end);
        if (text.empty() || end == text.c_str() || *end != '\0') return "'" + text + "' is not a number";
        if (!std::isfinite(v) || v < bounds.lo || v > bounds.hi)
          return "is " + text + (unit.empty() ? "" : " " + unit) + "; allowed range " + range;
        return {};
      },
      "NUMBER in " + range);
}

// A whole number in [lo, hi].
inline CLI::Validator count_in(long lo, long hi) {
  const std::string range = "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        char* end = nullptr;
        errno = 0;
        const long v = std::strtol(text.c_str(), &end, 10);
        if (text.empty() || end == text.c_str() || *end != '\0' || errno == ERANGE)
          return "'" + text + "' is not a whole number";
        if (v < lo || v > hi) return "is " + text + "; allowed range " + range;
        return {};
      },
      "INT in " + range);
}

}  // namespace exc::cli
