#include "safety/state_machine.hpp"

namespace exc::safety {

const char* to_string(Mode m) {
  switch (m) {
    case Mode::init: return "init";
    case Mode::wait_sensors: return "wait_sensors";
    case Mode::hold: return "hold";
    case Mode::track: return "track";
    case Mode::safe_stop: return "safe_stop";
  }
  return "unknown";
}

}  // namespace exc::safety
