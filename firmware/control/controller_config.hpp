#pragma once
// The scene's `controller:` section (gains, Lyapunov weights, adaptation rates, soil-parameter
// bounds, filter cut-offs, watchdog), parsed and validated at start-up. Every field is optional:
// a scene without `controller:` gets the embedded defaults below (docs/control.md lists them).
// Errors (ConfigError) name the file, the field and the allowed range. Start-up code: allocates.
#include <string>

#include "control/config_error.hpp"
#include "control/control_types.hpp"
#include "control/pid.hpp"
#include "control/state_estimator.hpp"

namespace YAML {
class Node;
}

namespace exc::control {

// Where the adaptive law's regressor takes the joint acceleration for the soil's M_t rhodd term.
enum class RegressorAcceleration : std::uint8_t { filtered = 0, desired = 1 };

struct ControllerConfig {
  ControllerKind kind = ControllerKind::adaptive;
  double period = 1e-3;  // s, the control period (update law integrated at it)

  // Computed-torque error dynamics e'' + kv e' + kp e (+ ki int e for the PID baseline).
  // Order: swing (rad), boom, arm, bucket (m).
  PidGains gains = default_gains();

  // Adaptive law (eqs. 21-28): Q of A^T P + P A + Q = 0, diagonal, x = [e; ed] order.
  Vec8 lyapunov_q = (Vec8() << 1, 1, 1, 1, 1, 1, 1, 1).finished();
  // Adaptation rates Gamma^-1 = diag(rate); Theta = [M_x B_x K_x M_z B_z K_z].
  Vec6 adaptation_rate = (Vec6() << 2e7, 2e10, 1e12, 2e7, 2e10, 1e12).finished();
  // Physical bounds of the soil parameters (machine.md): M 50..500 kg, B 1e3..3e4 N s/m,
  // K 1e4..1e6 N/m; and the initial estimate.
  Vec6 theta_min = (Vec6() << 50, 1e3, 1e4, 50, 1e3, 1e4).finished();
  Vec6 theta_max = (Vec6() << 500, 3e4, 1e6, 500, 3e4, 1e6).finished();
  Vec6 theta_initial = (Vec6() << 100, 2e3, 3e4, 100, 2e3, 3e4).finished();
  RegressorAcceleration regressor_acceleration = RegressorAcceleration::filtered;

  // Slotine-Li: s = ed + lambda e; tau = ... - kd s (kd in 1/s, scaled by M_a: see slotine_li.hpp).
  Vec4 sl_lambda = Vec4::Constant(20);
  Vec4 sl_kd = Vec4::Constant(20);
  Vec6 sl_adaptation_rate = (Vec6() << 1e3, 1e5, 1e7, 1e3, 1e5, 1e7).finished();

  EstimatorConfig filter;           // velocity / acceleration cut-offs
  double watchdog_timeout = 0.02;   // s without a valid sensor frame -> safe_stop
  double blend_time = 0.2;          // s, bumpless switch fade

  static PidGains default_gains() {
    PidGains g;
    g.kp = Vec4::Constant(400);   // 1/s^2: omega_n = 20 rad/s
    g.kv = Vec4::Constant(40);    // 1/s:   critically damped
    g.ki = Vec4::Constant(1000);  // 1/s^3: kv kp = 16000 > ki, stable
    g.integral_limit = Vec4::Constant(0.05);
    return g;
  }
};

// Parses the `controller:` node (which may be null/undefined: defaults). 'file' is named in errors.
ControllerConfig parse_controller_config(const YAML::Node& controller, const std::string& file);
// Reads a scene (or controller) file and parses its `controller:` section.
ControllerConfig load_controller_config(const std::string& path);
// Checks cross-field rules (min < initial < max, Hurwitz gains, ...); throws ConfigError.
void validate(const ControllerConfig& c, const std::string& file);

}  // namespace exc::control
