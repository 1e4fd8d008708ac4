#pragma once
// The sweep spec's enumerations (docs/sweeps.md lists the same names; tests/sim checks the rows). The
// knobs a case can set: sweep_knobs.hpp.
#include <cstdint>

#include "settings/enum_table.hpp"
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

}  // namespace exc::sim
