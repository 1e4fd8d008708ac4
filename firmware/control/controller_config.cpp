#include "control/controller_config.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>

#include "control/config_fields.hpp"
#include "control/controller_kinds.hpp"

namespace exc::control {
namespace {

template <int N>
Eigen::Matrix<double, N, 1> read_vector(const YAML::Node& n, const std::string& file,
                                        const std::string& field, double lo, double hi) {
  if (!n.IsSequence() || static_cast<int>(n.size()) != N)
    throw ConfigError(file, field, "must be a list of " + std::to_string(N) + " numbers in " +
                                       format_number(lo) + " .. " + format_number(hi));
  Eigen::Matrix<double, N, 1> v;
  for (int i = 0; i < N; ++i)
    v[i] = read_number(n[i], file, field + "[" + std::to_string(i) + "]", lo, hi);
  return v;
}

}  // namespace

const char* to_string(ControllerKind kind) {
  for (const ControllerKindEntry& e : kControllerKinds)
    if (e.kind == kind) return e.name;
  return "unknown";
}

ControllerConfig parse_controller_config(const YAML::Node& node, const std::string& file) {
  ControllerConfig c;
  if (!node.IsDefined() || node.IsNull()) return c;
  const std::string s = "controller";
  if (!node.IsMap()) throw ConfigError(file, s, "must be a mapping of controller settings");
  reject_unknown_keys(node, file, s,
                 {"type", "period", "kp", "kv", "ki", "integral_limit", "lyapunov_q",
                  "adaptation_rate", "theta_min", "theta_max", "theta_initial",
                  "regressor_acceleration", "slotine_li", "filters", "watchdog_timeout", "tracking_error_limit",
                  "blend_time", "actuator_lag", "actuator_lag_target", "integral_action",
                  "lyapunov_q_integral"});
  if (node["type"]) {
    const std::string t = node["type"].as<std::string>();
    const std::optional<ControllerKind> kind = controller_kind_named(t);
    if (!kind) throw ConfigError(file, s + ".type", "'" + t + "' (allowed: " + controller_kind_names() + ")");
    c.kind = *kind;
    c.kind_given = true;
  }
  if (node["period"]) c.period = read_number(node["period"], file, s + ".period", 1e-5, 0.1);
  if (node["kp"]) c.gains.kp = read_vector<4>(node["kp"], file, s + ".kp", 1e-3, 1e6);
  if (node["kv"]) c.gains.kv = read_vector<4>(node["kv"], file, s + ".kv", 1e-3, 1e4);
  if (node["ki"]) c.gains.ki = read_vector<4>(node["ki"], file, s + ".ki", 0, 1e8);
  if (node["integral_limit"])
    c.gains.integral_limit = read_vector<4>(node["integral_limit"], file, s + ".integral_limit", 0, 1e3);
  if (node["lyapunov_q"]) c.lyapunov_q = read_vector<8>(node["lyapunov_q"], file, s + ".lyapunov_q", 1e-9, 1e9);
  if (node["adaptation_rate"])
    c.adaptation_rate = read_vector<6>(node["adaptation_rate"], file, s + ".adaptation_rate", 0, 1e16);
  if (node["theta_min"]) c.theta_min = read_vector<6>(node["theta_min"], file, s + ".theta_min", 0, 1e8);
  if (node["theta_max"]) c.theta_max = read_vector<6>(node["theta_max"], file, s + ".theta_max", 0, 1e8);
  if (node["theta_initial"])
    c.theta_initial = read_vector<6>(node["theta_initial"], file, s + ".theta_initial", 0, 1e8);
  if (node["regressor_acceleration"]) {
    const std::string r = node["regressor_acceleration"].as<std::string>();
    if (r == "filtered") c.regressor_acceleration = RegressorAcceleration::filtered;
    else if (r == "desired") c.regressor_acceleration = RegressorAcceleration::desired;
    else throw ConfigError(file, s + ".regressor_acceleration", "'" + r + "' (allowed: filtered, desired)");
  }
  if (const YAML::Node sl = node["slotine_li"]) {
    if (!sl.IsMap()) throw ConfigError(file, s + ".slotine_li", "must be a mapping with lambda, kd");
    reject_unknown_keys(sl, file, s + ".slotine_li", {"lambda", "kd", "adaptation_rate"});
    if (sl["lambda"]) c.sl_lambda = read_vector<4>(sl["lambda"], file, s + ".slotine_li.lambda", 1e-3, 1e4);
    if (sl["adaptation_rate"])
      c.sl_adaptation_rate =
          read_vector<6>(sl["adaptation_rate"], file, s + ".slotine_li.adaptation_rate", 0, 1e16);
    if (sl["kd"]) c.sl_kd = read_vector<4>(sl["kd"], file, s + ".slotine_li.kd", 1e-3, 1e4);
  }
  if (const YAML::Node f = node["filters"]) {
    if (!f.IsMap()) throw ConfigError(file, s + ".filters", "must be a mapping");
    reject_unknown_keys(f, file, s + ".filters", {"velocity_cutoff_hz", "acceleration_cutoff_hz"});
    if (f["velocity_cutoff_hz"])
      c.filter.velocity_cutoff_hz = read_number(f["velocity_cutoff_hz"], file, s + ".filters.velocity_cutoff_hz", 0.1, 1e4);
    if (f["acceleration_cutoff_hz"])
      c.filter.acceleration_cutoff_hz =
          read_number(f["acceleration_cutoff_hz"], file, s + ".filters.acceleration_cutoff_hz", 0.1, 1e4);
  }
  if (node["tracking_error_limit"])
    c.tracking_error_limit = read_vector<4>(node["tracking_error_limit"], file, s + ".tracking_error_limit", 1e-4, 10);
  if (node["watchdog_timeout"])
    c.watchdog_timeout = read_number(node["watchdog_timeout"], file, s + ".watchdog_timeout", 1e-4, 10);
  if (node["blend_time"]) c.blend_time = read_number(node["blend_time"], file, s + ".blend_time", 0, 10);
  if (node["integral_action"]) {
    const YAML::Node n = node["integral_action"];
    try {
      c.integral_action = n.as<bool>();
    } catch (const YAML::Exception&) {
      throw ConfigError(file, s + ".integral_action", "'" + n.as<std::string>() + "' (allowed: true, false)");
    }
  }
  if (node["lyapunov_q_integral"])
    c.lyapunov_q_integral = read_vector<4>(node["lyapunov_q_integral"], file, s + ".lyapunov_q_integral", 1e-9, 1e9);
  if (node["actuator_lag"]) c.actuator_lag = read_number(node["actuator_lag"], file, s + ".actuator_lag", 0, 1);
  if (node["actuator_lag_target"])
    c.actuator_lag_target = read_number(node["actuator_lag_target"], file, s + ".actuator_lag_target", 1e-4, 1);
  c.filter.period = c.period;
  validate(c, file);
  return c;
}

void validate(const ControllerConfig& c, const std::string& file) {
  const std::string s = "controller";
  for (int i = 0; i < 6; ++i) {
    const std::string idx = "[" + std::to_string(i) + "]";
    if (!(c.theta_min[i] < c.theta_max[i]))
      throw ConfigError(file, s + ".theta_min" + idx,
                        format_number(c.theta_min[i]) + " must be below theta_max" + idx + " = " + format_number(c.theta_max[i]));
    if (c.theta_initial[i] < c.theta_min[i] || c.theta_initial[i] > c.theta_max[i])
      throw ConfigError(file, s + ".theta_initial" + idx,
                        format_number(c.theta_initial[i]) + " outside the bounds " + format_number(c.theta_min[i]) + " .. " +
                            format_number(c.theta_max[i]));
  }
  for (int j = 0; j < kNumActive; ++j) {
    // e''' + kv e'' + kp e' + ki e = 0 is Hurwitz iff kv kp > ki (Routh).
    if (!(c.gains.kv[j] * c.gains.kp[j] > c.gains.ki[j]))
      throw ConfigError(file, s + ".ki[" + std::to_string(j) + "]",
                        format_number(c.gains.ki[j]) + " makes the PID loop unstable: must be below kv*kp = " +
                            format_number(c.gains.kv[j] * c.gains.kp[j]));
  }
  // A target slower than the lag would lag more, not less; a lead gain above 20 amplifies the
  // measurement noise that reaches the command twentyfold.
  if (c.actuator_lag > 0 && !(c.actuator_lag_target <= c.actuator_lag && c.actuator_lag <= 20 * c.actuator_lag_target))
    throw ConfigError(file, s + ".actuator_lag_target",
                      format_number(c.actuator_lag_target) + " s must lie in actuator_lag / 20 .. actuator_lag = " +
                          format_number(c.actuator_lag / 20) + " .. " + format_number(c.actuator_lag) + " s");
  // The filters must sit below the Nyquist frequency of the control period.
  const double nyquist = 0.5 / c.period;
  if (!(c.filter.velocity_cutoff_hz < nyquist))
    throw ConfigError(file, s + ".filters.velocity_cutoff_hz",
                      format_number(c.filter.velocity_cutoff_hz) + " Hz must be below " + format_number(nyquist) + " Hz (Nyquist)");
  if (!(c.filter.acceleration_cutoff_hz < nyquist))
    throw ConfigError(file, s + ".filters.acceleration_cutoff_hz",
                      format_number(c.filter.acceleration_cutoff_hz) + " Hz must be below " + format_number(nyquist) + " Hz (Nyquist)");
}

ControllerConfig load_controller_config(const std::string& path) {
  const YAML::Node root = load_yaml_file(path);
  return parse_controller_config(root["controller"], path);
}

}  // namespace exc::control
