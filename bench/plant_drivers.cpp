// excavator-plant-bench's drivers and probe (bench/plant_drivers.hpp).
#include "plant_drivers.hpp"

namespace exc::bench {

using namespace exc::plant;

Stats stats(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  Stats s;
  s.median = v[v.size() / 2];
  s.p99 = v[std::min(v.size() - 1, static_cast<std::size_t>(0.99 * v.size()))];
  s.max = v.back();
  return s;
}

bool stable_in_stiff_clay(const Scene& base, const std::string& m, Formulation f, double h, std::string& why) {
  Scene s = base;
  s.integrator.method = m;
  s.integrator.formulation = f;
  s.integrator.step = h;
  s.cycle = h;
  s.q_a0 = Vec4(0.0, 2.4626, 2.3231, 2.1447);
  s.qd_a0 = Vec4(0.05, -0.1, 0.05, -0.05);
  s.terrain = Terrain{};
  s.terrain.height = 1.93;
  s.soil = soil_preset(SoilPreset::stiff_clay);
  s.actuators.fidelity = "ideal";
  Plant p(s);
  ActuatorCommand c;
  c.value = p.hold_effort();
  const long n = std::lround(2.0 / h);
  for (long k = 0; k < n; ++k) {
    const PlantStatus st = p.step(c);
    if (!st.ok()) {
      why = st.text();
      return false;
    }
  }
  return true;
}


}  // namespace exc::bench
