#pragma once
// What every controller takes and returns, and the interface the firmware loop calls
// (ros2_control's update(): the loop reads sensors, calls update(), writes the command).
// All fixed-size; update() never allocates, throws or blocks.
#include <array>
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "model/model_status.hpp"
#include "model/terrain.hpp"
#include "model/types.hpp"

namespace exc::control {

// What the controller knows about the soil beyond its own state (model.md s.5, s.6).
struct SoilContext {
  // The site map (the scene's ground, flat or a profile) the contact estimate may use; null: none,
  // contact is then told by the external force alone (soil_contact.hpp).
  const Terrain* site_map = nullptr;
  // false (the firmware): the controller estimates contact and the anchor rho_env itself
  // (soil_contact.hpp). true (simulation truth, tests): take them below.
  bool anchor_given = false;
  bool in_soil = false;
  Vec2 rho_env = Vec2::Zero();  // anchor (x, z world height) in the swing plane (m)
  // True soil parameters [M_x B_x K_x M_z B_z K_z] when the caller knows them (the simulator, for
  // telemetry and the Lyapunov test); V then includes the parameter-error term.
  bool theta_known = false;
  Vec6 theta = Vec6::Zero();
};

struct AppliedEffort {
  Vec4 effort = Vec4::Zero();  // N m (swing), N
  bool valid = false;          // false: nothing known yet (no command sent, no pressures)
  bool measured = false;       // from chamber pressures (true) or the command's model (false)
  // Bit j: joint j's effort is known not to follow the law's model this cycle (its valve fully open,
  // a chamber at its relief or at the make-up valve, the pumps short of flow, its command clamped):
  // the update leaves the joint out and the observer holds its estimate there.
  std::uint8_t suspect = 0;
};

struct ControlInput {
  double t = 0;                  // s
  Vec4 q = Vec4::Zero();         // measured q_a
  Vec4 qd = Vec4::Zero();        // measured (filtered) qd_a
  Vec4 qd_measured = Vec4::Zero();  // qd_a as the sensors sent it (unfiltered; the composite update's regressor)
  Vec4 qdd = Vec4::Zero();       // filtered qdd_a (state_estimator.hpp); only the adaptive law uses it
  Vec4 q_d = Vec4::Zero(), qd_d = Vec4::Zero(), qdd_d = Vec4::Zero();  // desired
  SoilContext soil;
  // Bit j set: downstream of the law joint j's command was not delivered last cycle (the actuator-lag
  // lead clamped it to its effort limit, or the valve stage opened the valve fully): the adaptive
  // laws leave the joint out of their update and the integrators hold (anti-windup).
  std::uint8_t actuator_limited = 0;
  // The efforts the machine applied over the last cycle, as the firmware knows them (beyond the
  // paper): measured from the chamber pressures on a hydraulic machine, else the delivered-effort model
  // of what was commanded (a force-commanded machine has no pressures). The external force observer
  // and the composite update read them (external_force_observer.hpp).
  AppliedEffort applied;
};

struct ControlOutput {
  Vec4 tau = Vec4::Zero();            // saturated effort sent to the actuators
  Vec4 tau_unsaturated = Vec4::Zero();
  std::uint8_t saturated = 0;         // bit j set: joint j hit its effort limit this step
  Vec4 e = Vec4::Zero(), ed = Vec4::Zero();  // q_a - q_d, qd_a - qd_d
  Vec6 theta_hat = Vec6::Zero();      // soil estimate (zero for the PID baseline)
  double lyapunov = 0;                // V (see each controller); includes Theta~ only if theta_known
  double lyapunov_tracking = 0;       // the tracking-error part of V alone
  bool in_soil = false;               // contact as the controller sees it
  Vec2 rho = Vec2::Zero(), rho_env = Vec2::Zero();  // tip and anchor as the controller sees them
  // The external effort observer (laws with one): the part of the applied effort the model and the soil
  // prediction do not explain, as estimated (its low-pass), and the soil force at the tip it implies.
  Vec4 disturbance = Vec4::Zero();     // N m, N
  Vec2 tip_force = Vec2::Zero();       // N, external force on the bucket (x, z)
  ModelStatus status = ModelStatus::ok;  // not ok: tau is the last good command held (never NaN)
  // Flow laws (FlowPositionControl) command each valve's flow instead of an effort: the velocity it
  // should pass (m/s; swing rad/s). Effort laws leave velocity_command false and command tau.
  bool velocity_command = false;
  Vec4 velocity = Vec4::Zero();
};

// What a law shows of its inner state, value by value (the firmware's scan for subnormal numbers,
// docs/floating-point.md), so the firmware reads a law's memory without knowing the law.
//
// The one shape of a state visitor, shared by the firmware and the plant: visit(name, values, count)
// and its three conveniences (one double, a std::array of doubles, a fixed-size Eigen matrix). The
// state types visit themselves beside their declarations with a function template
// visit_state(const T&, Visitor&) that calls only these four (hal::SensorState, hal::CommandState,
// app::DesiredMotion, ControlOutput below, exc::Workspace, the plant's PlantState and its parts), so a
// floor below this one (hal, the model, the plant) needs no header of ours to be visited; the laws,
// whose state is behind an interface, take this class. diagnostics::SubnormalScan
// (firmware/diagnostics/subnormal_scan.hpp) has the same four, for the plant's node, which may not
// include this floor (docs/architecture.md). A name is a string literal: visitors keep the pointer.
class StateVisitor {
 public:
  virtual void visit(const char* name, const double* values, std::size_t count) = 0;
  template <typename Derived>
  void visit(const char* name, const Eigen::PlainObjectBase<Derived>& values) {
    static_assert(std::is_same_v<typename Derived::Scalar, double>, "a state visitor reads doubles");
    visit(name, values.data(), static_cast<std::size_t>(values.size()));
  }
  template <std::size_t N>
  void visit(const char* name, const std::array<double, N>& values) { visit(name, values.data(), N); }
  void visit(const char* name, const double& value) { visit(name, &value, 1); }

 protected:
  ~StateVisitor() = default;
};

// A law's output, which the node keeps from one cycle to the next.
template <typename Visitor>
void visit_state(const ControlOutput& out, Visitor& v) {
  v.visit("law tau", out.tau);
  v.visit("law tau_unsaturated", out.tau_unsaturated);
  v.visit("law e", out.e);
  v.visit("law ed", out.ed);
  v.visit("law theta_hat", out.theta_hat);
  v.visit("law lyapunov", out.lyapunov);
  v.visit("law lyapunov_tracking", out.lyapunov_tracking);
  v.visit("law rho", out.rho);
  v.visit("law rho_env", out.rho_env);
  v.visit("law velocity (flow law)", out.velocity);
  v.visit("law disturbance (observer)", out.disturbance);
  v.visit("law tip_force", out.tip_force);
}

class Controller {
 public:
  virtual ~Controller() = default;
  // Forget integrators and adaptation state; theta_hat restarts at the configured initial value.
  virtual void reset() = 0;
  virtual ControlOutput update(const ControlInput& in) = 0;
  // The state the law carries from cycle to cycle beyond its ControlOutput (integrals, filters,
  // estimates); a law without any shows nothing. Allocation-free.
  virtual void visit_state(StateVisitor& visitor) const { (void)visitor; }
};

}  // namespace exc::control
