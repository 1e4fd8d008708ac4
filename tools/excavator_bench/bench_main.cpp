// excavator-bench: speed against accuracy (issue 8). One run writes the work-precision chart, the
// fidelity chart, the stability maps and the MuJoCo comparison (CSV + PNG each), a summary table on
// stdout and --json FILE. `excavator-bench export-mjcf` writes the machine as MJCF.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "bench_runs.hpp"
#include "control/make_controller.hpp"
#include "mjcf_export.hpp"
#include "model/closed_chain.hpp"
#include "model/loop_closure.hpp"
#include "sim_plant/plant.hpp"
#ifdef EXC_HAVE_MUJOCO
#include "mujoco_peer.hpp"
#endif

namespace fs = std::filesystem;
using nlohmann::json;

namespace exc::bench {
namespace {

struct Options {
  bool quick = false;
  std::string out = "out/bench";
  std::string json_file;
  std::string scenes_dir = EXC_SOURCE_DIR "/scenes";
  bool plots = true;
};

// Numbers that may be absent (a failed run, a skipped peer) go to JSON as null, never NaN.
json number_or_null(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

constexpr int kBatch = 10;

void progress(const char* format, const std::string& a, const std::string& b = "") {
  std::fprintf(stderr, format, a.c_str(), b.c_str());
  std::fflush(stderr);
}

std::string step_label(double h) {
  char buf[32];
  if (h >= 1e-3) std::snprintf(buf, sizeof buf, "%g ms", h * 1e3);
  else std::snprintf(buf, sizeof buf, "%g us", h * 1e6);
  return buf;
}

constexpr plant::IntegrationMethod kMethods[] = {plant::IntegrationMethod::semi_implicit_euler,
                                                 plant::IntegrationMethod::rk4,
                                                 plant::IntegrationMethod::implicit_midpoint};
constexpr plant::Formulation kFormulations[] = {plant::Formulation::independent,
                                                plant::Formulation::augmented_baumgarte,
                                                plant::Formulation::augmented_projection};

std::string method_name(plant::IntegrationMethod m, plant::Formulation f) {
  return std::string(plant::to_string(m)) + "/" + plant::to_string(f);
}

plant::IntegratorSettings settings_of(plant::IntegrationMethod m, plant::Formulation f, double h) {
  plant::IntegratorSettings s;
  s.method = m;
  s.formulation = f;
  s.step = h;
  return s;
}

// ---------------------------------------------------------------------------------------------
// Work-precision chart.
struct WorkPoint {
  std::string scene, method;
  double step = 0, cpu_per_s = 0, tip_rms = 0, constraint = 0, energy = 0;
  bool ok = false;
  std::string failure;
  bool pareto = false;
};

std::vector<WorkPoint> work_precision(const std::vector<BenchScene>& scenes, const std::vector<double>& steps,
                                      double reference_step, std::vector<OpenLoopResult>& references) {
  std::vector<WorkPoint> points;
  for (const BenchScene& s : scenes) {
    const EffortProfile profile = effort_profile(s);
    progress("work-precision %s: reference (rk4/independent at %s)\n", s.name, step_label(reference_step));
    OpenLoopSettings ref_settings;
    ref_settings.integrator = settings_of(plant::IntegrationMethod::rk4, plant::Formulation::independent, reference_step);
    references.push_back(run_open_loop(s, profile, ref_settings));
    const OpenLoopResult& ref = references.back();
    if (!ref.ok) throw std::runtime_error("the fine-step reference of " + s.name + " failed: " + ref.failure);
    for (plant::IntegrationMethod m : kMethods)
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
  std::ofstream f(path);
  f << "scene,method,step_s,ok,cpu_s_per_sim_s,tip_rms_m,constraint_residual_m,energy_drift_J,pareto,failure\n";
  f.precision(6);
  for (const WorkPoint& p : points) {
    std::string failure = p.failure;
    std::replace(failure.begin(), failure.end(), ',', ';');
    std::replace(failure.begin(), failure.end(), '\n', ' ');
    f << p.scene << ',' << p.method << ',' << p.step << ',' << (p.ok ? 1 : 0) << ',' << p.cpu_per_s << ','
      << p.tip_rms << ',' << p.constraint << ',' << p.energy << ',' << (p.pareto ? 1 : 0) << ",\"" << failure << "\"\n";
  }
}

// ---------------------------------------------------------------------------------------------
// The project's plant against MuJoCo on the same states and efforts.
struct PeerResult {
  std::string scene;
  double plant_step_us = NAN, constraint_error = NAN, tip_rms = NAN;           // ours, default method
  double augmented_constraint_error = NAN;                                     // ours, augmented + Baumgarte
  double mujoco_step_us = NAN, mujoco_constraint_error = NAN, mujoco_tip_rms = NAN;
  double control_step_us = NAN, mujoco_inverse_us = NAN, inverse_dynamics_us = NAN;
  double dynamics_step_us = NAN;  // the plant's integrator step alone (dynamics + integration)
  std::string mujoco_status = "not available, peer skipped";
  std::vector<Vec3> reference_tip, ours_tip, mujoco_tip;
};

// Median time of the adaptive controller's update (inverse dynamics + regressor + update law) and of
// our inverse dynamics alone, on the states of a run.
void time_controller(const BenchScene& s, const OpenLoopResult& run, PeerResult& out) {
  const Model model = build_model(s.scene.machine);
  auto controller = control::make_controller(control::ControllerKind::adaptive, model, s.controller);
  Workspace ws(model);
  std::vector<double> control_us, id_us;
  control::ControlInput in;
  in.soil.terrain_height = s.scene.terrain.height;
  const int repeats = 2;
  for (int rep = 0; rep < repeats; ++rep)
    for (std::size_t k = 0; k < run.q.size(); ++k) {
      Vec4 q_d, qd_d, qdd_d;
      s.task.trajectory.evaluate(s.task.start_time() + s.start + static_cast<double>(k) * kProfileHold, q_d, qd_d, qdd_d);
      for (int a = 0; a < kNumActive; ++a) {
        in.q[a] = run.q[k][kActiveJoints[a]];
        in.qd[a] = run.qd[k][kActiveJoints[a]];
      }
      in.qdd = qdd_d;
      in.q_d = q_d;
      in.qd_d = qd_d;
      in.qdd_d = qdd_d;
      in.t = static_cast<double>(k) * kProfileHold;
      // Batches of kBatch calls in thread CPU time (the clock costs ~0.3 us a read).
      double t0 = thread_cpu_seconds();
      for (int b = 0; b < kBatch; ++b) {
        in.t += 1e-3;
        const control::ControlOutput o = controller->update(in);
        (void)o;
      }
      control_us.push_back(1e6 * (thread_cpu_seconds() - t0) / kBatch);
      Vec4 tau;
      t0 = thread_cpu_seconds();
      for (int b = 0; b < kBatch; ++b) {
        update_closed_chain(model, ws, in.q, in.qd);
        inverse_dynamics(model, ws, qdd_d, Vec2::Zero(), tau);
      }
      id_us.push_back(1e6 * (thread_cpu_seconds() - t0) / kBatch);
    }
  out.control_step_us = median(control_us);
  out.inverse_dynamics_us = median(id_us);
}

// The integrator's step alone (forward dynamics + semi-implicit Euler, soil load, no sensors, energy
// balance or checks): the part of the plant step that mj_step corresponds to.
void time_dynamics_step(const BenchScene& s, const EffortProfile& profile, const OpenLoopResult& run, PeerResult& out) {
  const Model model = build_model(s.scene.machine);
  Workspace ws(model);
  plant::Integrator integrator(model, settings_of(plant::IntegrationMethod::semi_implicit_euler,
                                                  plant::Formulation::independent, 1e-3));
  plant::SoilModel soil(s.scene.terrain, s.scene.soil);
  std::vector<double> us;
  for (std::size_t k = 0; k + 1 < run.q.size() && k < profile.tau.size(); ++k) {
    plant::MechanicalState m;
    m.q = run.q[k];
    m.qd = run.qd[k];
    for (int a = 0; a < kNumActive; ++a) {
      m.q_a[a] = run.q[k][kActiveJoints[a]];
      m.qd_a[a] = run.qd[k][kActiveJoints[a]];
    }
    integrator.invalidate_cache();
    plant::Evaluation start;
    const double t0 = thread_cpu_seconds();
    for (int b = 0; b < kBatch; ++b) integrator.step(ws, soil, profile.tau[k], 1e-3, m, start);
    us.push_back(1e6 * (thread_cpu_seconds() - t0) / kBatch);
  }
  out.dynamics_step_us = median(us);
}

// Passes over which the plant's and MuJoCo's step times are measured (the best median counts). With
// MuJoCo the passes alternate engine by engine, so load that comes and goes meets both.
constexpr int kTimingPasses = 3;

#ifdef EXC_HAVE_MUJOCO
// plant_pass: one more timing pass of the plant (its step median, us), run between MuJoCo's passes.
void run_mujoco(const BenchScene& s, const EffortProfile& profile, const OpenLoopResult& ours,
                const std::string& out_dir, const std::function<double()>& plant_pass, PeerResult& out) {
  const Model model = build_model(s.scene.machine);
  const std::string xml_path = out_dir + "/" + s.name + ".mjcf.xml";
  {
    std::ofstream f(xml_path);
    f << export_mjcf(model, profile.q_a0);
  }
  std::string error;
  std::unique_ptr<MujocoPeer> peer = MujocoPeer::load(model, xml_path, error);
  if (!peer) {
    out.mujoco_status = "failed to load: " + error;
    return;
  }
  out.mujoco_status = "ok (" + mujoco_version() + ")";
  peer->set_state(ours.q.front(), ours.qd.front());
  plant::SoilModel soil(s.scene.terrain, s.scene.soil);
  const int per_hold = static_cast<int>(std::lround(kProfileHold / 1e-3));
  std::vector<double> step_us;
  std::vector<Vec3> tip_forces;
  tip_forces.reserve(profile.tau.size() * static_cast<std::size_t>(per_hold));
  out.mujoco_tip.push_back(peer->tip_world());
  double worst = peer->constraint_error();
  Vec2 rho_prev = Vec2::Zero(), rhod_prev = Vec2::Zero();
  bool have_prev = false;
  bool ok = true;
  for (std::size_t k = 0; k < profile.tau.size() && ok; ++k) {
    peer->set_effort(profile.tau[k]);
    for (int c = 0; c < per_hold; ++c) {
      // The soil of eqs. 9-11 from MuJoCo's own tip (the added mass from the last acceleration).
      const Vec12 q = peer->q();
      const Vec3 tip = peer->tip_world();
      const double sw = q[kSwing];
      const Vec2 rho(std::cos(sw) * tip.x() + std::sin(sw) * tip.y(), tip.z());
      const Vec2 rhod = have_prev ? Vec2((rho - rho_prev) / 1e-3) : Vec2::Zero();
      const Vec2 rhodd = have_prev ? Vec2((rhod - rhod_prev) / 1e-3) : Vec2::Zero();
      const TipLoad load = soil.load(rho, rhod);
      const Vec2 f_soil = load.force + load.added_mass.cwiseProduct(rhodd);
      // The bucket feels -F_soil, in the swing plane.
      const Vec3 f_bucket(-std::cos(sw) * f_soil.x(), -std::sin(sw) * f_soil.x(), -f_soil.y());
      peer->set_tip_force(f_bucket);
      tip_forces.push_back(f_bucket);
      rho_prev = rho;
      rhod_prev = rhod;
      have_prev = true;
      peer->step();
      if (!peer->finite()) {
        ok = false;
        break;
      }
      worst = std::max(worst, peer->constraint_error());
      const Vec3 tip1 = peer->tip_world();
      const double sw1 = peer->q()[kSwing];
      soil.commit(Vec2(std::cos(sw1) * tip1.x() + std::sin(sw1) * tip1.y(), tip1.z()));
    }
    out.mujoco_tip.push_back(peer->tip_world());
  }
  if (!ok) out.mujoco_status = "diverged (non-finite state)";
  // Step time: further passes over the same efforts and soil forces with nothing but mj_step in the
  // timed blocks (one clock read per hold interval; a read costs ~0.3 us); best of kTimingPasses medians.
  out.mujoco_step_us = INFINITY;
  for (int pass = 0; pass < kTimingPasses; ++pass) {
    if (pass > 0) out.plant_step_us = std::min(out.plant_step_us, plant_pass());
    peer->set_state(ours.q.front(), ours.qd.front());
    step_us.clear();
    std::size_t n = 0;
    for (std::size_t k = 0; k < profile.tau.size() && n < tip_forces.size(); ++k) {
      peer->set_effort(profile.tau[k]);
      const double block0 = thread_cpu_seconds();
      int stepped = 0;
      for (int c = 0; c < per_hold && n < tip_forces.size(); ++c, ++n, ++stepped) {
        peer->set_tip_force(tip_forces[n]);
        peer->step();
      }
      if (stepped > 0) step_us.push_back(1e6 * (thread_cpu_seconds() - block0) / stepped);
    }
    out.mujoco_step_us = std::min(out.mujoco_step_us, median(step_us));
  }
  out.mujoco_constraint_error = worst;
  // mj_inverse on the states of our run, with the accelerations between them.
  std::vector<double> inverse_us;
  Vec12 tau;
  for (int rep = 0; rep < 2; ++rep)
    for (std::size_t k = 0; k + 1 < ours.q.size(); ++k) {
      const Vec12 qdd = (ours.qd[k + 1] - ours.qd[k]) / kProfileHold;
      const double t0 = thread_cpu_seconds();
      for (int b = 0; b < kBatch; ++b) peer->inverse(ours.q[k], ours.qd[k], qdd, tau);
      inverse_us.push_back(1e6 * (thread_cpu_seconds() - t0) / kBatch);
    }
  out.mujoco_inverse_us = median(inverse_us);
}
#endif

std::vector<PeerResult> peer_comparison(const std::vector<BenchScene>& scenes,
                                        const std::vector<OpenLoopResult>& references, const std::string& out_dir) {
  std::vector<PeerResult> results;
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const BenchScene& s = scenes[i];
    progress("peer %s: the plant (semi_implicit_euler/independent, 1 ms)%s\n", s.name);
    const EffortProfile profile = effort_profile(s);
    PeerResult p;
    p.scene = s.name;
    OpenLoopSettings st;
    st.integrator = settings_of(plant::IntegrationMethod::semi_implicit_euler, plant::Formulation::independent, 1e-3);
    const OpenLoopResult ours = run_open_loop(s, profile, st, true);
    // Step times are the best of kTimingPasses medians, for both engines: a burst of load from
    // elsewhere on this shared machine can cover a whole pass and would otherwise decide the ratio.
    p.plant_step_us = ours.step_median_us;
    // A copy of st: it is switched to the augmented form below.
    auto plant_pass = [&, st] { return run_open_loop(s, profile, st, true).step_median_us; };
    p.constraint_error = ours.max_constraint_residual;
    p.tip_rms = ours.ok ? rms_distance(ours.tip, references[i].tip) : NAN;
    p.reference_tip = references[i].tip;
    p.ours_tip = ours.tip;
    st.integrator.formulation = plant::Formulation::augmented_baumgarte;
    p.augmented_constraint_error = run_open_loop(s, profile, st).max_constraint_residual;
    time_controller(s, ours, p);
    time_dynamics_step(s, profile, ours, p);
#ifdef EXC_HAVE_MUJOCO
    progress("peer %s: MuJoCo (Euler, 1 ms)%s\n", s.name);
    run_mujoco(s, profile, ours, out_dir, plant_pass, p);
    p.mujoco_tip_rms = rms_distance(p.mujoco_tip, references[i].tip);
#else
    (void)out_dir;
    for (int pass = 1; pass < kTimingPasses; ++pass) p.plant_step_us = std::min(p.plant_step_us, plant_pass());
#endif
    results.push_back(p);
  }
  return results;
}

void write_peer_csvs(const std::string& dir, const std::vector<PeerResult>& peers) {
  std::ofstream f(dir + "/peer.csv");
  f << "scene,engine,step_us,constraint_error_m,tip_rms_vs_reference_m,inverse_us,status\n";
  std::ofstream t(dir + "/peer_tip.csv");
  t << "scene,t,reference_x,reference_z,plant_x,plant_z,mujoco_x,mujoco_z\n";
  for (const PeerResult& p : peers) {
    f << p.scene << ",plant," << p.plant_step_us << ',' << p.constraint_error << ',' << p.tip_rms << ','
      << p.control_step_us << ",ok\n";
    f << p.scene << ",mujoco," << p.mujoco_step_us << ',' << p.mujoco_constraint_error << ',' << p.mujoco_tip_rms << ','
      << p.mujoco_inverse_us << ",\"" << p.mujoco_status << "\"\n";
    for (std::size_t k = 0; k < p.reference_tip.size(); ++k) {
      auto xz = [&](const std::vector<Vec3>& v) {
        std::ostringstream o;
        if (k < v.size()) o << std::hypot(v[k].x(), v[k].y()) << ',' << v[k].z();
        else o << ',';
        return o.str();
      };
      t << p.scene << ',' << static_cast<double>(k) * kProfileHold << ',' << xz(p.reference_tip) << ','
        << xz(p.ours_tip) << ',' << xz(p.mujoco_tip) << '\n';
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Fidelity chart: closed loop, adaptive controller.
struct FidelityRow {
  std::string scene, fidelity;
  bool ok = false;
  std::string failure;
  double cpu_per_s = NAN, tip_rms = NAN, force_rel = NAN, tracking_diff = NAN, tracking = NAN;
  bool within = false, recommended = false;
};

// Tolerances of the recommendation (stated in the output and docs/bench.md).
constexpr double kTipTolerance = 0.01;       // m, RMS tip path difference
constexpr double kForceTolerance = 0.05;     // relative RMS cylinder-force difference
constexpr double kTrackingTolerance = 0.002; // m or rad, change of the worst joint's RMS tracking error
constexpr double kCostNoise = 0.15;          // CPU-time differences below this fraction are noise here

double worst_tracking(const ClosedLoopResult& r) {
  return *std::max_element(std::begin(r.tracking_rms), std::end(r.tracking_rms));
}

std::vector<FidelityRow> fidelity_chart(const std::vector<BenchScene>& scenes, double duration) {
  std::vector<FidelityRow> rows;
  for (const BenchScene& s : scenes) {
    struct Variant {
      std::string name;
      ClosedLoopVariant v;
    };
    std::vector<Variant> variants;
    auto add = [&](const std::string& name, plant::ActuatorFidelity f, bool soil, bool massless) {
      Variant x;
      x.name = name;
      x.v.fidelity = f;
      x.v.soil = soil;
      x.v.massless_cylinders = massless;
      x.v.duration = duration;
      variants.push_back(x);
    };
    // The first variant that runs is the reference: the most complete model.
    add("12-link + hydraulic + soil", plant::ActuatorFidelity::hydraulic, true, false);
    add("12-link + limited + soil", plant::ActuatorFidelity::limited, true, false);
    add("12-link + ideal + soil", plant::ActuatorFidelity::ideal, true, false);
    add("massless cylinders + ideal + soil", plant::ActuatorFidelity::ideal, true, true);
    add("12-link + ideal + no soil", plant::ActuatorFidelity::ideal, false, false);
    add("massless cylinders + ideal + no soil", plant::ActuatorFidelity::ideal, false, true);
    // The firmware commands efforts; a hydraulic plant takes valve openings, so with this firmware
    // its valves stay closed. Its row is shown but it is neither the reference nor a candidate.
    auto drivable = [&](std::size_t i) { return variants[i].v.fidelity != plant::ActuatorFidelity::hydraulic; };
    std::vector<ClosedLoopResult> results;
    for (const Variant& x : variants) {
      progress("fidelity %s: %s\n", s.name, x.name);
      results.push_back(run_closed_loop(s, x.v));
    }
    int ref = -1;
    for (std::size_t i = 0; i < results.size() && ref < 0; ++i)
      if (results[i].ok && drivable(i)) ref = static_cast<int>(i);
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
      row.failure = drivable(i) ? r.failure : "not driven: the firmware sends efforts, this plant takes valve openings";
      if (r.ok && ref >= 0) {
        const ClosedLoopResult& R = results[ref];
        row.cpu_per_s = r.cpu_seconds / r.simulated;
        row.tip_rms = rms_distance(r.tip, R.tip);
        double sum = 0;
        const std::size_t n = std::min(r.effort.size(), R.effort.size());
        for (std::size_t k = 0; k < n; ++k) sum += (r.effort[k] - R.effort[k]).tail<3>().squaredNorm();
        row.force_rel = n ? std::sqrt(sum / static_cast<double>(n)) / std::max(ref_force, 1.0) : NAN;
        row.tracking = worst_tracking(r);
        row.tracking_diff = std::abs(row.tracking - worst_tracking(R));
        row.within = drivable(i) && row.tip_rms <= kTipTolerance && row.force_rel <= kForceTolerance &&
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
  std::ofstream f(path);
  f << "scene,fidelity,ok,cpu_s_per_sim_s,tip_rms_m,force_rel,tracking_rms,tracking_diff,within_tolerance,"
       "recommended,failure\n";
  for (const FidelityRow& r : rows) {
    std::string failure = r.failure;
    std::replace(failure.begin(), failure.end(), ',', ';');
    f << r.scene << ',' << r.fidelity << ',' << r.ok << ',' << r.cpu_per_s << ',' << r.tip_rms << ',' << r.force_rel << ','
      << r.tracking << ',' << r.tracking_diff << ',' << r.within << ',' << r.recommended << ",\"" << failure << "\"\n";
  }
}

// ---------------------------------------------------------------------------------------------
// Stability maps.
struct StepStability {
  std::string method, axis;
  double value = 0, largest_stable_step = NAN;
  std::string failure_above;  // what the plant's checks said at the next larger step
};

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

struct ControlStability {
  std::string controller, axis;
  double value = 0;
  bool ok = false;
  double tracking = NAN;
  std::string failure;
};

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

// ---------------------------------------------------------------------------------------------

int run_bench(const Options& o) {
  const auto wall0 = std::chrono::steady_clock::now();
  fs::create_directories(o.out);
  // Windows of the tasks that the open-loop runs cover: the dig window starts just before the tip
  // reaches the ground (t = 2 s of the task) so that it digs.
  const double horizon = o.quick ? 0.5 : 3.0;
  std::vector<BenchScene> scenes = {load_bench_scene(o.scenes_dir + "/free_motion.yaml", 0.0, horizon),
                                    load_bench_scene(o.scenes_dir + "/dig.yaml", o.quick ? 2.5 : 1.5, horizon)};
  const std::vector<double> steps = o.quick ? std::vector<double>{1e-2, 1e-3, 1e-4}
                                            : std::vector<double>{1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5};
  const double reference_step = o.quick ? 2e-5 : 2.5e-6;

#ifdef EXC_HAVE_MUJOCO
  std::printf("mujoco: available (%s), peer in this run\n", mujoco_version().c_str());
#else
  std::printf("mujoco: not available, peer skipped (install libmujoco-dev and reconfigure)\n");
#endif

  std::vector<OpenLoopResult> references;
  const std::vector<WorkPoint> work = work_precision(scenes, steps, reference_step, references);
  write_work_csv(o.out + "/work_precision.csv", work);

  const std::vector<PeerResult> peers = peer_comparison(scenes, references, o.out);
  write_peer_csvs(o.out, peers);

  const double closed_duration = o.quick ? 1.0 : 0.0;  // 0: the scenes' own durations
  const std::vector<FidelityRow> fidelity = fidelity_chart(scenes, closed_duration);
  write_fidelity_csv(o.out + "/fidelity.csv", fidelity);

  BenchScene dig_window = scenes[1];
  dig_window.start = o.quick ? 3.0 : 2.5;  // in the soil from the start
  dig_window.horizon = o.quick ? 0.2 : 1.0;
  BenchScene free_window = scenes[0];
  free_window.horizon = o.quick ? 0.2 : 1.0;
  // Loose sand (2e4 N/m) to loads far past stiff clay (2e7 N/m: a full bucket pressed on rock): the
  // map has to reach the failures. Steps stop at the effort profile's 10 ms hold.
  const std::vector<double> stiffness = o.quick ? std::vector<double>{2e4, 2e7}
                                                : std::vector<double>{2e4, 7e4, 2e5, 9e5, 4e6, 2e7};
  const std::vector<double> map_steps = o.quick ? std::vector<double>{1e-2, 1e-3, 1e-4}
                                                : std::vector<double>{1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5};
  const std::vector<double> speeds = o.quick ? std::vector<double>{1, 3} : std::vector<double>{0.5, 1, 2, 3};
  const std::vector<StepStability> step_map = step_stability_map(dig_window, free_window, map_steps, stiffness, speeds);
  const std::vector<ControlStability> control_map = control_stability_map(scenes[1], o.quick ? 1.0 : 0.0);
  write_stability_csvs(o.out, step_map, control_map);

  // Headline numbers: the free-motion scene (the dig scene's figures are in peer.csv).
  const PeerResult& head = peers.front();
  json j;
  j["plant_step_us"] = number_or_null(head.plant_step_us);
  j["mujoco_step_us"] = number_or_null(head.mujoco_step_us);
  j["constraint_error"] = number_or_null(head.constraint_error);
  j["mujoco_constraint_error"] = number_or_null(head.mujoco_constraint_error);
  j["control_step_us"] = number_or_null(head.control_step_us);
  j["mujoco_inverse_us"] = number_or_null(head.mujoco_inverse_us);
  j["plant_dynamics_step_us"] = number_or_null(head.dynamics_step_us);
  j["mujoco"] = head.mujoco_status;
  j["step_speed_ratio"] = number_or_null(head.mujoco_step_us / head.plant_step_us);
  j["constraint_error_ratio"] = number_or_null(head.mujoco_constraint_error / std::max(head.constraint_error, 1e-16));
  j["control_speed_ratio"] = number_or_null(head.mujoco_inverse_us / head.control_step_us);
  j["pareto"] = json::array();
  for (const WorkPoint& p : work)
    if (p.pareto)
      j["pareto"].push_back({{"scene", p.scene}, {"method", p.method}, {"step_s", p.step},
                             {"cpu_s_per_sim_s", p.cpu_per_s}, {"tip_rms_m", p.tip_rms}});
  j["scenes"] = json::array();
  for (const PeerResult& p : peers)
    j["scenes"].push_back({{"scene", p.scene}, {"plant_step_us", number_or_null(p.plant_step_us)},
                           {"plant_tip_rms_m", number_or_null(p.tip_rms)},
                           {"constraint_error", number_or_null(p.constraint_error)},
                           {"augmented_baumgarte_constraint_error", number_or_null(p.augmented_constraint_error)},
                           {"mujoco_step_us", number_or_null(p.mujoco_step_us)},
                           {"mujoco_constraint_error", number_or_null(p.mujoco_constraint_error)},
                           {"mujoco_tip_rms_m", number_or_null(p.mujoco_tip_rms)},
                           {"control_step_us", number_or_null(p.control_step_us)},
                           {"inverse_dynamics_us", number_or_null(p.inverse_dynamics_us)},
                           {"plant_dynamics_step_us", number_or_null(p.dynamics_step_us)},
                           {"mujoco_inverse_us", number_or_null(p.mujoco_inverse_us)}});
  j["recommended_fidelity"] = json::object();
  for (const FidelityRow& r : fidelity)
    if (r.recommended) j["recommended_fidelity"][r.scene] = r.fidelity;
  j["tolerances"] = {{"tip_rms_m", kTipTolerance}, {"force_rel", kForceTolerance}, {"tracking_m", kTrackingTolerance}};
  j["quick"] = o.quick;
  j["wall_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const std::string json_path = o.json_file.empty() ? o.out + "/bench.json" : o.json_file;
  std::ofstream(json_path) << j.dump(2) << '\n';

  // Summary table.
  std::printf("\n== excavator-bench %s (CSV, PNG and JSON in %s) ==\n", o.quick ? "--quick" : "", o.out.c_str());
  std::printf("%-12s %-8s %12s %16s %16s %14s\n", "scene", "engine", "step (us)", "constraint (m)", "tip vs ref (m)",
              "control (us)");
  for (const PeerResult& p : peers) {
    std::printf("%-12s %-8s %12.2f %16.3g %16.3g %14.2f\n", p.scene.c_str(), "plant", p.plant_step_us,
                p.constraint_error, p.tip_rms, p.control_step_us);
    std::printf("%-12s %-8s %12.2f %16.3g %16.3g %14.2f   (mj_inverse; %s)\n", p.scene.c_str(), "mujoco",
                p.mujoco_step_us, p.mujoco_constraint_error, p.mujoco_tip_rms, p.mujoco_inverse_us,
                p.mujoco_status.c_str());
  }
  for (const PeerResult& p : peers)
    std::printf("%-12s %-8s %12.2f   (integrator step alone: dynamics + Euler, no sensors/checks; our inverse "
                "dynamics %.2f us)\n", p.scene.c_str(), "plant", p.dynamics_step_us, p.inverse_dynamics_us);
  std::printf("ratios (free motion): mj_step / plant step = %.2f (target >= 2), constraint error MuJoCo / plant = "
              "%.3g (target >= 100), mj_inverse / control step = %.2f (target > 1); mj_step / integrator step = %.2f\n",
              head.mujoco_step_us / head.plant_step_us,
              head.mujoco_constraint_error / std::max(head.constraint_error, 1e-16),
              head.mujoco_inverse_us / head.control_step_us, head.mujoco_step_us / head.dynamics_step_us);
  std::printf("\nPareto front (work-precision, tip RMS against CPU per simulated second):\n");
  for (const WorkPoint& p : work)
    if (p.pareto)
      std::printf("  %-12s %-40s %-8s %10.3g s/s %12.3g m\n", p.scene.c_str(), p.method.c_str(), step_label(p.step).c_str(),
                  p.cpu_per_s, p.tip_rms);
  std::printf("\nFidelity (closed loop, adaptive; tolerance: tip %.0f mm, forces %.0f %%, tracking %.0f mm):\n",
              kTipTolerance * 1e3, kForceTolerance * 100, kTrackingTolerance * 1e3);
  for (const FidelityRow& r : fidelity)
    std::printf("  %-12s %-38s %s cpu %8.3g s/s tip %9.3g m force %8.3g tracking %9.3g %s\n", r.scene.c_str(),
                r.fidelity.c_str(), r.ok ? "ok  " : "FAIL", r.cpu_per_s, r.tip_rms, r.force_rel, r.tracking,
                r.recommended ? "<- recommended" : r.failure.substr(0, 70).c_str());
  std::printf("\nLargest stable step (plant checks) against soil stiffness and joint speed:\n");
  for (const StepStability& r : step_map)
    std::printf("  %-42s %-24s %10.3g  %s\n", r.method.c_str(), r.axis.c_str(), r.value,
                std::isfinite(r.largest_stable_step) ? step_label(r.largest_stable_step).c_str() : "none");
  std::printf("\nController stability (dig scene; ok = no plant check and no safe stop):\n");
  for (const ControlStability& r : control_map)
    std::printf("  %-10s %-18s %10.3g  %-4s tracking %9.3g %s\n", r.controller.c_str(), r.axis.c_str(), r.value,
                r.ok ? "ok" : "FAIL", r.tracking, r.failure.substr(0, 70).c_str());

  if (o.plots) {
    const std::string cmd = std::string("/usr/bin/python3 '") + EXC_BENCH_PLOT_SCRIPT + "' '" + o.out + "'";
    if (std::system(cmd.c_str()) != 0) std::printf("plots: the plotting script failed (CSV files are complete)\n");
  }
  std::printf("json: %s (%.1f s wall)\n", json_path.c_str(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count());
  return 0;
}

int export_command(const std::string& machine_file, const std::string& out, std::vector<double> q_a) {
  const Machine machine = machine_file.empty() ? reference_machine() : load_machine(machine_file);
  const Model model = build_model(machine);
  Vec4 pose;
  if (q_a.empty()) {
    if (machine.reference_poses.empty())
      throw std::runtime_error(machine.source + ": no reference_poses to assemble at; pass --q-a");
    pose = machine.reference_poses.front().q_a;
  } else {
    for (int i = 0; i < 4; ++i) pose[i] = q_a[i];
  }
  const std::string xml = export_mjcf(model, pose);
  if (out == "-") {
    std::cout << xml;
  } else {
    std::ofstream f(out);
    if (!f) throw std::runtime_error(out + ": cannot write");
    f << xml;
    std::fprintf(stderr, "export-mjcf: wrote %s\n", out.c_str());
  }
  return 0;
}

}  // namespace
}  // namespace exc::bench

int main(int argc, char** argv) {
  CLI::App app{
      "excavator-bench: work-precision chart, fidelity chart, stability maps and MuJoCo as a peer.\n"
      "Without a subcommand it runs the whole benchmark (about 10 min; --quick: under 1 min)."};
  exc::bench::Options o;
  app.add_flag("--quick", o.quick, "CI mode: fewer step sizes and shorter horizons (< 1 min)");
  app.add_option("--out", o.out, "directory for the CSV and PNG files")->capture_default_str();
  app.add_option("--json", o.json_file, "write the summary JSON here (default: OUT/bench.json)");
  app.add_option("--scenes", o.scenes_dir, "directory holding free_motion.yaml and dig.yaml")->capture_default_str();
  bool no_plots = false;
  app.add_flag("--no-plots", no_plots, "write the CSV files only");
  auto* exp = app.add_subcommand("export-mjcf", "write the machine as MJCF (MuJoCo XML), loops as connect equalities");
  std::string machine_file, xml_out = "-";
  std::vector<double> q_a;
  exp->add_option("--machine", machine_file, "machine file (default: the built-in reference machine)");
  exp->add_option("-o,--output", xml_out, "output file ('-': stdout)")->capture_default_str();
  exp->add_option("--q-a", q_a, "assemble at q_a = swing L_boom L_arm L_bucket (default: the first reference pose)")
      ->expected(4);
  app.require_subcommand(0, 1);
  CLI11_PARSE(app, argc, argv);
  o.plots = !no_plots;
  try {
    if (exp->parsed()) return exc::bench::export_command(machine_file, xml_out, q_a);
    return exc::bench::run_bench(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "excavator-bench: %s\n", e.what());
    return 1;
  }
}
