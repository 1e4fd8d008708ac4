#include "fidelity_chart.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>

#include "bench_common.hpp"
#include "output_files/output_file.hpp"

namespace exc::bench {

double worst_tracking(const ClosedLoopResult& r) {
  return *std::max_element(std::begin(r.tracking_rms), std::end(r.tracking_rms));
}

std::vector<FidelityRow> fidelity_chart(const std::vector<BenchScene>& scenes, double duration, int repeats) {
  std::vector<FidelityRow> rows;
  for (const BenchScene& s : scenes) {
    struct Variant {
      std::string name;
      ClosedLoopVariant v;
    };
    std::vector<Variant> variants;
    auto add = [&](const std::string& name, const char* f, bool soil, bool massless, bool dry = true) {
      Variant x;
      x.name = name;
      x.v.fidelity = f;
      x.v.soil = soil;
      x.v.massless_cylinders = massless;
      x.v.dry_friction_and_leakage = dry;
      x.v.duration = duration;
      variants.push_back(x);
    };
    // The first variant that runs is the reference: the most complete model. The second is the
    // hydraulic machine as it was before its friction and leakage (viscous friction only).
    add("12-link + hydraulic + soil", "hydraulic", true, false);
    add("12-link + hydraulic without dry friction and leakage + soil", "hydraulic", true, false, false);
    add("12-link + limited + soil", "limited", true, false);
    add("12-link + ideal + soil", "ideal", true, false);
    add("massless cylinders + ideal + soil", "ideal", true, true);
    add("12-link + ideal + no soil", "ideal", false, false);
    add("massless cylinders + ideal + no soil", "ideal", false, true);
    std::vector<ClosedLoopResult> results;
    for (const Variant& x : variants) {
      progress("fidelity %s: %s\n", s.name, x.name);
      ClosedLoopResult best = run_closed_loop(s, x.v);
      for (int k = 1; k < repeats && best.ok; ++k) {
        const ClosedLoopResult again = run_closed_loop(s, x.v);
        best.cpu_seconds = std::min(best.cpu_seconds, again.cpu_seconds);
      }
      results.push_back(std::move(best));
    }
    int ref = -1;
    for (std::size_t i = 0; i < results.size() && ref < 0; ++i)
      if (results[i].ok) ref = static_cast<int>(i);
    double ref_force = 0;
    if (ref >= 0) {
      for (const Vec4& e : results[ref].effort) ref_force += e.tail<3>().squaredNorm();
      ref_force = std::sqrt(ref_force / std::max<std::size_t>(1, results[ref].effort.size()));
    }
    for (std::size_t i = 0; i < results.size(); ++i) {
      const ClosedLoopResult& r = results[i];
      FidelityRow row;
      row.scene = s.name;
      row.fidelity = variants[i].name;
      row.ok = r.ok;
      row.reference = static_cast<int>(i) == ref;
      row.failure = r.failure;
      if (r.ok && ref >= 0) {
        const ClosedLoopResult& R = results[ref];
        row.cpu_per_s = r.cpu_seconds / r.simulated;
        row.cost_ratio = row.cpu_per_s / (R.cpu_seconds / R.simulated);
        row.tip_rms = rms_distance(r.tip, R.tip);
        double sum = 0;
        const std::size_t n = std::min(r.effort.size(), R.effort.size());
        for (std::size_t k = 0; k < n; ++k) sum += (r.effort[k] - R.effort[k]).tail<3>().squaredNorm();
        row.force_rel = n ? std::sqrt(sum / static_cast<double>(n)) / std::max(ref_force, 1.0) : NAN;
        row.tracking = worst_tracking(r);
        row.tracking_diff = std::abs(row.tracking - worst_tracking(R));
        row.within = row.tip_rms <= kTipTolerance && row.force_rel <= kForceTolerance &&
                     row.tracking_diff <= kTrackingTolerance;
      }
      rows.push_back(row);
    }
    // The cheapest within tolerance; costs within kCostNoise of it count as equal (this machine's
    // timing noise), and among those the least model wins: variants run from the most complete down.
    const std::size_t first = rows.size() - results.size();
    double cheapest = std::numeric_limits<double>::infinity();
    for (std::size_t i = first; i < rows.size(); ++i)
      if (rows[i].within) cheapest = std::min(cheapest, rows[i].cpu_per_s);
    for (std::size_t i = rows.size(); i-- > first;)
      if (rows[i].within && rows[i].cpu_per_s <= cheapest * (1 + kCostNoise)) {
        rows[i].recommended = true;
        break;
      }
  }
  return rows;
}

void write_fidelity_csv(const std::string& path, const std::vector<FidelityRow>& rows) {
  std::ofstream f = output::open_file(path);
  f << "scene,fidelity,ok,reference,cpu_s_per_sim_s,cost_ratio,tip_rms_m,force_rel,tracking_rms,tracking_diff,"
       "within_tolerance,recommended,failure\n";
  for (const FidelityRow& r : rows) {
    std::string failure = r.failure;
    std::replace(failure.begin(), failure.end(), ',', ';');
    f << r.scene << ',' << r.fidelity << ',' << r.ok << ',' << r.reference << ',' << r.cpu_per_s << ',' << r.cost_ratio
      << ',' << r.tip_rms << ',' << r.force_rel << ',' << r.tracking << ',' << r.tracking_diff << ',' << r.within << ','
      << r.recommended << ",\"" << failure << "\"\n";
  }
  output::finish_file(f, path);
}

}  // namespace exc::bench
