#include "hal/fault_injecting_bus.hpp"

#include <algorithm>

namespace exc::hal {
namespace {
double clamp_unit(double x) { return (x >= 0.0 && x <= 1.0) ? x : (x > 1.0 ? 1.0 : 0.0); }
}  // namespace

FaultInjectingBus::FaultInjectingBus(CanBus& inner, const FaultInjection& config)
    : inner_(inner), config_(config), random_(config.seed), held_{} {
  config_.drop_fraction = clamp_unit(config_.drop_fraction);
  config_.corrupt_fraction = std::min(clamp_unit(config_.corrupt_fraction), 1.0 - config_.drop_fraction);
  config_.delay_fraction =
      std::min(clamp_unit(config_.delay_fraction), 1.0 - config_.drop_fraction - config_.corrupt_fraction);
}

double FaultInjectingBus::next_uniform() {
  // 53 random bits into [0, 1): the same sequence on every platform for a given seed.
  return static_cast<double>(random_() >> 11) * (1.0 / 9007199254740992.0);
}

void FaultInjectingBus::release_due() {
  std::size_t kept = 0;
  for (std::size_t i = 0; i < held_count_; ++i) {
    if (held_[i].release_at <= sends_) {
      inner_.send(held_[i].frame);
    } else {
      held_[kept++] = held_[i];
    }
  }
  held_count_ = kept;
}

bool FaultInjectingBus::send(const CanFrame& frame) {
  ++stats_.frames;
  ++sends_;
  const double u = next_uniform();
  bool result = true;
  if (u < config_.drop_fraction) {
    ++stats_.dropped;  // lost on the wire: the sender cannot tell
  } else if (u < config_.drop_fraction + config_.corrupt_fraction && frame.len > 0) {
    ++stats_.corrupted;
    CanFrame damaged = frame;
    const auto bit = static_cast<unsigned>(random_() % (8u * damaged.len));
    damaged.data[bit / 8] = static_cast<std::uint8_t>(damaged.data[bit / 8] ^ (1u << (bit % 8)));
    damaged.wire_ns = 0;  // other bits, other stuffing: the receiver times what it got
    result = inner_.send(damaged);
  } else if (u < config_.drop_fraction + config_.corrupt_fraction + config_.delay_fraction) {
    if (held_count_ < kDelayCapacity) {
      ++stats_.delayed;
      held_[held_count_++] = Held{frame, sends_ + config_.delay_frames};
    } else {
      ++stats_.delay_overflows;
      result = inner_.send(frame);
    }
  } else {
    result = inner_.send(frame);
  }
  release_due();
  return result;
}

void FaultInjectingBus::release_delayed() {
  for (std::size_t i = 0; i < held_count_; ++i) inner_.send(held_[i].frame);
  held_count_ = 0;
}

}  // namespace exc::hal
