#pragma once
// A pilot-operated main-valve spool (hydraulics.md): the pilot pressures on its two ends push it
// against its centring springs, it follows with a first-order lag, and its metering notches stay
// closed over a dead zone (the spool's overlap) in each direction before they open.

namespace exc::plant {

// The spool position a signed opening command or a pair of pilot pressures asks for (-1..1; the
// pilot difference over the full-stroke pressure, clamped).
double spool_target_from_opening(double opening);
double spool_target_from_pilots(double pilot_a, double pilot_b, double full_stroke_pressure);

// First-order lag toward the target over dt, solved exactly (no step-size limit): the spool moves
// the fraction spool_lag_gain(time_constant, dt) = 1 - exp(-dt / time_constant) of the way, a gain
// computed once per substep for every spool.
double spool_lag_gain(double time_constant, double dt);
double spool_lag(double spool, double target, double gain);

// The metering opening 0..1 the spool gives in its direction: zero inside the dead zone of that
// direction, then linear to full at full stroke.
double metering_opening(double spool, double dead_zone_extend, double dead_zone_retract);

}  // namespace exc::plant
