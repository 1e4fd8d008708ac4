#pragma once
// The simulated machine's end of the bus: on each SYNC(k) it takes the latest valid command set,
// steps the plant exactly once (CMD_EFFORT, CMD_VALVE or CMD_PILOT applied as the kind it is) and
// answers with SENS_MACHINE of cycle k (every chamber and pump pressure when hydraulic). It holds
// the machine (valves centred; for force-commanded fidelities a model-based brake, see
// hold_effort()) when the firmware asks for it, when commands stop for longer than the command
// timeout, or on an emergency stop. Nothing allocates after construction.
#include <cstdint>

#include "diagnostics/subnormal_scan.hpp"
#include "diagnostics/perf_counter.hpp"
#include "hal/can_ports.hpp"
#include "model/workspace.hpp"
#include "sim_plant/injected_fault.hpp"
#include "sim_plant/plant.hpp"

namespace exc::telemetry {
class TelemetryPublisher;
}

namespace exc::plant {

struct PlantNodeConfig {
  int command_timeout_cycles = 20;  // cycles without a new valid command set -> hold
  double brake_rate = 40.0;         // 1/s, velocity decay rate of the model-based hold
};

class PlantNode {
 public:
  PlantNode(plant::Plant& plant, hal::PlantCanPort& port, telemetry::TelemetryPublisher* telemetry,
            const PlantNodeConfig& config = {});

  // Handles what is on the bus; if a SYNC was among it, steps once and answers. True if stepped.
  bool poll();
  // Same, waiting up to timeout_ns for a SYNC (SocketCAN); false on timeout.
  bool wait(std::int64_t timeout_ns);
  // A cycle whose SYNC never reached the plant (lost on the bus): the machine goes on with the
  // command it holds, one step, and sends nothing (no SYNC, no answer). Lockstep harnesses call it so
  // that the machine's time keeps the firmware's when frames are lost.
  void coast();

  bool failed() const { return !plant_.status().ok(); }
  // The firmware fell silent (no SYNC): latch the hold until a fresh command set arrives, and say
  // so on the bus with PLANT_EMERGENCY. Called again every 10 ms while the silence lasts, each call
  // repeats the frame (IfActive in the DBC).
  void hold_for_silence();
  bool holding() const { return holding_; }
  // Starts (kind != none) or ends (none) an injected fault; takes effect from the next step.
  void set_fault(const InjectedFault& fault);
  std::uint64_t holds() const { return holds_; }     // transitions into hold
  std::uint64_t steps() const { return steps_; }
  const plant::Plant& plant() const { return plant_; }
  void publish_counters();
  // Plant::step's wall time per call, as EXC_TIMING stage 4 reports it.
  const diagnostics::PerfCounter& step_timing() const { return step_timing_; }
  // Every value the plant and this node carry from one step to the next (the machine's state, its
  // circuit and soil, the sensor and command sets, the dynamics' workspace), for a look for
  // subnormals (docs/floating-point.md). Not on the loop's path.
  void scan_state(diagnostics::SubnormalScan& scan) const;

 private:
  void step(std::uint64_t cycle, bool answer = true);
  void apply_actuator_fault(plant::ActuatorCommand& actuator);
  void apply_sensor_fault();
  // Efforts that brake the machine to rest where it is: g_a(q) - M_a * rate * qd_a.
  Vec4 hold_effort();
  void publish_state();

  plant::Plant& plant_;
  hal::PlantCanPort& port_;
  telemetry::TelemetryPublisher* telemetry_;
  PlantNodeConfig config_;
  Workspace ws_;
  hal::CommandState command_;
  hal::SensorState sensors_;
  std::uint64_t last_command_cycle_ = 0;
  std::uint64_t last_cycle_ = 0;  // of the last step
  bool have_command_ = false;
  bool holding_ = true;
  bool silence_hold_ = false;
  std::uint64_t holds_ = 0;
  std::uint64_t steps_ = 0;
  InjectedFault fault_;
  bool fault_started_ = false;
  hal::SensorState frozen_;       // sensor_freeze, pressure_stuck: what the stuck sensor keeps reporting
  std::uint64_t fault_cycles_ = 0;  // pressure_drift: sensor sets since the fault's start
  double jammed_effort_ = 0;      // actuator_jam: the effort the stuck actuator keeps applying
  diagnostics::PerfCounter step_timing_{"plant_step", 1000.0};
};

}  // namespace exc::plant
