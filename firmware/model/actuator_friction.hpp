#pragma once
// Friction of the hydraulic functions (docs/plant.md, "Friction and leakage"; hydraulics.md), the
// usual lumped form per function i (swing, boom, arm, bucket):
//   F_i(v) = Fc_i (1 + (Kbrk - 1) exp(-|v| / v_brk,i)) sign(v) + b_i v,
//   Fc_i   = preload_i + c_i (p_A + p_B),
// seal friction growing with the chamber pressures; the static (breakaway) friction is Kbrk Fc_i,
// the Stribeck curve's value at rest. The swing's preload carries its motor's breakaway torque,
// swing_breakaway_pressure x D (D its displacement at the swing axis) over Kbrk. Both sides derive it
// from a machine: the plant from its true machine (as impulses, sim_plant/coulomb_friction.hpp), the
// firmware from its nominal one. Start-up code builds it; the functions are for every step.
#include "model/machine.hpp"

namespace exc {

struct ActuatorFriction {
  Vec4 preload = Vec4::Zero();               // N m (swing), N: Fc at zero pressure
  Vec4 pressure_coefficient = Vec4::Zero();  // N m/Pa, N/Pa: Fc per Pa of p_A + p_B
  Vec4 stribeck_velocity = Vec4::Ones();     // rad/s, m/s
  Vec4 viscous = Vec4::Zero();               // N m s/rad, N s/m
  double breakaway_ratio = 1;                // Kbrk: static over Coulomb friction
};

// From machine.hydraulics (the swing's displacement from the machine's hydraulic geometry).
ActuatorFriction actuator_friction(const Machine& machine);

// The Coulomb level Fc of each function at these chamber pressures (Pa).
Vec4 coulomb_level(const ActuatorFriction& f, const Vec4& p_a, const Vec4& p_b);

// The dry friction's magnitude at speed v with Coulomb level fc: fc (1 + (Kbrk - 1) exp(-|v| / v_brk));
// at rest it is the static friction Kbrk fc.
double dry_friction(const ActuatorFriction& f, int function, double fc, double v);

// The whole friction force of a function moving at v (signed with v; 0 at rest, where the static
// friction holds whatever is below it): dry_friction sign(v) + b v.
double friction_force(const ActuatorFriction& f, int function, double v, double p_a, double p_b);

}  // namespace exc
