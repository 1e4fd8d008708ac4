#include "settings/settings_error.hpp"

namespace exc::settings {
namespace {

std::string format_what(const std::string& file, int line, int column, const std::string& field,
                        const std::string& reason) {
  std::string s = file;
  if (line > 0) s += ":" + std::to_string(line) + ":" + std::to_string(column);
  s += ": ";
  if (!field.empty()) s += field + ": ";
  return s + reason;
}

}  // namespace

SettingsError::SettingsError(std::string file, int line, int column, std::string field, std::string reason)
    : std::runtime_error(format_what(file, line, column, field, reason)),
      file_(std::move(file)),
      line_(line),
      column_(column),
      field_(std::move(field)),
      reason_(std::move(reason)) {}

}  // namespace exc::settings
