#include "model/hydraulic_geometry.hpp"

#include <cmath>

namespace exc {

HydraulicGeometry hydraulic_geometry(const Machine& machine) {
  const HydraulicParameters& h = machine.hydraulics;
  const Vec4 effort_min = machine.effort_min(), effort_max = machine.effort_max(), speed_max = machine.speed_max();
  const double margin_flow = orifice_unit_flow(h.load_sensing_margin, h.laminar_pressure);
  const double out_flow = orifice_unit_flow(h.valve_pressure_drop, h.laminar_pressure);
  HydraulicGeometry g;
  for (int i = 0; i < kNumActive; ++i) {
    g.area_a[i] = effort_max[i] / machine.relief_pressure;
    g.area_b[i] = -effort_min[i] / machine.relief_pressure;
    g.meter_in_a[i] = g.area_a[i] * speed_max[i] / margin_flow;
    g.meter_in_b[i] = g.area_b[i] * speed_max[i] / margin_flow;
    g.meter_out_a[i] = g.area_a[i] * speed_max[i] / out_flow;
    g.meter_out_b[i] = g.area_b[i] * speed_max[i] / out_flow;
  }
  return g;
}

}  // namespace exc
