#pragma once
// The hydraulic geometry both sides derive from a machine (docs/plant.md, "The hydraulic machine"):
// the plant's circuit runs on it with the true machine, the firmware's valve loop with its nominal
// one. From the machine file's numbers:
//   areas      push = bore area x relief, pull = annulus area x relief (machine.md): A_A = F_max / p_r,
//              A_B = -F_min / p_r; the swing's torque limit gives its displacement at the swing axis
//              (motor displacement x reduction), D = T_max / p_r on both ports;
//   meter-in   fully open it passes the speed-limit flow A v_max at the load-sensing margin (the
//              machine's speeds are pump flow over piston area): K_in = A v_max / q(margin);
//   meter-out  fully open it passes the speed-limit return flow at hydraulics.valve_pressure_drop:
//              K_out = A v_max / q(valve_pressure_drop);
// with q(dp) the orifice law for unit gain and opening (hydraulics.md): Q = K a sqrt(dp), linear
// below hydraulics.laminar_pressure. Start-up code, except the orifice law (used every substep).
#include <cmath>

#include "model/machine.hpp"

namespace exc {

// Flow for unit gain and opening, and its derivative with respect to dp. Linear below the laminar
// pressure (meeting the square root there) so that the flow and its derivative stay finite at dp = 0.
// Inline: the plant's chamber solver and the firmware's valve loop and pressure monitor call it a few
// dozen times a cycle with arguments the compiler can often fold.
inline void orifice_flow(double dp, double laminar_pressure, double& flow, double& dflow_ddp) {
  const double a = std::abs(dp);
  if (a < laminar_pressure) {
    // Linear branch meeting sqrt at dp = laminar_pressure (same value there).
    const double s = 1.0 / std::sqrt(laminar_pressure);
    flow = dp * s;
    dflow_ddp = s;
  } else {
    const double r = std::sqrt(a);
    flow = dp > 0 ? r : -r;
    dflow_ddp = 0.5 / r;
  }
}
// The flow alone.
inline double orifice_unit_flow(double dp, double laminar_pressure) {
  double f, df;
  orifice_flow(dp, laminar_pressure, f, df);
  return f;
}

// Per function, swing, boom, arm, bucket; side A is the bore side (extends) and the swing's port A
// (swings counter-clockwise), side B the annulus and port B.
struct HydraulicGeometry {
  Vec4 area_a = Vec4::Zero(), area_b = Vec4::Zero();  // m^2; swing: displacement m^3/rad
  // Fully open orifice gains, m^3/s/sqrt(Pa): meter-in into each side, meter-out from each side.
  Vec4 meter_in_a = Vec4::Zero(), meter_in_b = Vec4::Zero();
  Vec4 meter_out_a = Vec4::Zero(), meter_out_b = Vec4::Zero();
};

HydraulicGeometry hydraulic_geometry(const Machine& machine);

}  // namespace exc
