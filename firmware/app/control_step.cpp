#include "app/control_step.hpp"

#include <stdexcept>
#include <string>

#include "app/firmware_node_config.hpp"
#include "control/controller_registry.hpp"
#include "hal/clock.hpp"

namespace exc::app {
namespace {

Vec4 to_vec(const std::array<double, 4>& a) { return Vec4(a[0], a[1], a[2], a[3]); }

control::ChamberPressures pressures_of(const hal::SensorState& s) {
  return control::ChamberPressures{s.pressure_valid, to_vec(s.pressure_a), to_vec(s.pressure_b)};
}

// Refuses a law the command interface cannot carry (a flow law on the effort interface) before it
// is built: std::invalid_argument naming both.
std::unique_ptr<control::Controller> checked_controller(const Model& model, const control::ControllerConfig& config) {
  const control::ControllerEntry& law = control::controller_registry().at(config.law);
  if (const std::string why = control::interface_misfit(law, config.command_interface); !why.empty())
    throw std::invalid_argument("controller " + why + " (the scene's controller.command_interface is " +
                                control::kCommandInterfaces.name_of(config.command_interface) + ")");
  return law.make(model, config);
}

}  // namespace

void check_control_law(const Model& model, const control::ControllerConfig& config) { checked_controller(model, config); }

ControlStep::ControlStep(const Model& model, const FirmwareNodeConfig& config, safety::Supervisor& supervisor, diagnostics::LoopCounters& counters)
    : config_(config),
      supervisor_(supervisor),
      counters_(counters),
      controller_(checked_controller(model, config.controller)),
      controller_id_(control::controller_registry().id_of(config.controller.law)),
      estimator_(config.controller.filter),
      stage_(model.machine, config.controller.actuation, config.controller.command_interface, config.controller.period) {}

ControlStep::~ControlStep() = default;

void ControlStep::centre(double t, const hal::SensorState& sensors, hal::CommandState& command) {
  // The safe state is valves centred: zero cylinder flow and the swing brake; the plant holds the
  // machine where it is.
  command.mode = hal::CommandMode::valve;
  command.value = {0, 0, 0, 0};
  stage_.centre();
  supervisor_.update_pump_warning(t, false, 0);  // centred valves ask nothing
  supervisor_.idle_pressures();
  supervisor_.check_spools(t, false, to_vec(sensors.spool));  // the expectation follows the centring
  supervisor_.command_spools(Vec4::Zero());
}

void ControlStep::estimate(const hal::SensorState& sensors, bool restarted) {
  start_ns_ = hal::monotonic_now_ns();
  restarted_ = restarted;
  const Vec4 q = to_vec(sensors.position), qd = to_vec(sensors.velocity);
  if (restarted) {
    estimator_.reset(q, qd);
    controller_->reset();
    stage_.restart();
    supervisor_.restart_spools();
  } else {
    estimator_.update(q, qd);
  }
}

void ControlStep::update(double t, safety::Mode mode, bool mode_entered, bool from_commanding, bool complete,
                         const hal::SensorState& sensors, const DesiredMotion& desired, hal::CommandState& command) {
  const bool restarted = restarted_;
  const Vec4 q = to_vec(sensors.position), qd = to_vec(sensors.velocity);
  const control::ChamberPressures p = pressures_of(sensors);
  std::int64_t now_ns = hal::monotonic_now_ns(), monitors_ns = 0;
  counters_.estimate.record_ns(now_ns - start_ns_);  // the estimate and the path
  // Each stage's time from the mark before it (lap): the monitors' two visits are added up.
  auto lap = [&now_ns]() {
    const std::int64_t before = now_ns;
    now_ns = hal::monotonic_now_ns();
    return now_ns - before;
  };

  control::ControlInput input;
  input.t = t;
  input.q = estimator_.position();
  input.qd = estimator_.velocity();
  input.qd_measured = qd;
  input.qdd = estimator_.acceleration();
  input.q_d = desired.q;
  input.qd_d = desired.qd;
  input.qdd_d = desired.qdd;
  input.soil.site_map = &config_.site_map;
  input.soil.theta_known = config_.theta_known;
  input.soil.theta = config_.theta_true;
  // What the stage after the law could not deliver last cycle (a clamped lead, a fully open valve):
  // the adaptive laws leave those joints out of their update, the PID its integrator.
  input.actuator_limited = stage_.limited();
  const Vec4 sent = to_vec(command.value);
  input.applied = restarted ? control::AppliedEffort{}
                            : stage_.applied(p, estimator_.velocity(), command.mode == hal::CommandMode::effort ? &sent : nullptr,
                                             out_.saturated);
  out_ = controller_->update(input);
  counters_.law.record_ns(lap());
  supervisor_.check_law(t, out_.status == ModelStatus::ok && out_.tau.allFinite(), out_.e, mode == safety::Mode::track && mode_entered);

  // Bumpless: entering hold/track from another effort-commanding mode starts from the last command.
  if (mode_entered && from_commanding) stage_.switch_modes(t, out_.tau);
  if (stage_.valves()) {
    supervisor_.check_pressures(t, !restarted && p.valid, complete, sensors);
    // The force loop closes on the measured chamber pressures: without them it would drive the
    // valves blind. Fault (the safe state centres the valves next cycle) rather than guess.
    if (!out_.velocity_command) supervisor_.require_pressures(t, p.valid);
    monitors_ns += lap();
    const control::ValveCommand& v = stage_.valve_command(t, out_, desired.qd, q, p, mode == safety::Mode::hold);
    command.mode = hal::CommandMode::pilot;
    for (int j = 0; j < 4; ++j) {
      command.value[j] = v.spool[j];
      command.pilot_a[j] = v.pilot_a[j];
      command.pilot_b[j] = v.pilot_b[j];
    }
    counters_.actuation.record_ns(lap());
    supervisor_.update_pump_warning(t, v.pump_limited, v.demanded_flow);
    supervisor_.check_flow(t, !restarted, v.velocity, stage_.flow_measurement(q, p), estimator_.velocity());
    supervisor_.check_spools(t, complete && p.valid, to_vec(sensors.spool));
    supervisor_.command_spools(v.spool);
  } else {
    monitors_ns += lap();
    const Vec4 efforts = stage_.efforts(t, out_.tau, restarted);
    command.mode = hal::CommandMode::effort;
    for (int j = 0; j < 4; ++j) command.value[j] = efforts[j];
    counters_.actuation.record_ns(lap());
  }
  counters_.monitors.record_ns(monitors_ns + lap());
  counters_.update.record_ns(now_ns - start_ns_);
}

void ControlStep::visit_state(control::StateVisitor& v) const {
  estimator_.visit_state(v);
  control::visit_state(out_, v);
  controller_->visit_state(v);
  stage_.visit_state(v);
}

}  // namespace exc::app
