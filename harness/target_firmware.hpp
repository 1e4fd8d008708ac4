#pragma once
// The firmware on the emulated Cortex-M7, as a lockstep run's firmware end (processor in the loop,
// docs/target.md): the image runs under QEMU, its settings sent as a blob at boot, and each cycle its
// CAN frames are put on this process's bus (the same frames, through the same fault injection, as the
// in-process node's) and the plant's answer sent back; its telemetry goes into the run's log through
// the plant's publisher, one sequence per channel. Its instructions per cycle and per stage, exact
// per cycle, are the run's target figures.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "app/settings_blob.hpp"
#include "harness/emulated_target.hpp"
#include "harness/firmware_end.hpp"
#include "hal/can_bus.hpp"
#include "telemetry/telemetry_sink.hpp"

namespace exc::sim {

// The targets a run may take ("cortex-m7") and the image each runs: EXC_FIRMWARE_IMAGE when set, else
// the image this build made (empty: none was built; the error then says how to build it).
std::string firmware_target_image(const std::string& target);

class TargetFirmware final : public FirmwareEnd {
 public:
  // Starts the image and sends it `settings`; returns once it said ready. Throws EmulatedTargetError
  // (the image refused the settings, naming why; QEMU missing; no answer within timeout_s).
  TargetFirmware(const std::string& image, const app::FirmwareImageSettings& settings, hal::CanBus& bus,
                 telemetry::TelemetrySink* telemetry, double timeout_s = 120);
  ~TargetFirmware() override;

  void begin_cycle() override;
  void end_cycle() override;
  const app::CycleStatus& status() const override { return status_; }
  app::RunSummaryRecord finish() override;
  std::optional<TargetFigures> target_figures() const override { return figures_; }

 private:
  // Puts the target's frames on the bus and its messages into the log; returns the last record.
  const TargetRecord& forward(const std::vector<TargetRecord>& records);

  EmulatedTarget target_;
  hal::CanBus& bus_;
  telemetry::TelemetrySink* telemetry_;
  app::CycleStatus status_;
  std::vector<std::uint32_t> instructions_[app::kTargetStages];  // per cycle, per stage
  std::optional<TargetFigures> figures_;
  bool finished_ = false;
};

}  // namespace exc::sim
