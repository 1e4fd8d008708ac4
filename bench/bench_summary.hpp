#pragma once
// excavator-bench's summary of one run: the figures of its JSON file (--json, OUT/bench.json) and the
// table it prints, from the charts' results.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fidelity_chart.hpp"
#include "peer_comparison.hpp"
#include "pressure_integration.hpp"
#include "stability_map.hpp"
#include "work_precision.hpp"

namespace exc::bench {

struct BenchResults {
  const std::vector<WorkPoint>& work;
  const std::vector<PeerResult>& peers;  // the first (free motion) gives the headline figures
  const PressureChart& pressures;
  const std::vector<FidelityRow>& fidelity;
  const StabilityMaps& maps;
};

// The headline figures, the Pareto front, each scene's peer figures, the pressure boundaries and the
// recommended fidelities (the caller adds the run's own fields).
nlohmann::json summary_json(const BenchResults& r);

// The summary table on stdout (OUT named in its head).
void print_summary(const BenchResults& r, bool quick, const std::string& out);

}  // namespace exc::bench
