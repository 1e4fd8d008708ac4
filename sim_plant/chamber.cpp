#include "sim_plant/chamber.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace exc::plant {

ChamberFlows chamber_flows(const ChamberValves& v, double p, double& dnet_dp) {
  ChamberFlows q;
  dnet_dp = 0;
  double f, df;
  if (v.meter_in_gain > 0) {
    const double drop = std::min(v.margin, v.supply_limit - p);
    if (drop > 0) {
      orifice_flow(drop, v.laminar, f, df);
      q.meter_in = v.meter_in_gain * f;
      // The drop follows p only once the pump is at its limit; before, the compensator holds it.
      if (v.supply_limit - p < v.margin) dnet_dp -= v.meter_in_gain * df;
    }
  }
  if (v.meter_out_gain > 0) {
    orifice_flow(p - v.tank, v.laminar, f, df);
    q.meter_out = v.meter_out_gain * f;
    dnet_dp -= v.meter_out_gain * df;
  }
  if (v.makeup_gain > 0 && p < v.tank) {
    orifice_flow(v.tank - p, v.laminar, f, df);
    q.makeup = v.makeup_gain * f;
    dnet_dp -= v.makeup_gain * df;
  }
  if (v.relief_gain > 0 && p > v.relief_setting) {
    q.relief = v.relief_gain * (p - v.relief_setting);
    dnet_dp -= v.relief_gain;
  }
  q.leakage = v.leakage_gain * (p - v.tank);
  dnet_dp -= v.leakage_gain;
  q.cross = v.cross_inflow;
  return q;
}

namespace {

// The flows at p, and the end pressure that satisfies the discrete balance with exactly these flows,
// so that the volume (and energy) bookkeeping closes to round-off; below the floor the make-up could
// not keep up and the missing oil is a vapour void.
void close_balance(const ChamberValves& v, double p, double p0, double c, double dt, double swept, double floor,
                   bool may_void, ChamberStep& out) {
  double unused;
  const ChamberFlows q = chamber_flows(v, p, unused);
  double p1 = p0 + (dt * q.net() - swept) / c;
  if (p1 < floor && may_void) {
    out.void_volume = c * (floor - p1);
    p1 = floor;
  }
  out.pressure = p1;
  out.flows = q;
}

}  // namespace

ChamberStep step_chamber(const ChamberValves& v, double p0, double volume, double bulk_modulus, double dt,
                         double swept, double floor) {
  const double c = volume / bulk_modulus;  // m^3/Pa, the chamber's capacitance
  // G(p) = c (p - p0) + swept - dt Q(p), strictly increasing (G' >= c).
  double lo = -std::numeric_limits<double>::infinity(), hi = std::numeric_limits<double>::infinity();
  double p = p0;
  ChamberStep out;
  ChamberFlows q;
  constexpr int kMaxIterations = 60;
  for (int it = 0; it < kMaxIterations; ++it) {
    double dq;
    q = chamber_flows(v, p, dq);
    const double g = c * (p - p0) + swept - dt * q.net();
    out.iterations = it + 1;
    if (g == 0) break;
    if (g > 0) hi = std::min(hi, p);
    else lo = std::max(lo, p);
    const double step = -g / (c - dt * dq);
    // 1e-12 relative: the last correction is below round-off of the pressures that matter.
    const double tolerance = 1e-12 * (std::abs(p) + 1e6);
    if (std::abs(step) <= tolerance) {
      p += step;
      break;
    }
    double next = p + step;
    // Newton left the bracket (a kink between the iterate and the root): bisect instead.
    if (!(next > lo && next < hi)) {
      next = 0.5 * (lo + hi);
      if (hi - lo <= tolerance) {
        p = next;
        break;
      }
    }
    p = next;
  }
  // Below the floor the make-up could not keep up: the chamber stays at the floor and the missing
  // oil is a vapour void, with the flows of the floor pressure.
  if (p < floor) p = floor;
  close_balance(v, p, p0, c, dt, swept, floor, true, out);
  return out;
}

ChamberStep step_chamber_explicit(const ChamberValves& v, double p0, double volume, double bulk_modulus, double dt,
                                  double swept, double floor) {
  ChamberStep out;
  // A void opens only where the step saw the make-up valve open (p0 below tank); from above it the
  // pressure is left below the floor for the plant's pressure check (chamber.hpp).
  close_balance(v, p0, p0, volume / bulk_modulus, dt, swept, floor, p0 < v.tank, out);
  return out;
}

}  // namespace exc::plant
