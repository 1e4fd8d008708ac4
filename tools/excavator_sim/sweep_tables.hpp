#pragma once
// The sweep spec's enumerations and the knobs a case can set, per run kind (docs/sweeps.md lists the
// same names; tests/sim checks the rows).
#include <string>
#include <vector>

#include "settings/enum_table.hpp"
#include "sim_plant/integrators.hpp"
#include "sweep.hpp"

namespace exc::sim {

inline constexpr settings::EnumTable<SweepRun, 2> kSweepRuns{{{
    {SweepRun::closed_loop, "closed_loop", "firmware and plant in SYNC lockstep (run_lockstep), each controller"},
    {SweepRun::open_loop, "open_loop", "the plant alone under excavator-bench's effort profile (its step map)"},
}}};

// sweep.csv (a row per case) and sweep.json's missing cases are always written.
enum class SweepRecord : std::uint8_t { failures, robustness, stability };
inline constexpr settings::EnumTable<SweepRecord, 3> kSweepRecords{{{
    {SweepRecord::failures, "failures", "sweep.json's failed runs by region, by set value and by kind"},
    {SweepRecord::robustness, "robustness", "robustness.png: RMS error per variant (or the draws' spread)"},
    {SweepRecord::stability, "stability", "stability.png: ok / failed and tracking over the grid's axes"},
}}};

// "method/formulation", both from the integrator's tables.
inline bool integrator_name(const std::string& s) {
  const auto slash = s.find('/');
  return slash != std::string::npos && plant::kIntegrationMethods.named(s.substr(0, slash)) &&
         plant::kFormulations.named(s.substr(slash + 1));
}

struct KnobInfo {
  const char* name;
  double lo, hi;
  bool joints;                            // also takes four values, one per joint
  bool (*names)(const std::string&);      // takes a name checked by this (null: numbers)
  const char* what;
};

inline const std::vector<KnobInfo>& knob_table(SweepRun run) {
  static const std::vector<KnobInfo> closed = {
      {"model_mass", -0.9, 9, false, nullptr, "the firmware's link masses and inertias x (1 + value)"},
      {"soil_stiffness", 0.01, 100, false, nullptr, "the plant's soil K x value"},
      {"position_noise", 0, 0.1, true, nullptr, "sensor noise, m (rad on the swing), 1 sigma"},
      {"velocity_noise", 0, 1, true, nullptr, "sensor velocity noise, m/s (rad/s), 1 sigma"},
      {"delay_cycles", 0, 100, false, nullptr, "sensor latency, whole cycles"},
      {"gain_scale", 0.01, 100, false, nullptr, "the outer law's omega_n x value (kp x s^2, kv x s, ki x s^3, Slotine-Li x s)"},
      {"adaptation_scale", 1e-6, 1e6, false, nullptr, "adaptation rates x value"},
      {"controller.valves.force_time_constant", 1e-3, 1, false, nullptr, "s, the valve stage's force loop T_f"},
      {"controller.valves.position_gain", 0, 100, true, nullptr, "1/s, the valve stage's flow feedforward position gain"},
      {"machine.hydraulics.valve_time_constant", 0, 1, false, nullptr, "s, the plant's spool lag (the firmware keeps its own)"},
      {"machine.hydraulics.bulk_modulus", 1e7, 5e9, false, nullptr, "Pa, the plant's oil (the firmware keeps its own)"},
  };
  static const std::vector<KnobInfo> open = {
      {"integrator", 0, 0, false, integrator_name, "must be method/formulation, e.g. rk4/augmented_baumgarte"},
      {"integrator.step", 1e-6, 1e-2, false, nullptr, "s, the plant's step (divides the profile's 10 ms hold)"},
      {"soil.stiffness", 1, 1e10, false, nullptr, "N/m, the soil's K_t (its damping ratio kept)"},
      {"profile.speed", 0.1, 10, false, nullptr, "the task run this many times faster"},
  };
  return run == SweepRun::open_loop ? open : closed;
}

inline std::string knob_names(SweepRun run) {
  std::string s;
  for (const KnobInfo& k : knob_table(run)) s += (s.empty() ? "" : ", ") + std::string(k.name);
  return s;
}

inline std::vector<std::string> sweep_knobs(SweepRun run) {
  std::vector<std::string> v;
  for (const KnobInfo& k : knob_table(run)) v.emplace_back(k.name);
  return v;
}

}  // namespace exc::sim
