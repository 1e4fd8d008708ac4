#include "safety/firmware_faults.hpp"

namespace exc::safety {

const char* to_string(FirmwareFault fault) {
  switch (fault) {
    case FirmwareFault::none: return "none";
    case FirmwareFault::sensor_timeout: return "sensor timeout";
    case FirmwareFault::model: return "model";
    case FirmwareFault::tracking_error: return "tracking error";
    case FirmwareFault::no_pressures: return "no pressures";
    case FirmwareFault::pump_limited: return "pumps short of flow";
    case FirmwareFault::plant_emergency: return "plant emergency";
    case FirmwareFault::plant_fault: return "plant fault";
    case FirmwareFault::plant_holding: return "plant holding";
    case FirmwareFault::deadline_overrun: return "missed deadlines";
    case FirmwareFault::velocity_implausible: return "velocity implausible";
    case FirmwareFault::exited: return "firmware exited";
    case FirmwareFault::fatal_error: return "firmware fatal error";
    case FirmwareFault::operator_stop: return "operator stop";
    case FirmwareFault::operator_link_lost: return "operator link lost";
    case FirmwareFault::pressure_implausible: return "pressure implausible";
    case FirmwareFault::spool_disagreement: return "spool disagreement";
  }
  return "unknown";
}

const char* to_string(StopKind stop) {
  switch (stop) {
    case StopKind::none: return "none";
    case StopKind::controlled: return "controlled";
    case StopKind::emergency: return "emergency";
  }
  return "unknown";
}

}  // namespace exc::safety
