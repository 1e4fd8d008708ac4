#include "harness/lockstep_rig.hpp"

#include <cmath>
#include <stdexcept>

#include "app/firmware_node.hpp"
#include "harness/target_firmware.hpp"
#include "harness/timing_windows.hpp"
#include "telemetry/lcm_output.hpp"

namespace exc::sim {
namespace {

std::unique_ptr<telemetry::TelemetryPublisher> start_telemetry(const LockstepOptions& options, const std::string& law) {
  if (!options.telemetry) return nullptr;
  telemetry::TelemetryConfig tc;
  tc.shared_output = options.telemetry;
  tc.channel_suffix = "/" + law;
  tc.overflow = telemetry::OverflowPolicy::block;  // no deadline here: every message is recorded
  tc.per_cycle_every = options.log_every;
  auto publisher = std::make_unique<telemetry::TelemetryPublisher>(tc);
  std::string error;
  if (!publisher->start(&error)) throw std::runtime_error("telemetry: " + error);
  return publisher;
}

std::unique_ptr<FirmwareEnd> firmware_end_of(const Model& model, const app::FirmwareImageSettings& firmware,
                                             const LockstepOptions& options, hal::FirmwareCanPort& port, hal::CanBus& bus,
                                             telemetry::TelemetryPublisher* publisher) {
  if (options.firmware_target.empty())
    return std::make_unique<HostFirmware>(
        std::make_unique<app::FirmwareNode>(model, firmware.task, firmware.node, port, publisher));
  if (options.observer || options.node_observer)
    throw std::invalid_argument("a run on " + options.firmware_target + " takes no observer of the in-process node");
  const std::string image = options.firmware_image.empty() ? firmware_target_image(options.firmware_target) : options.firmware_image;
  if (image.empty())
    throw std::invalid_argument("--firmware-target " + options.firmware_target +
                                ": this build made no firmware image (the test build makes it; another build with "
                                "-DEXC_TARGET_IMAGES=ON, after tools/install-deps test; or set EXC_FIRMWARE_IMAGE)");
  return std::make_unique<TargetFirmware>(image, firmware, bus, publisher);
}

}  // namespace

OperatorStation::OperatorStation(std::vector<SupervisorFrameAt> frames, hal::MemoryBusHub& hub, hal::CanBus& unused_bus)
    : frames_(std::move(frames)), port_(frames_.empty() ? unused_bus : *hub.attach()) {}

void OperatorStation::send_due(double now) {
  for (; next_ < frames_.size() && frames_[next_].time <= now + 1e-9; ++next_)
    if (!port_.send(frames_[next_].command))
      throw std::runtime_error("lockstep: the operator station's SUPERVISOR frame did not go out");
}

LockstepRig::LockstepRig(const plant::Scene& scene, const app::FirmwareImageSettings& firmware, const LockstepOptions& options)
    : plant_(scene),
      period_ns_(std::llround(scene.cycle * 1e9)),
      hub_(&SimClock::read, &clock_),
      firmware_bus_(hub_.attach()),
      plant_bus_(hub_.attach()),
      faults_(options.fault, *firmware_bus_, *plant_bus_),
      firmware_port_(faults_.firmware_end()),
      plant_port_(faults_.plant_end()),
      operator_station_(operator_frames(options.supervisor, options.fault), hub_, *firmware_bus_),
      publisher_(start_telemetry(options, firmware.node.controller.law)),
      firmware_model_(build_model(firmware.machine)),
      firmware_(firmware_end_of(firmware_model_, firmware, options, firmware_port_, faults_.firmware_end(), publisher_.get())),
      plant_node_(std::make_unique<plant::PlantNode>(plant_, plant_port_, publisher_.get())) {}

LockstepRig::~LockstepRig() = default;

void LockstepRig::step(std::int64_t k, double now) {
  clock_.now_ns = k * period_ns_;
  faults_.apply(now, plant_, *plant_node_);
  operator_station_.send_due(now);
  firmware_->begin_cycle();
  if (!plant_node_->poll()) plant_node_->coast();  // a SYNC lost in a burst: the machine moves on
  firmware_->end_cycle();
}

app::RunSummaryRecord LockstepRig::finish(RunRecord& r) {
  const app::RunSummaryRecord outcome = firmware_->finish();
  plant_node_->publish_counters();
  if (publisher_) {
    publisher_->stop();
    const telemetry::TelemetryCounters c = publisher_->counters();
    r.telemetry_enqueued = c.enqueued;
    r.telemetry_published = c.published;
    r.telemetry_dropped = c.dropped_full_total + c.dropped_overflow + c.dropped_too_large;
    r.telemetry_ring_high_water = c.ring_high_water;
  }
  r.firmware_cycle = host_node() != nullptr ? timing_of(host_node()->cycle_timing()) : Timing{};
  r.target = firmware_->target_figures();
  r.rx_rejected = (host_node() != nullptr ? firmware_port_.rx_stats().rejected() : outcome.rx_rejected) +
                  plant_port_.rx_stats().rejected();
  return outcome;
}

}  // namespace exc::sim
