#pragma once
// A CanBus decorator that damages outgoing frames on purpose, to show the loop survives a bad bus:
// each frame sent through it is, with the configured probabilities (exclusive, one draw per frame),
// dropped, corrupted (one payload bit flipped, so only the checksum can catch it) or delayed (held
// back and sent after `delay_frames` later frames, i.e. reordered). Seeded, so a run is repeatable.
// Fixed-capacity delay line; no allocation after construction.
#include <cstddef>
#include <cstdint>
#include <random>

#include "hal/can_bus.hpp"

namespace exc::hal {

struct FaultInjection {
  double drop_fraction = 0.0;
  double corrupt_fraction = 0.0;
  double delay_fraction = 0.0;
  std::uint32_t delay_frames = 3;  // a delayed frame goes out after this many later frames
  std::uint64_t seed = 1;
};

struct FaultInjectionStats {
  std::uint64_t frames = 0;
  std::uint64_t dropped = 0;
  std::uint64_t corrupted = 0;
  std::uint64_t delayed = 0;
  std::uint64_t delay_overflows = 0;  // delay line full: the frame went out undelayed
};

class FaultInjectingBus final : public CanBus {
 public:
  static constexpr std::size_t kDelayCapacity = 64;

  // `inner` must outlive this object. Fractions outside [0, 1] or summing above 1 are clamped.
  FaultInjectingBus(CanBus& inner, const FaultInjection& config);

  bool send(const CanFrame& frame) override;
  bool receive(CanFrame& frame) override { return inner_.receive(frame); }
  bool wait_readable(std::int64_t timeout_ns) override { return inner_.wait_readable(timeout_ns); }

  // Sends every frame still held back (e.g. at the end of a run).
  void release_delayed();
  const FaultInjectionStats& stats() const { return stats_; }
  const FaultInjection& config() const { return config_; }

 private:
  struct Held {
    CanFrame frame;
    std::uint64_t release_at;  // value of sends_ at which it goes out
  };
  double next_uniform();
  void release_due();

  CanBus& inner_;
  FaultInjection config_;
  std::mt19937_64 random_;
  FaultInjectionStats stats_;
  Held held_[kDelayCapacity];
  std::size_t held_count_ = 0;
  std::uint64_t sends_ = 0;
};

}  // namespace exc::hal
