#pragma once
// Holding a settings error to what a user must see: the file, the line and column of the offending
// text, the field's dotted path and the reason (with the allowed range or values), and what() made
// of them as "file:line:column: field: reason". The place is found independently of the reader:
// the first occurrence of `at` in the text the reader was given.
#include <doctest/doctest.h>

#include <algorithm>
#include <string>
#include <utility>

#include "settings/settings_error.hpp"

namespace exc::test {

// 1-based line and column of the first occurrence of `at` in `text` (it must occur).
inline std::pair<int, int> place_of(const std::string& text, const std::string& at) {
  const auto pos = text.find(at);
  REQUIRE_MESSAGE(pos != std::string::npos, "'" << at << "' not in the text");
  const auto line_start = text.rfind('\n', pos == 0 ? 0 : pos - 1);
  const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(pos), '\n'));
  const int column = static_cast<int>(pos - (line_start == std::string::npos || pos == 0 ? 0 : line_start + 1)) + 1;
  return {line, column};
}

inline void check_settings_error(const SettingsError& e, const std::string& file, const std::string& text,
                                 const std::string& field, const std::string& at, const std::string& reason_part) {
  const std::string what = e.what();
  CAPTURE(what);
  const auto [line, column] = place_of(text, at);
  CHECK(e.file() == file);
  CHECK(e.field() == field);
  CHECK(e.line() == line);
  CHECK(e.column() == column);
  CHECK(e.reason().find(reason_part) != std::string::npos);
  CHECK(what == file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " +
                    (field.empty() ? "" : field + ": ") + e.reason());
}

}  // namespace exc::test
