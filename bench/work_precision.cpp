#include "work_precision.hpp"

#include <algorithm>
#include <fstream>
#include <limits>
#include <stdexcept>

#include "bench_common.hpp"
#include "output_files/output_file.hpp"

namespace exc::bench {

std::vector<WorkPoint> work_precision(const std::vector<BenchScene>& scenes, const std::vector<double>& steps,
                                      double reference_step, std::vector<OpenLoopResult>& references) {
  std::vector<WorkPoint> points;
  for (const BenchScene& s : scenes) {
    const EffortProfile profile = effort_profile(s);
    progress("work-precision %s: reference (rk4/independent at %s)\n", s.name, step_label(reference_step));
    OpenLoopSettings ref_settings;
    ref_settings.integrator = settings_of("rk4", plant::Formulation::independent, reference_step);
    references.push_back(run_open_loop(s, profile, ref_settings));
    const OpenLoopResult& ref = references.back();
    if (!ref.ok) throw std::runtime_error("the fine-step reference of " + s.name + " failed: " + ref.failure);
    for (const std::string& m : bench_methods())
      for (plant::Formulation f : kFormulations) {
        progress("work-precision %s: %s\n", s.name, method_name(m, f));
        for (double h : steps) {
          OpenLoopSettings st;
          st.integrator = settings_of(m, f, h);
          st.plant_energy_check = false;
          const OpenLoopResult r = run_open_loop(s, profile, st);
          WorkPoint p;
          p.scene = s.name;
          p.method = method_name(m, f);
          p.step = h;
          p.ok = r.ok;
          p.failure = r.failure;
          p.cpu_per_s = r.simulated > 0 ? r.cpu_seconds / r.simulated : std::numeric_limits<double>::quiet_NaN();
          p.tip_rms = r.ok ? rms_distance(r.tip, ref.tip) : std::numeric_limits<double>::quiet_NaN();
          p.constraint = r.max_constraint_residual;
          p.energy = r.max_energy_error;
          points.push_back(p);
        }
      }
  }
  // Pareto front per scene: no other successful point is both cheaper and more accurate.
  for (WorkPoint& p : points) {
    if (!p.ok) continue;
    p.pareto = true;
    for (const WorkPoint& q : points)
      if (&q != &p && q.ok && q.scene == p.scene && q.cpu_per_s <= p.cpu_per_s && q.tip_rms <= p.tip_rms &&
          (q.cpu_per_s < p.cpu_per_s || q.tip_rms < p.tip_rms)) {
        p.pareto = false;
        break;
      }
  }
  return points;
}

void write_work_csv(const std::string& path, const std::vector<WorkPoint>& points) {
  std::ofstream f = output::open_file(path);
  f << "scene,method,step_s,ok,cpu_s_per_sim_s,tip_rms_m,constraint_residual_m,energy_drift_J,pareto,failure\n";
  f.precision(6);
  for (const WorkPoint& p : points) {
    std::string failure = p.failure;
    std::replace(failure.begin(), failure.end(), ',', ';');
    std::replace(failure.begin(), failure.end(), '\n', ' ');
    f << p.scene << ',' << p.method << ',' << p.step << ',' << (p.ok ? 1 : 0) << ',' << p.cpu_per_s << ','
      << p.tip_rms << ',' << p.constraint << ',' << p.energy << ',' << (p.pareto ? 1 : 0) << ",\"" << failure << "\"\n";
  }
  output::finish_file(f, path);
}

}  // namespace exc::bench
