// The pressure monitor's limits from the nominal machine's hydraulics section (start-up).
#include "safety/pressure_plausibility.hpp"

namespace exc::safety {

const char* to_string(PressureTest test) {
  switch (test) {
    case PressureTest::none: return "none";
    case PressureTest::range: return "out of range";
    case PressureTest::step: return "jumped";
    case PressureTest::frozen: return "frozen";
  }
  return "unknown";
}

PressureLimits pressure_limits(const Machine& nominal, const PressurePlausibilitySettings& s) {
  const HydraulicParameters& h = nominal.hydraulics;
  const HydraulicGeometry g = hydraulic_geometry(nominal);
  PressureLimits l;
  l.area_a = g.area_a;
  l.area_b = g.area_b;
  l.q_min = nominal.q_min();
  l.q_max = nominal.q_max();
  l.speed_max = nominal.speed_max();
  l.bulk_modulus = h.bulk_modulus;
  l.dead_volume = h.dead_volume;
  l.swing_volume = h.swing_volume;
  l.pump_flow = h.pump_flow;
  l.tank_pressure = h.tank_pressure;
  l.laminar_pressure = h.laminar_pressure;
  for (int i = 0; i < kNumActive; ++i) {
    // A chamber is loaded by its port relief (or the swing's) or, pushed by the pumps, their limit;
    // a relief passes the pumps' flow at its override above the setting.
    const double relief = std::max(i == 0 ? h.swing_relief_pressure : h.port_relief_pressure, h.pump_pressure_limit());
    const double floor = std::min(h.vapour_pressure, h.tank_pressure - h.makeup_pressure_drop);
    l.floor[i] = floor - s.range_margin;
    l.top[i] = relief + h.relief_override + s.range_margin;
    l.clamp_low[i] = h.tank_pressure;
    l.clamp_high[i] = std::min(i == 0 ? h.swing_relief_pressure : h.port_relief_pressure, h.pump_pressure_limit());
    l.meter_out_a[i] = g.meter_out_a[i];
    l.meter_out_b[i] = g.meter_out_b[i];
  }
  return l;
}

}  // namespace exc::safety
