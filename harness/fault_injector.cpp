#include "harness/fault_injector.hpp"

#include <algorithm>
#include <cmath>

#include "sim_plant/plant.hpp"
#include "sim_plant/plant_node.hpp"

namespace exc::sim {

std::string fault_misfit(plant::FaultKind kind, const plant::Scene& scene) {
  using K = plant::FaultKind;
  const bool needs_hydraulics = kind == K::pump_loss || kind == K::spool_stuck || kind == K::pressure_stuck ||
                                kind == K::pressure_jump || kind == K::pressure_drift;
  if (!needs_hydraulics || plant::fidelity_of(scene.actuators).has(plant::kHydraulicCircuit)) return "";
  return std::string(to_string(kind)) + " needs the hydraulic machine; " + scene.file + " has actuators " +
         scene.actuators.fidelity;
}

std::vector<SupervisorFrameAt> operator_frames(std::vector<SupervisorFrameAt> frames, const FaultSchedule& fault) {
  // The operator station is outside the burst: its frames are what the fault campaign never damages.
  if (fault.kind == plant::FaultKind::operator_stop) frames.push_back({fault.start, hal::SupervisorCommand::stop});
  if (fault.kind == plant::FaultKind::operator_link_lost) {
    // Counted, not compared: 0.1 * 30 is above 3.0, and a start on the grid keeps its own frame.
    const int last = static_cast<int>(std::floor(fault.start / 0.1 + 1e-9));
    for (int k = 1; k <= last; ++k) frames.push_back({0.1 * k, hal::SupervisorCommand::none});
  }
  std::stable_sort(frames.begin(), frames.end(), [](const SupervisorFrameAt& a, const SupervisorFrameAt& b) { return a.time < b.time; });
  return frames;
}

hal::FaultInjection FaultInjector::burst_of(const FaultSchedule& fault, std::uint64_t seed) {
  // A burst's damaged share split evenly into dropped, corrupted and delayed frames.
  hal::FaultInjection burst;
  const double share = fault.kind == plant::FaultKind::bus_burst ? fault.magnitude / 3 : 0;
  burst.drop_fraction = burst.corrupt_fraction = burst.delay_fraction = share;
  burst.seed = seed;
  return burst;
}

FaultInjector::FaultInjector(const FaultSchedule& fault, hal::CanBus& firmware_bus, hal::CanBus& plant_bus)
    : fault_(fault),
      firmware_end_(firmware_bus, burst_of(fault, fault.seed)),
      plant_end_(plant_bus, burst_of(fault, fault.seed + 1)) {}

void FaultInjector::apply(double now, plant::Plant& plant, plant::PlantNode& plant_node) {
  using K = plant::FaultKind;
  const bool want = fault_.kind != K::none && now >= fault_.start && now < fault_.start + fault_.duration;
  if (want == on_) return;
  on_ = want;
  firmware_end_.set(on_ && fault_.kind == K::bus_burst);
  plant_end_.set(on_ && fault_.kind == K::bus_burst);
  plant_node.set_fault(on_ ? static_cast<const plant::InjectedFault&>(fault_) : plant::InjectedFault{});
  if (fault_.kind == K::rock) plant.set_soil_stiffness_scale(on_ ? fault_.magnitude : 1.0);
  if (fault_.kind == K::pump_loss) plant.set_pump_flow_scale(on_ ? 1 - fault_.magnitude : 1.0);
}

}  // namespace exc::sim
