#include "peer_comparison.hpp"

#include <cmath>
#include <fstream>
#include <functional>
#include <memory>
#include <sstream>

#include "control/controller_registry.hpp"
#include "mjcf_export.hpp"
#include "output_files/output_file.hpp"
#include "model/closed_chain.hpp"
#include "sim_plant/plant.hpp"
#ifdef EXC_HAVE_MUJOCO
#include "mujoco_peer.hpp"
#endif

#include "bench_common.hpp"

namespace exc::bench {
namespace {

// Median time of the adaptive controller's update (inverse dynamics + regressor + update law) and of
// our inverse dynamics alone, on the states of a run.
void time_controller(const BenchScene& s, const OpenLoopResult& run, PeerResult& out) {
  const Model model = build_model(s.scene.machine);
  auto controller = control::make_controller("adaptive", model, s.controller);
  Workspace ws(model);
  std::vector<double> control_us, id_us;
  control::ControlInput in;
  in.soil.site_map = &s.scene.terrain;
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
  plant::Integrator integrator(model, settings_of("semi_implicit_euler",
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
  output::write_file(xml_path, export_mjcf(model, profile.q_a0));
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

}  // namespace

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
    st.integrator = settings_of("semi_implicit_euler", plant::Formulation::independent, 1e-3);
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
  std::ofstream f = output::open_file(dir + "/peer.csv");
  f << "scene,engine,step_us,constraint_error_m,tip_rms_vs_reference_m,inverse_us,status\n";
  std::ofstream t = output::open_file(dir + "/peer_tip.csv");
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
  output::finish_file(f, dir + "/peer.csv");
  output::finish_file(t, dir + "/peer_tip.csv");
}

}  // namespace exc::bench
