#pragma once
// The cycle's control computation, between the mode's step and the bus write: the state estimate,
// the control law on the path's (or the hold's) desired motion, the stages after the law (blend and
// lag lead, or the valve stage) and the supervisor's checks of each (the law's output, the
// pressures, the flow and the spools), each stage timed into the loop's counters. FirmwareNode owns
// one and calls it once a cycle; nothing here allocates after construction.
#include <cstdint>
#include <memory>

#include "diagnostics/loop_counters.hpp"
#include "control/actuation/actuation_stage.hpp"
#include "control/control_types.hpp"
#include "control/controller_config.hpp"
#include "control/estimation/state_estimator.hpp"
#include "hal/excavator_interface.hpp"
#include "model/model.hpp"
#include "safety/supervisor.hpp"

namespace exc::app {

struct FirmwareNodeConfig;

// The desired motion of this cycle (the path's, or the hold's with zero rates).
struct DesiredMotion {
  Vec4 q = Vec4::Zero(), qd = Vec4::Zero(), qdd = Vec4::Zero();
};

// Its values to a state visitor (control::StateVisitor's shape), for the subnormal scan.
template <typename Visitor>
void visit_state(const DesiredMotion& d, Visitor& v) {
  v.visit("desired q", d.q);
  v.visit("desired qd", d.qd);
  v.visit("desired qdd", d.qdd);
}

// Builds the law as ControlStep does and drops it: a law the command interface cannot carry, or gains
// the law refuses, are named before a program opens its bus (start-up code: allocates, throws).
void check_control_law(const Model& model, const control::ControllerConfig& config);

class ControlStep {
 public:
  // Builds the law (refused with std::invalid_argument when the command interface cannot carry it).
  ControlStep(const Model& model, const FirmwareNodeConfig& config, safety::Supervisor& supervisor, diagnostics::LoopCounters& counters);
  ~ControlStep();
  ControlStep(const ControlStep&) = delete;
  ControlStep& operator=(const ControlStep&) = delete;

  // Not commanding (no valid sensors, or a fault): the safe state's centred valves into `command`.
  void centre(double t, const hal::SensorState& sensors, hal::CommandState& command);
  // Commanding, first half: the estimate (restarted: entering hold/track after a stop or at start,
  // the estimator, the law and the stages after it start again).
  void estimate(const hal::SensorState& sensors, bool restarted);
  // Commanding, second half: the law on `desired`, the stages after it and the supervisor's checks;
  // the command to send into `command` (whose last value is what the bus carried last cycle).
  // mode_changed_from_commanding: entering this mode from another commanding one (a bumpless blend).
  void update(double t, safety::Mode mode, bool mode_entered, bool from_commanding, bool complete, const hal::SensorState& sensors,
              const DesiredMotion& desired, hal::CommandState& command);

  std::int8_t controller_id() const { return controller_id_; }
  const control::ControlOutput& output() const { return out_; }
  const control::ActuationStage& stage() const { return stage_; }
  const control::StateEstimator& estimator() const { return estimator_; }
  // The estimator's, the law's and the stages' state, for the subnormal scan.
  void visit_state(control::StateVisitor& v) const;

 private:
  const FirmwareNodeConfig& config_;
  safety::Supervisor& supervisor_;
  diagnostics::LoopCounters& counters_;
  std::unique_ptr<control::Controller> controller_;
  std::int8_t controller_id_;  // the law's number in telemetry (ControllerRegistry::id_of)
  control::StateEstimator estimator_;
  control::ActuationStage stage_;
  control::ControlOutput out_;
  bool restarted_ = false;
  std::int64_t start_ns_ = 0;
};

}  // namespace exc::app
