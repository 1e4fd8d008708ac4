#include "telemetry/lcm_output.hpp"

#include <lcm/lcm.h>

namespace exc::telemetry {

std::shared_ptr<LcmOutput> LcmOutput::open(const std::string& url, std::string* error) {
  lcm_t* lcm = lcm_create(url.c_str());
  if (lcm == nullptr) {
    if (error != nullptr) {
      *error = "telemetry: LCM cannot open provider '" + url +
               "' (expected udpm://GROUP:PORT?ttl=N, e.g. udpm://239.255.76.67:7667?ttl=0, or "
               "file://PATH?mode=w; for udpm the loopback may need multicast: "
               "ip link set lo multicast on; ip route add 239.255.0.0/16 dev lo)";
    }
    return nullptr;
  }
  return std::shared_ptr<LcmOutput>(new LcmOutput(lcm, url));
}

LcmOutput::~LcmOutput() { lcm_destroy(lcm_); }

bool LcmOutput::publish(const char* channel, const void* data, std::size_t size) {
  std::lock_guard<std::mutex> lock(mutex_);
  return lcm_publish(lcm_, channel, data, static_cast<unsigned int>(size)) == 0;
}

}  // namespace exc::telemetry
