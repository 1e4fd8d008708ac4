#pragma once
// The one load-time error of every settings file (machine, scene, sweep spec): which file, where in
// it (line and column, 1-based; 0 when the value was not read from a file) and which field (dotted
// path, e.g. "bodies.boom.mass", "task.path[3].x"), and why, with the allowed range or values.
//   what() = "file:line:column: field: reason"   ("file: field: reason" without a place)
// Thrown only at start-up, never from a control or plant step.
#include <stdexcept>
#include <string>

namespace exc::settings {

class SettingsError : public std::runtime_error {
 public:
  SettingsError(std::string file, int line, int column, std::string field, std::string reason);
  const std::string& file() const { return file_; }
  int line() const { return line_; }
  int column() const { return column_; }
  const std::string& field() const { return field_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string file_;
  int line_ = 0, column_ = 0;
  std::string field_, reason_;
};

}  // namespace exc::settings

namespace exc {
using settings::SettingsError;
}
