#include "sim_plant/plant_node.hpp"

#include <algorithm>

#include "diagnostics/can_stats_message.hpp"
#include "diagnostics/timing_message.hpp"
#include "hal/clock.hpp"
#include "exlcm/machine_state_t.hpp"
#include "model/closed_chain.hpp"
#include "telemetry/telemetry_publisher.hpp"

namespace exc::plant {

PlantNode::PlantNode(plant::Plant& plant, hal::PlantCanPort& port, telemetry::TelemetryPublisher* telemetry,
                     const PlantNodeConfig& config)
    : plant_(plant), port_(port), telemetry_(telemetry), config_(config), ws_(plant.model()) {}

bool PlantNode::poll() {
  std::uint64_t cycle = 0;
  if (!port_.poll_sync(cycle)) return false;
  step(cycle);
  return true;
}

void PlantNode::coast() { step(last_cycle_ + 1, false); }

bool PlantNode::wait(std::int64_t timeout_ns) {
  std::uint64_t cycle = 0;
  if (!port_.wait_sync(cycle, timeout_ns)) return false;
  step(cycle);
  return true;
}

Vec4 PlantNode::hold_effort() {
  const plant::PlantState& s = plant_.state();
  Vec4 tau = Vec4::Zero();
  // Static load at the current pose, then a velocity brake scaled by the mass matrix so every axis
  // stops at the same rate; outside assembly (never expected here) the last efforts are held.
  if (!update_closed_chain(plant_.model(), ws_, s.q_a, Vec4::Zero()).ok()) return s.effort;
  bias_forces(plant_.model(), ws_, tau);
  Mat4 M_a;
  mass_matrix(plant_.model(), ws_, M_a);
  tau -= M_a * (config_.brake_rate * s.qd_a);
  return tau;
}

void PlantNode::scan_state(diagnostics::SubnormalScan& scan) const {
  // The machine (its state, circuit, sensors' reading and dynamics' workspace), then this node's
  // frames: the sensor set it sent and the command set it steps with. Each type visits its own values.
  plant_.visit_state(scan);
  hal::visit_state(sensors_, scan);
  hal::visit_state(command_, scan);
}

void PlantNode::hold_for_silence() {
  if (!silence_hold_) ++holds_;
  silence_hold_ = true;
  holding_ = true;
  port_.send_fault(true, 1);
}

void PlantNode::step(std::uint64_t cycle, bool answer) {
  last_cycle_ = cycle;
  if (port_.read(command_)) {
    have_command_ = true;
    last_command_cycle_ = cycle;
    silence_hold_ = false;
  }
  // A cycle counter that went backwards (a restarted firmware) counts as timed out until it commands.
  const bool timed_out = !have_command_ || silence_hold_ || cycle < last_command_cycle_ ||
                         cycle - last_command_cycle_ > static_cast<std::uint64_t>(config_.command_timeout_cycles);
  // The firmware's safe state is "valves centred" (valve command of zeros); a force-commanded
  // plant has no valves, so it brakes instead.
  const bool valves = plant_.fidelity().takes_valves();
  const bool hydraulic = plant_.fidelity().has(plant::kHydraulicCircuit);
  bool centred = true;
  for (double v : command_.value) centred = centred && v == 0;
  const bool firmware_holds = command_.valid && command_.mode == hal::CommandMode::valve && centred && !valves;
  const bool machine_fault = fault_.kind == InjectedFault::Kind::machine_fault;
  const bool hold = timed_out || command_.emergency_stop || firmware_holds || machine_fault;
  if (hold && !holding_) ++holds_;
  holding_ = hold;
  // The machine's safety controller on the firmware's emergency stop (FW_EMERGENCY EmergencyStop):
  // pilot supply cut (every spool springs to centre), engine stopped (the pumps run down), and its
  // safety solenoids dropped: the pump-line shut-off unloads the pumps, the load-holding valves close
  // and the swing brake is dumped, whatever the main spools do; all back when the stop is released
  // (docs/safety.md). On a lost
  // link (commands had come, then none within the timeout, or SYNC fell silent) it drops the enable
  // as an autonomy kit's receiver does: the pilot supply cut, so the load-holding valves and the
  // swing's brake hold; the engine runs on. Both come back with the next valid command set. Before
  // the first command the valves are centred and the supply stays on (no link was lost).
  const bool link_lost = have_command_ && timed_out;
  const bool pilot_cut = hydraulic && (command_.emergency_stop || link_lost);
  if (hydraulic) {
    plant_.set_pilot_supply(!pilot_cut);
    plant_.set_engine_running(!command_.emergency_stop);
    plant_.set_safety_solenoids(!command_.emergency_stop);
    // Any stop the firmware latched (a FW_EMERGENCY with a FaultCode, controlled or emergency) locks
    // the swing: with its valves centred and no brake, the upper structure rang on its motor's
    // leaking oil spring for seconds (docs/safety.md, the stop requirement's swing drift).
    plant_.set_swing_lock(command_.fault_code != 0);
  }

  // Any other command goes to the plant as the kind it is: a kind the actuators cannot use (efforts
  // for valves, openings or pilots for force actuators) stops the plant with its message, so a
  // mismatched setup fails at once instead of running on with the commands ignored.
  plant::ActuatorCommand actuator;
  if (hold) {
    actuator.mode = valves ? plant::ActuatorCommand::valve : plant::ActuatorCommand::effort;
    if (!valves) actuator.value = hold_effort();  // valves: centred (zeros)
  } else {
    switch (command_.mode) {
      case hal::CommandMode::effort: actuator.mode = plant::ActuatorCommand::effort; break;
      case hal::CommandMode::valve: actuator.mode = plant::ActuatorCommand::valve; break;
      case hal::CommandMode::pilot: actuator.mode = plant::ActuatorCommand::pilot; break;
    }
    for (int j = 0; j < 4; ++j) {
      actuator.value[j] = command_.value[j];
      actuator.pilot_a[j] = command_.pilot_a[j];
      actuator.pilot_b[j] = command_.pilot_b[j];
    }
  }
  apply_actuator_fault(actuator);
  const std::int64_t step_start = hal::monotonic_now_ns();
  plant_.step(actuator);
  step_timing_.record_ns(hal::monotonic_now_ns() - step_start);
  ++steps_;

  const plant::SensorReading& r = plant_.sensors();
  sensors_.cycle = cycle;
  for (int j = 0; j < 4; ++j) {
    sensors_.position[j] = r.position[j];
    sensors_.velocity[j] = r.velocity[j];
  }
  // Every chamber (swing motor ports first, then the cylinders' cap and rod sides) and both pumps;
  // measured only by the hydraulic plant.
  sensors_.pressure_a[hal::kSwing] = r.swing_pressure[0];
  sensors_.pressure_b[hal::kSwing] = r.swing_pressure[1];
  for (int c = 0; c < 3; ++c) {
    sensors_.pressure_a[c + 1] = r.pressure_a[c];
    sensors_.pressure_b[c + 1] = r.pressure_b[c];
  }
  for (int p = 0; p < hal::kPumpCount; ++p) sensors_.pump_pressure[p] = r.pump_pressure[p];
  for (int j = 0; j < 4; ++j) sensors_.spool[j] = r.spool[j];
  sensors_.pressure_valid = hydraulic;
  apply_sensor_fault();
  const plant::HydraulicReport& h = plant_.state().hydraulics;
  const bool estop = hydraulic && command_.emergency_stop;
  sensors_.plant_state = static_cast<std::uint8_t>((hold ? hal::kPlantStateHolding : 0) | (pilot_cut ? hal::kPlantStatePilotCut : 0) |
                                                   (estop ? hal::kPlantStateEngineStopped : 0) |
                                                   (hydraulic && h.holding_valves_closed ? hal::kPlantStateHoldingValvesClosed : 0));
  sensors_.plant_faults = static_cast<std::uint8_t>((failed() ? 1 : 0) | (machine_fault ? 2 : 0));
  if (answer && !failed()) port_.write(sensors_);  // a failed plant goes silent: the firmware's watchdog acts
  if (answer && cycle % 100 == 50) port_.send_heartbeat(sensors_.plant_state);
  if (telemetry_ != nullptr) {
    publish_state();
    if (cycle % 100 == 0) publish_counters();
  }
}

void PlantNode::publish_state() {
  const plant::PlantState& s = plant_.state();
  exlcm::machine_state_t m{};
  m.utime = static_cast<std::int64_t>(s.time * 1e6 + 0.5);
  for (int j = 0; j < 4; ++j) {
    m.q_active[j] = s.q_a[j];
    m.qd_active[j] = s.qd_a[j];
  }
  for (int i = 0; i < kNumPassive; ++i) m.q_passive[i] = s.q[kPassiveJoints[i]];
  for (int i = 0; i < 3; ++i) m.tip_world[i] = s.tip_world[i];
  for (int i = 0; i < 2; ++i) {
    m.tip_rho[i] = s.rho[i];
    m.soil_force[i] = s.soil_force[i];
    m.soil_anchor[i] = s.soil_anchor[i];
  }
  m.in_soil = s.in_soil;
  m.depth = s.depth;
  if (plant_.fidelity().has(plant::kHydraulicCircuit)) {
    for (int j = 0; j < 4; ++j) {
      m.pressure_a[j] = s.pressure_a[j];
      m.pressure_b[j] = s.pressure_b[j];
      m.spool[j] = s.spool[j];
    }
    for (int i = 0; i < 2; ++i) {
      m.pump_pressure[i] = s.hydraulics.pump_pressure[i];
      m.flow_scale[i] = s.hydraulics.flow_scale[i];
    }
  }
  telemetry_->publish(telemetry::Channel::state, m);
}

void PlantNode::publish_counters() {
  if (telemetry_ == nullptr) return;
  const exlcm::can_stats_t cs =
      diagnostics::can_stats_message(port_.rx_stats(), port_.tx_stats(), 1, static_cast<std::int64_t>(plant_.state().time * 1e6 + 0.5));
  telemetry_->publish(telemetry::Channel::can_stats, cs);
  exlcm::timing_t m{};
  diagnostics::fill_timing(step_timing_, 4, cs.utime, m);  // stage 4: the plant step
  telemetry_->publish(telemetry::Channel::timing, m);
}

void PlantNode::set_fault(const InjectedFault& fault) {
  if (fault_.kind == InjectedFault::Kind::spool_stuck || fault_.kind == InjectedFault::Kind::actuator_jam)
    plant_.release_spool();  // a spool held by the fault that ends (none on a force-actuated plant)
  fault_ = fault;
  fault_started_ = false;
  // A stuck spool is the circuit's own state: no command moves it (hydraulic plants; the others have
  // no spools and ignore it).
  if (fault.kind == InjectedFault::Kind::spool_stuck) plant_.stick_spool(fault.joint, fault.magnitude);
}

void PlantNode::apply_actuator_fault(plant::ActuatorCommand& actuator) {
  const int j = fault_.joint;
  if (fault_.kind == InjectedFault::Kind::actuator_loss) {
    actuator.value[j] *= 1 - fault_.magnitude;
    actuator.pilot_a[j] *= 1 - fault_.magnitude;  // the spool's travel scales with its pilot difference
    actuator.pilot_b[j] *= 1 - fault_.magnitude;
  } else if (fault_.kind == InjectedFault::Kind::actuator_jam) {
    // A stuck actuator keeps what it applied when it stuck, whatever is commanded: a force actuator
    // its effort; on the hydraulic machine its spool, through the circuit's own stuck-spool state (the
    // spool_stuck fault's), so the safe state's centred valves do not move it either.
    if (actuator.mode == plant::ActuatorCommand::effort) {
      if (!fault_started_) jammed_effort_ = plant_.state().effort[j];
      actuator.value[j] = jammed_effort_;
    } else if (!fault_started_) {
      plant_.stick_spool(j, plant_.state().spool[j]);
    }
  }
  if (fault_.kind == InjectedFault::Kind::actuator_loss || fault_.kind == InjectedFault::Kind::actuator_jam)
    fault_started_ = true;
}

void PlantNode::apply_sensor_fault() {
  if (fault_.kind == InjectedFault::Kind::sensor_freeze) {
    // A stuck encoder: the values of the moment it stuck, in frames that are otherwise valid.
    if (!fault_started_) frozen_ = sensors_;
    fault_started_ = true;
    sensors_.position[fault_.joint] = frozen_.position[fault_.joint];
    sensors_.velocity[fault_.joint] = 0;
  } else if (fault_.kind == InjectedFault::Kind::sensor_jump) {
    sensors_.position[fault_.joint] += fault_.magnitude;
  } else if (fault_.kind == InjectedFault::Kind::pressure_stuck || fault_.kind == InjectedFault::Kind::pressure_jump ||
             fault_.kind == InjectedFault::Kind::pressure_drift) {
    if (!fault_started_) {
      frozen_ = sensors_;
      fault_cycles_ = 0;
    }
    fault_started_ = true;
    ++fault_cycles_;
    auto& p = fault_.chamber == 0 ? sensors_.pressure_a : sensors_.pressure_b;
    const auto& held = fault_.chamber == 0 ? frozen_.pressure_a : frozen_.pressure_b;
    const std::size_t j = static_cast<std::size_t>(fault_.joint);
    if (fault_.kind == InjectedFault::Kind::pressure_stuck)
      p[j] = held[j];
    else if (fault_.kind == InjectedFault::Kind::pressure_jump)
      p[j] += fault_.magnitude;
    else
      p[j] += fault_.magnitude * static_cast<double>(fault_cycles_) * plant_.scene().cycle;
  }
}

}  // namespace exc::plant
