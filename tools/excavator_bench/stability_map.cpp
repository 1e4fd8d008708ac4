#include "stability_map.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>

#include "fidelity_chart.hpp"

#include "bench_common.hpp"

namespace exc::bench {

namespace {

// Largest step of 'steps' (descending) at which the run passes the plant's own checks.
StepStability largest_stable_step(const BenchScene& s, const EffortProfile& profile, plant::IntegrationMethod m,
                                  plant::Formulation f, const std::vector<double>& steps, double soil_scale) {
  StepStability out;
  out.method = method_name(m, f);
  for (double h : steps) {
    OpenLoopSettings st;
    st.integrator = settings_of(m, f, h);
    st.soil_stiffness_scale = soil_scale;
    st.constraint_tolerance = 1e-4;  // the plant's default check
    const OpenLoopResult r = run_open_loop(s, profile, st);
    if (r.ok) {
      out.largest_stable_step = h;
      break;
    }
    out.failure_above = r.failure;
  }
  return out;
}

}  // namespace

std::vector<StepStability> step_stability_map(const BenchScene& dig, const BenchScene& free,
                                              const std::vector<double>& steps, const std::vector<double>& stiffness,
                                              const std::vector<double>& speeds) {
  std::vector<StepStability> rows;
  const EffortProfile dig_profile = effort_profile(dig);
  const double base_k = dig.scene.soil.stiffness.x() > 0 ? dig.scene.soil.stiffness.x() : 7e4;
  for (plant::IntegrationMethod m : kMethods)
    for (plant::Formulation f : kFormulations) {
      progress("stability %s: %s\n", method_name(m, f), "soil stiffness and joint speed");
      for (double k : stiffness) {
        StepStability r = largest_stable_step(dig, dig_profile, m, f, steps, k / base_k);
        r.axis = "soil_stiffness_N_per_m";
        r.value = k;
        rows.push_back(r);
      }
      for (double v : speeds) {
        const EffortProfile p = effort_profile(free, v);
        StepStability r = largest_stable_step(free, p, m, f, steps, 1.0);
        r.axis = "joint_speed_factor";
        r.value = v;
        rows.push_back(r);
      }
    }
  return rows;
}


std::vector<ControlStability> control_stability_map(const BenchScene& dig, double duration) {
  std::vector<ControlStability> rows;
  const control::ControllerKind kinds[] = {control::ControllerKind::pid, control::ControllerKind::adaptive,
                                           control::ControllerKind::slotine_li};
  struct Axis {
    const char* name;
    std::vector<double> values;
  };
  const std::vector<Axis> axes = {{"gain_scale", {0.5, 1, 2, 4, 8, 16}},
                                  {"adaptation_scale", {0.01, 1, 100, 1e4}},
                                  {"position_noise", {0, 1e-5, 1e-4, 1e-3}},
                                  {"delay_cycles", {0, 1, 2, 3}},
                                  {"model_mass_error", {-0.3, -0.1, 0, 0.1, 0.3}}};
  for (control::ControllerKind kind : kinds) {
    progress("stability %s: gain, adaptation, noise, delay, mass error%s\n", control::to_string(kind));
    for (const Axis& a : axes)
      for (double value : a.values) {
        if (kind == control::ControllerKind::pid && std::string(a.name) == "adaptation_scale") continue;
        ClosedLoopVariant v;
        v.controller = kind;
        v.fidelity = dig.scene.actuators.fidelity;  // the scene's own actuators, which its firmware config expects
        v.duration = duration;
        const std::string n = a.name;
        if (n == "gain_scale") v.gain_scale = value;
        if (n == "adaptation_scale") v.adaptation_scale = value;
        if (n == "position_noise") v.position_noise = value;
        if (n == "delay_cycles") v.delay_cycles = static_cast<int>(value);
        if (n == "model_mass_error") v.model_mass_error = value;
        const ClosedLoopResult r = run_closed_loop(dig, v);
        ControlStability row;
        row.controller = control::to_string(kind);
        row.axis = n;
        row.value = value;
        row.ok = r.ok;
        row.failure = r.failure;
        row.tracking = worst_tracking(r);
        rows.push_back(row);
      }
  }
  return rows;
}

void write_stability_csvs(const std::string& dir, const std::vector<StepStability>& steps,
                          const std::vector<ControlStability>& control) {
  std::ofstream f(dir + "/stability_step.csv");
  f << "method,axis,value,largest_stable_step_s,failure_at_next_larger_step\n";
  for (const StepStability& r : steps) {
    std::string failure = r.failure_above;
    std::replace(failure.begin(), failure.end(), ',', ';');
    f << r.method << ',' << r.axis << ',' << r.value << ',' << r.largest_stable_step << ",\"" << failure << "\"\n";
  }
  std::ofstream g(dir + "/stability_control.csv");
  g << "controller,axis,value,ok,tracking_rms_worst,failure\n";
  for (const ControlStability& r : control) {
    std::string failure = r.failure;
    std::replace(failure.begin(), failure.end(), ',', ';');
    g << r.controller << ',' << r.axis << ',' << r.value << ',' << r.ok << ',' << r.tracking << ",\"" << failure << "\"\n";
  }
}

}  // namespace exc::bench
