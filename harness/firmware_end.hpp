#pragma once
// The firmware's side of a lockstep run, wherever the firmware runs: its node in this process
// (HostFirmware) or its image on the emulated Cortex-M7, over the link (TargetFirmware,
// harness/target_firmware.hpp). The harness steps it and reads the same record of it either way.
#include <memory>
#include <optional>

#include "app/firmware_node.hpp"
#include "app/pil_records.hpp"
#include "harness/target_figures.hpp"

namespace exc::sim {

class FirmwareEnd {
 public:
  virtual ~FirmwareEnd() = default;
  virtual void begin_cycle() = 0;  // SYNC (and heartbeat, a standing stop's frame) onto the bus
  virtual void end_cycle() = 0;    // read, compute, write, telemetry
  // What the harness reads after each end_cycle.
  virtual const app::CycleStatus& status() const = 0;
  // The run is over: the last counters published; the outcome as the firmware saw it.
  virtual app::RunSummaryRecord finish() = 0;
  // The node itself (an in-process run's observers and timing windows); null on a target.
  virtual const app::FirmwareNode* node() const { return nullptr; }
  // A target's own figures (instructions per stage, stack, image size); none in-process.
  virtual std::optional<TargetFigures> target_figures() const { return std::nullopt; }
};

// The firmware's node in this process.
class HostFirmware final : public FirmwareEnd {
 public:
  explicit HostFirmware(std::unique_ptr<app::FirmwareNode> node) : node_(std::move(node)) {}
  void begin_cycle() override { node_->begin_cycle(); }
  void end_cycle() override;
  const app::CycleStatus& status() const override { return status_; }
  app::RunSummaryRecord finish() override;
  const app::FirmwareNode* node() const override { return node_.get(); }

 private:
  std::unique_ptr<app::FirmwareNode> node_;
  app::CycleStatus status_;
};

}  // namespace exc::sim
