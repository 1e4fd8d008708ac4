#pragma once
// A load-time error of the firmware's own scene sections (`controller:` and `task:`): which file,
// which field (dotted path, e.g. "controller.kp[2]" or "task.path[3]") and why, with the allowed
// range. Thrown only at start-up, never from the control step.
#include <stdexcept>
#include <string>

namespace exc::control {

class ConfigError : public std::runtime_error {
 public:
  ConfigError(std::string file, std::string field, std::string reason)
      : std::runtime_error(file + ": " + field + ": " + reason),
        file_(std::move(file)), field_(std::move(field)), reason_(std::move(reason)) {}
  const std::string& file() const { return file_; }
  const std::string& field() const { return field_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string file_, field_, reason_;
};

}  // namespace exc::control
