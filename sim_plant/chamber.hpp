#pragma once
// One oil chamber (a cylinder side or a swing-motor port) over one substep. The pressure obeys
// dp/dt = beta / V (Q - dV/dt) (hydraulics.md), stiff because beta / V is large and the orifices
// couple the pressure to itself (beta / V * dQ/dp reaches 1e4 1/s). It is integrated by backward
// Euler in the chamber's own pressure, with the piston's swept volume from the mechanical step:
//   V1 / beta (p1 - p0) = dt Q(p1) - dV
// Every element's net inflow Q(p) (meter-in, make-up, minus meter-out, minus relief, minus leakage to
// tank; the leakage across the piston is fixed over the substep) is non-increasing in p, so the left
// side minus the right is strictly increasing in p1: one root, found by Newton's method safeguarded
// by bisection once bracketed. Unconditionally stable, no overshoot past a relief setting or below
// the make-up valve's tank pressure.
// The alternative (integrator.pressure_method forward_euler) takes the flows at the start pressure:
//   V1 / beta (p1 - p0) = dt Q(p0) - dV
// one flow evaluation, no solve. It overshoots a valve that opens within the step (a make-up valve
// below tank, a relief above its setting): bounded where the valve is one-sided, but a chamber that
// falls from above tank to below the vapour floor in one step jumped the make-up valve it never saw.
// That is no vapour void but an unresolved step: the pressure is left below the floor, and the
// plant's pressure check stops the run (docs/bench.md has where on which input).
#include "model/hydraulic_geometry.hpp"
#include "settings/enum_table.hpp"

namespace exc::plant {

enum class PressureMethod { backward_euler, forward_euler };
// The names a scene's integrator.pressure_method takes.
inline constexpr settings::EnumTable<PressureMethod, 2> kPressureMethods{{{
    {PressureMethod::backward_euler, "backward_euler", "implicit per chamber and substep, unconditionally stable (the default)"},
    {PressureMethod::forward_euler, "forward_euler", "explicit: each chamber's flows at the substep's start; overshoots the valves above a step the input sets"},
}}};
inline const char* to_string(PressureMethod m) { return kPressureMethods.name_of(m); }

// The valves connected to one chamber during a substep (all gains already include the opening).
struct ChamberValves {
  // Meter-in from the pump through a post-compensated orifice: drop = min(margin, supply_limit - p),
  // never negative (a load-check valve stops backflow into the pump).
  double meter_in_gain = 0;   // m^3/s/sqrt(Pa): K_in x the opening x the flow-sharing factor
  double margin = 0;          // Pa, the load-sensing margin (the compensated drop)
  double supply_limit = 0;    // Pa, the pump's pressure limit (main relief)
  // Meter-out to tank through the spool (either direction, an orifice).
  double meter_out_gain = 0;  // m^3/s/sqrt(Pa)
  double tank = 0;            // Pa
  // Anti-cavitation (make-up) check valve from the tank line, open while p < tank.
  double makeup_gain = 0;     // m^3/s/sqrt(Pa)
  // Port relief to tank: Q = gain (p - setting) above its setting (linear override).
  double relief_setting = 0;  // Pa
  double relief_gain = 0;     // m^3/s/Pa
  double laminar = 0;         // Pa, orifices are linear below this drop
  // Internal leakage, laminar: to tank past the centred spool (and a swing motor's case drain),
  // Q = leakage_gain (p - tank); and across the piston from the other chamber, a flow fixed over the
  // substep (from the starting pressures: hydraulics.cpp, piston_leakage_flow), which couples the two
  // chambers' solves no further.
  double leakage_gain = 0;    // m^3/(s Pa)
  double cross_inflow = 0;    // m^3/s, signed, into this chamber
};

struct ChamberFlows {
  double meter_in = 0, meter_out = 0, makeup = 0, relief = 0;  // m^3/s, each >= 0 except meter_out (signed, out)
  double leakage = 0;         // m^3/s to tank, signed (negative: from tank, below tank pressure)
  double cross = 0;           // m^3/s across the piston into this chamber, signed
  double net() const { return meter_in + makeup - meter_out - relief - leakage + cross; }
};

// Flows at pressure p; dnet_dp (<= 0) is the derivative of the net inflow.
ChamberFlows chamber_flows(const ChamberValves& v, double p, double& dnet_dp);

struct ChamberStep {
  double pressure = 0;     // Pa at the end of the substep (>= floor)
  ChamberFlows flows;      // over the substep (backward Euler: at the end pressure)
  double void_volume = 0;  // m^3 of vapour that opened because the make-up could not keep up (p hit the floor)
  int iterations = 0;      // Newton (and bisection) iterations used
};

// p0: pressure at the start; volume: chamber volume at the end; swept: how much the piston's (or
// motor's) motion grew the chamber during the substep (m^3, negative when it shrank it).
ChamberStep step_chamber(const ChamberValves& v, double p0, double volume, double bulk_modulus, double dt,
                         double swept, double floor);
// The same balance with the flows at p0 (forward Euler): one evaluation, iterations = 0.
ChamberStep step_chamber_explicit(const ChamberValves& v, double p0, double volume, double bulk_modulus, double dt,
                                  double swept, double floor);

}  // namespace exc::plant
