#pragma once
// A position sensor that stopped changing while its function is driven (docs/safety.md, H1): the
// flow monitor (velocity_plausibility.hpp) is one-sided, it finds oil that arrived unasked, and a
// function given less than asked is normally the tracking error's business (a dead zone, the pumps
// short, an end stop). A frozen encoder is the case it leaves: the law drives the function on after
// a reading that no longer moves, the oil it asks for arrives as real motion the firmware cannot see,
// and the machine leaves its path unseen. Oil asked through an open valve must show somewhere: as
// motion or as the oil column's compression (a function stalled on a rock or an end stop compresses
// it as much as asked). So, per function, a set counts when
//   the position reading is bit-identical to the last one,
//   the lagged commanded flow per area asks more than frozen_speed (a motion of many sensor quanta
//     over the window), no chamber of it at a relief, and
//   of the displacement asked its way over the flow monitor's window, less than half arrived as
//     motion or compression;
// frozen_sets such sets in a row are a fault (the flow monitor's, emergency stop: "no motion"). A
// function that truly does not move while driven (a spool stuck near centre, a dead actuator) shows
// the same and is found the same way: the firmware cannot tell the two apart, and both are faults.
// Fixed-size state, no allocation.
#include <cmath>
#include <cstdint>

#include "safety/velocity_plausibility.hpp"
#include "model/types.hpp"

namespace exc::safety {

class FrozenPosition {
 public:
  FrozenPosition() = default;
  explicit FrozenPosition(const PlausibilitySettings& s) : s_(s) {}

  // One cycle, after the flow monitor's own update: its sums, the position reading, the functions at a
  // relief (bit i). Returns the functions found frozen this cycle (bit i), once per episode.
  std::uint8_t update(bool active, const VelocityPlausibility& flow, const Vec4& position, std::uint8_t at_relief) {
    std::uint8_t found = 0;
    for (int i = 0; i < 4; ++i) {
      const double expected = flow.expected()[i];
      const double asked_its_way = expected >= 0 ? flow.asked_positive()[i] : flow.asked_negative()[i];
      const double arrived_its_way = expected >= 0 ? flow.delivered()[i] : -flow.delivered()[i];
      const bool counts = active && primed_ && position[i] == last_position_[i] && ((at_relief >> i) & 1) == 0 &&
                          std::abs(expected) > s_.frozen_speed[i] && arrived_its_way < 0.5 * asked_its_way;
      run_[i] = counts ? run_[i] + 1 : 0;
      if (run_[i] == s_.frozen_sets) found |= static_cast<std::uint8_t>(1u << i);
    }
    last_position_ = position;
    primed_ = active;
    return found;
  }
  int run(int function) const { return run_[function]; }  // sets counted in a row now
  const PlausibilitySettings& settings() const { return s_; }

 private:
  PlausibilitySettings s_;
  bool primed_ = false;
  Vec4 last_position_ = Vec4::Zero();
  Eigen::Vector4i run_ = Eigen::Vector4i::Zero();
};

}  // namespace exc::safety
