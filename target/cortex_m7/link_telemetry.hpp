#pragma once
// The firmware's telemetry on the emulated target: the encoded messages staged in RAM as the loop
// publishes them (telemetry/telemetry_sink.hpp), framed onto the link after the cycle, so the loop's
// telemetry stage costs what encoding costs on a machine and not the link's framing. The host
// publishes the bytes unchanged into LCM (harness/target_firmware.cpp). No heap.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "telemetry/telemetry_sink.hpp"

namespace exc::target {

class LinkTelemetry final : public telemetry::TelemetrySink {
 public:
  static constexpr std::size_t kStageBytes = 8 * 1024;  // a cycle's messages, ~1.3 KB with a counter part; a run's last round ~7 KB

  LinkTelemetry() : TelemetrySink(1) {}

  // The staged messages, each as [size low, size high, channel, bytes] (size: of the bytes), so that
  // [channel, bytes] is a telemetry record's payload as it stands; cleared by the loop.
  const std::uint8_t* staged() const { return stage_; }
  std::size_t staged_bytes() const { return fill_; }
  void clear() { fill_ = 0; }
  std::uint64_t refused() const { return refused_; }

 private:
  bool put(std::size_t channel, const std::uint8_t* bytes, std::size_t size) override {
    if (size + 3 > kStageBytes - fill_) {
      ++refused_;
      return false;
    }
    stage_[fill_] = static_cast<std::uint8_t>(size);
    stage_[fill_ + 1] = static_cast<std::uint8_t>(size >> 8);
    stage_[fill_ + 2] = static_cast<std::uint8_t>(channel);
    std::memcpy(stage_ + fill_ + 3, bytes, size);
    fill_ += size + 3;
    return true;
  }
  void note_too_large() override { ++refused_; }

  std::uint8_t stage_[kStageBytes];
  std::size_t fill_ = 0;
  std::uint64_t refused_ = 0;
};

}  // namespace exc::target
