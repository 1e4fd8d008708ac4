#pragma once
// What a lockstep run steps: the plant and its node, the firmware's end (its node in this process or
// its image on the emulated target), the in-memory bus between them stamped with simulated time,
// the fault injector on both node ends, the operator station and the telemetry. Built before the
// first cycle (start-up: allocates, throws); stepping it allocates nothing.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hal/can_ports.hpp"
#include "hal/memory_bus.hpp"
#include "harness/fault_injector.hpp"
#include "harness/firmware_end.hpp"
#include "harness/lockstep_run.hpp"
#include "sim_plant/plant.hpp"
#include "sim_plant/plant_node.hpp"
#include "telemetry/telemetry_publisher.hpp"

namespace exc::sim {

// The bus is stamped with simulated time, so the codec's timing rules never see wall-clock jitter.
struct SimClock {
  std::int64_t now_ns = 0;
  static std::int64_t read(void* self) { return static_cast<SimClock*>(self)->now_ns; }
};

// A third node on the bus, outside the burst: the operator's SUPERVISOR frames at their times.
class OperatorStation {
 public:
  OperatorStation(std::vector<SupervisorFrameAt> frames, hal::MemoryBusHub& hub, hal::CanBus& unused_bus);
  // Before the cycle at `now` (s): every frame due by then. Allocation-free.
  void send_due(double now);

 private:
  std::vector<SupervisorFrameAt> frames_;
  std::size_t next_ = 0;
  hal::OperatorCanPort port_;
};

class LockstepRig {
 public:
  LockstepRig(const plant::Scene& scene, const app::FirmwareImageSettings& firmware, const LockstepOptions& options);
  ~LockstepRig();

  // Cycle k: the bus's clock, the fault, the operator's frames due, then SYNC -> plant step and
  // sensor frames -> the firmware's control and commands.
  void step(std::int64_t k, double now);

  plant::Plant& machine() { return plant_; }
  const app::FirmwareNode* host_node() const { return firmware_->node(); }  // null on a target
  FirmwareEnd& firmware() { return *firmware_; }
  plant::PlantNode& plant_node() { return *plant_node_; }
  // The run is over: the firmware's outcome; telemetry flushed and its counters, the bus's rejected
  // frames and a target's figures into r.
  app::RunSummaryRecord finish(RunRecord& r);

 private:
  plant::Plant plant_;
  std::int64_t period_ns_;
  SimClock clock_;
  hal::MemoryBusHub hub_;
  hal::MemoryBusNode* firmware_bus_;
  hal::MemoryBusNode* plant_bus_;
  FaultInjector faults_;
  hal::FirmwareCanPort firmware_port_;
  hal::PlantCanPort plant_port_;
  OperatorStation operator_station_;
  std::unique_ptr<telemetry::TelemetryPublisher> publisher_;
  Model firmware_model_;  // the firmware's own (its node keeps a reference)
  std::unique_ptr<FirmwareEnd> firmware_;
  std::unique_ptr<plant::PlantNode> plant_node_;
};

}  // namespace exc::sim
