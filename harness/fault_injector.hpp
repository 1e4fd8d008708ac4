#pragma once
// The lockstep run's faults (the fault campaign): one fault from its start for its duration, each
// kind acted on by the end that has it. The plant's node takes the machine's own (sensors,
// actuators, spools, pressure transmitters, its controller's fault); here the bus ends' burst
// injectors, the soil's stiffness and the pumps' flow; the operator station sends the stop frame or
// ends its keep-alives (operator_frames). The kinds: sim_plant/injected_fault.hpp.
#include <cstdint>
#include <string>
#include <vector>

#include "hal/can_protocol.hpp"
#include "hal/fault_injecting_bus.hpp"
#include "sim_plant/injected_fault.hpp"
#include "sim_plant/scene.hpp"

namespace exc::plant {
class Plant;
class PlantNode;
}

namespace exc::sim {

using plant::kFaultKinds;
using plant::to_string;

// One fault injected into a run: the injected fault from `start` for `duration` s of simulated time.
struct FaultSchedule : plant::InjectedFault {
  FaultSchedule() { joint = 1; }  // the boom, unless the schedule says otherwise
  double start = 0, duration = 0;  // s
  std::uint64_t seed = 1;          // bus_burst: the injectors' draws
};

// Why a fault of `kind` cannot run on `scene` ("" when it can): the pumps' and the spools' faults
// and the pressure transmitters' need the hydraulic machine. run_lockstep refuses such a run, a
// sweep such a spec before any run.
std::string fault_misfit(plant::FaultKind kind, const plant::Scene& scene);

// An operator's command, sent as a SUPERVISOR frame by a third node on the bus (an operator station)
// just before the first cycle at or after `time` (s).
struct SupervisorFrameAt {
  double time = 0;
  hal::SupervisorCommand command = hal::SupervisorCommand::none;
};
// The frames the operator station sends in a run: the planned ones, and an operator_stop fault's stop
// frame at its start or an operator_link_lost fault's keep-alives (every 0.1 s up to its start), in
// time order.
std::vector<SupervisorFrameAt> operator_frames(std::vector<SupervisorFrameAt> planned, const FaultSchedule& fault);

// The bus of one node end: frames go out through a fault injector while a burst is on.
class BurstBus final : public hal::CanBus {
 public:
  BurstBus(hal::CanBus& inner, const hal::FaultInjection& faults) : inner_(inner), faulty_(inner, faults) {}
  bool send(const hal::CanFrame& frame) override { return on_ ? faulty_.send(frame) : inner_.send(frame); }
  bool receive(hal::CanFrame& frame) override { return inner_.receive(frame); }
  bool wait_readable(std::int64_t timeout_ns) override { return inner_.wait_readable(timeout_ns); }
  void set(bool on) {
    if (on_ && !on) faulty_.release_delayed();
    on_ = on;
  }

 private:
  hal::CanBus& inner_;
  hal::FaultInjectingBus faulty_;
  bool on_ = false;
};

// Both node ends' buses (idle unless a burst is on) and the fault's switching on and off.
class FaultInjector {
 public:
  FaultInjector(const FaultSchedule& fault, hal::CanBus& firmware_bus, hal::CanBus& plant_bus);
  hal::CanBus& firmware_end() { return firmware_end_; }
  hal::CanBus& plant_end() { return plant_end_; }
  // Before the cycle at `now` (s): the fault switched on at its start and off at its end.
  // Allocation-free.
  void apply(double now, plant::Plant& plant, plant::PlantNode& plant_node);

 private:
  static hal::FaultInjection burst_of(const FaultSchedule& fault, std::uint64_t seed);
  FaultSchedule fault_;
  BurstBus firmware_end_, plant_end_;
  bool on_ = false;
};

}  // namespace exc::sim
