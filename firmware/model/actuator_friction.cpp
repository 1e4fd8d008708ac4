#include "model/actuator_friction.hpp"

#include <cmath>

#include "model/hydraulic_geometry.hpp"

namespace exc {

ActuatorFriction actuator_friction(const Machine& machine) {
  const HydraulicParameters& h = machine.hydraulics;
  ActuatorFriction f;
  f.preload = h.seal_preload;
  f.pressure_coefficient = h.seal_pressure_friction;
  f.stribeck_velocity = h.stribeck_velocity;
  f.viscous = h.viscous_friction;
  f.breakaway_ratio = h.breakaway_ratio;
  // The swing motor starts turning at its breakaway pressure: static torque p_brk D = Kbrk Fc.
  const double displacement = hydraulic_geometry(machine).area_a[0];
  f.preload[0] += h.swing_breakaway_pressure * displacement / h.breakaway_ratio;
  return f;
}

Vec4 coulomb_level(const ActuatorFriction& f, const Vec4& p_a, const Vec4& p_b) {
  return f.preload + f.pressure_coefficient.cwiseProduct(p_a + p_b);
}

double dry_friction(const ActuatorFriction& f, int function, double fc, double v) {
  return fc * (1.0 + (f.breakaway_ratio - 1.0) * std::exp(-std::abs(v) / f.stribeck_velocity[function]));
}

double friction_force(const ActuatorFriction& f, int function, double v, double p_a, double p_b) {
  if (v == 0) return 0;
  const double fc = f.preload[function] + f.pressure_coefficient[function] * (p_a + p_b);
  return std::copysign(dry_friction(f, function, fc, v), v) + f.viscous[function] * v;
}

}  // namespace exc
