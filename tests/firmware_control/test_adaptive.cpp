#include <doctest/doctest.h>
#include <yaml-cpp/yaml.h>

#include <random>

#include "closed_loop.hpp"
#include "control/controller_config.hpp"
#include "control/laws/adaptive_computed_torque.hpp"
#include "control/controller_registry.hpp"
#include "control/estimation/state_estimator.hpp"
#include "control/task/task.hpp"
#include "scenes.hpp"
#include "tracking_run.hpp"
#include "model/machine_reader.hpp"
#include "control/task/task_reader.hpp"

using namespace exc;
using namespace exc::control;

namespace {

// Desired motion with the tip in the soil: small joint sinusoids around a pose below the ground.
void desired(double t, const Vec4& q0, Vec4& q, Vec4& qd, Vec4& qdd) {
  const Vec4 amp(0.0, 0.03, 0.05, 0.06), w(1.0, 2.1, 2.9, 3.7);
  for (int j = 0; j < 4; ++j) {
    q[j] = q0[j] + amp[j] * std::sin(w[j] * t);
    qd[j] = amp[j] * w[j] * std::cos(w[j] * t);
    qdd[j] = -amp[j] * w[j] * w[j] * std::sin(w[j] * t);
  }
}

// The tests' digging pose: the tip 0.3 m below the ground at 7 m, bucket at 30 degrees; ws holds
// the closed chain there (ws.rho the tip).
Vec4 pose_in_soil(const Model& model, Workspace& ws) {
  Vec4 q0;
  REQUIRE(inverse_kinematics(model.machine, 0.0, TipPose{7.0, -0.3, 30 * 3.14159265358979 / 180}, q0) == IkStatus::ok);
  update_closed_chain(model, ws, q0, Vec4::Zero());
  return q0;
}

struct LyapunovRun {
  double v0 = 0, v_end = 0, worst_rise = 0;
  Vec6 theta_end = Vec6::Zero();
};

// Step 25 us: at 50 us the explicit Euler steps show one-step rises of ~1e-6 V0 that vanish at
// 25 us (so they are integration error, not the law). Noise-free, exact model, constant soil parameters, fixed anchor, the controller given the true
// qdd (the algebraic loop through the soil's added mass solved by fixed-point iteration).
LyapunovRun run_lyapunov(const Vec2& anchor_error, bool integral_action = false, double dt = 2.5e-5) {
  const Model model = build_model(reference_machine());
  ControllerConfig cfg;
  cfg.period = dt;
  cfg.soil_parameters.theta_initial = (Vec6() << 100, 2e3, 3e4, 100, 2e3, 3e4).finished();
  cfg.adaptation.rate = (Vec6() << 1e8, 1e11, 1e13, 1e8, 1e11, 1e13).finished();
  // Vdot = -x^T Q x holds for any SPD Q; Q = I keeps the O(dt^2) residual of the explicit Euler
  // update below round-off at this step (the defaults' larger Q needs a smaller step for that).
  cfg.pid.lyapunov_q = Vec8::Ones();
  cfg.adaptation.integral_action = integral_action;  // z = [int e; e; ed] with K_i = 100 (the defaults)
  cfg.adaptation.lyapunov_q_integral = Vec4::Ones();
  EffortLimits unlimited;
  AdaptiveComputedTorque ctrl(model, adaptive_law_settings(cfg), cfg.period, unlimited);

  Workspace ws(model);
  const Vec4 q0 = pose_in_soil(model, ws);
  sim::SoilTruth soil;
  soil.theta = (Vec6() << 300, 8e3, 2e5, 250, 6e3, 1.5e5).finished();
  soil.always_in_soil = true;
  soil.fixed_anchor = true;
  soil.anchor = ws.rho + Vec2(0.05, 0.03);
  sim::ModelPlant plant(model, soil);
  Vec4 qd_, qdd_, qdes;
  desired(0, q0, qdes, qd_, qdd_);
  plant.reset(qdes + Vec4(0.0, 0.004, -0.005, 0.006), qd_);

  LyapunovRun run;
  double v_prev = -1;
  // With integral action the integral starts away from zero, so that its terms in V carry weight.
  if (integral_action) ctrl.set_error_integral(Vec4(0.0, 2e-3, -3e-3, 3e-3));
  Vec4 qdd_true = Vec4::Zero();
  const int steps = static_cast<int>(std::lround(2.0 / dt));
  for (int k = 0; k < steps; ++k) {  // 2 s
    const double t = k * cfg.period;
    ControlInput in;
    in.t = t;
    in.q = plant.q();
    in.qd = plant.qd();
    desired(t, q0, in.q_d, in.qd_d, in.qdd_d);
    in.soil.anchor_given = true;
    in.soil.in_soil = true;
    in.soil.rho_env = soil.anchor + anchor_error;
    in.soil.theta_known = true;
    in.soil.theta = soil.theta;
    const TipLoad load = plant.soil_load();
    for (int it = 0; it < 4; ++it) {  // qdd and tau depend on each other through M_t
      AdaptiveComputedTorque trial = ctrl;
      in.qdd = qdd_true;
      qdd_true = plant.acceleration(trial.update(in).tau, load);
    }
    in.qdd = qdd_true;
    const ControlOutput out = ctrl.update(in);
    REQUIRE(out.status == ModelStatus::ok);
    if (k == 0) run.v0 = out.lyapunov;
    if (v_prev >= 0) run.worst_rise = std::max(run.worst_rise, out.lyapunov - v_prev);
    v_prev = out.lyapunov;
    REQUIRE(plant.step(out.tau, load, cfg.period));
  }
  run.v_end = v_prev;
  run.theta_end = ctrl.theta_hat();
  return run;
}

}  // namespace

TEST_CASE("firmware/adaptive: V = x'Px + Theta~'Gamma Theta~ never increases (noise-free, exact model)") {
  const LyapunovRun run = run_lyapunov(Vec2::Zero());
  MESSAGE("V0 = " << run.v0 << ", V(2 s) = " << run.v_end << ", worst one-step rise = " << run.worst_rise);
  CHECK(run.v_end < 0.9 * run.v0);                 // it does decrease
  CHECK(run.worst_rise <= 1e-9 * run.v0);          // and never rises beyond integration round-off
}

TEST_CASE("firmware/adaptive with integral action: V = z'Pz + Theta~'Gamma Theta~ never increases (noise-free, exact model)") {
  const LyapunovRun run = run_lyapunov(Vec2::Zero(), true);
  MESSAGE("V0 = " << run.v0 << ", V(2 s) = " << run.v_end << ", worst one-step rise = " << run.worst_rise);
  CHECK(run.v_end < 0.9 * run.v0);
  CHECK(run.worst_rise <= 1e-9 * run.v0);
}

TEST_CASE("firmware/adaptive: the Lyapunov check can fail (a wrong anchor breaks the error dynamics)") {
  // Negative control for the test above: with the anchor 5 cm off, Y no longer matches the soil and
  // V rises at some steps by far more than the tolerance used there.
  const LyapunovRun run = run_lyapunov(Vec2(0.05, -0.05));
  MESSAGE("worst one-step rise with a wrong anchor = " << run.worst_rise << " (V0 = " << run.v0 << ")");
  CHECK(run.worst_rise > 1e-5 * run.v0);
}

TEST_CASE("firmware/adaptive: the projection keeps every soil estimate inside its bounds under noise") {
  const Model model = build_model(reference_machine());
  const Machine& m = model.machine;
  const Task task = read_task(settings::Document::parse(sim::kDigTask, "dig"), m);
  ControllerConfig cfg;
  cfg.adaptation.rate *= 10.0;  // an aggressive rate, so the noise really pushes at the bounds
  AdaptiveComputedTorque ctrl(model, adaptive_law_settings(cfg), cfg.period, effort_limits_of(m));
  sim::ModelPlant plant(model, sim::SoilTruth{});
  Vec4 q0, qd0, qdd0;
  task.trajectory.evaluate(0, q0, qd0, qdd0);
  plant.reset(q0, qd0);
  StateEstimator est(cfg.filter);
  std::mt19937 rng(5);
  std::normal_distribution<double> pos_noise(0, 2e-4), vel_noise(0, 5e-3);
  int at_bound = 0;
  bool inside = true;
  const Terrain ground;  // flat at z = 0, as the model plant's
  for (int k = 0; k < 10000; ++k) {
    const double t = k * cfg.period;
    Vec4 noise_q, noise_v;
    for (int j = 0; j < 4; ++j) {
      noise_q[j] = pos_noise(rng);
      noise_v[j] = vel_noise(rng);
    }
    ControlInput in = sim::estimated_input(est, plant.q() + noise_q, plant.qd() + noise_v, task, t);
    in.soil.site_map = &ground;
    const TipLoad load = plant.soil_load();
    const ControlOutput out = ctrl.update(in);
    const Vec6& th = ctrl.theta_hat();
    for (int i = 0; i < 6; ++i) {
      inside = inside && std::isfinite(th[i]) && th[i] >= cfg.soil_parameters.theta_min[i] && th[i] <= cfg.soil_parameters.theta_max[i];
      at_bound += (th[i] == cfg.soil_parameters.theta_min[i] || th[i] == cfg.soil_parameters.theta_max[i]) ? 1 : 0;
    }
    REQUIRE(plant.step(out.tau, load, cfg.period));
  }
  CHECK(inside);
  MESSAGE("parameter-steps spent on a bound: " << at_bound);
  CHECK(at_bound > 0);  // the projection was exercised, not idle
}

TEST_CASE("firmware/adaptive and Slotine-Li leave a joint the actuator-lag stage clamps out of the soil update, and freeze only when every joint is clamped") {
  const Model model = build_model(reference_machine());
  Workspace ws(model);
  const Vec4 q0 = pose_in_soil(model, ws);
  ControlInput in;
  in.q = q0;
  in.qd = Vec4(0, 0.02, -0.03, 0.04);
  in.q_d = q0 + Vec4(0, 0.002, 0.003, -0.004);  // a tracking error, so the update law has work
  in.soil.anchor_given = true;
  in.soil.in_soil = true;
  in.soil.rho_env = ws.rho + Vec2(0.05, 0.03);
  const ControllerConfig cfg;
  for (const std::string kind : {"adaptive", "slotine_li"}) {
    CAPTURE(kind);
    auto free_law = make_controller(kind, model, cfg);
    auto arm_law = make_controller(kind, model, cfg);
    auto all_law = make_controller(kind, model, cfg);
    ControlInput arm_clamped = in, all_clamped = in;
    arm_clamped.actuator_limited = 0b0100;  // the arm's command was clamped last cycle
    all_clamped.actuator_limited = 0b1111;
    const ControlOutput a = free_law->update(in), b = arm_law->update(arm_clamped), c = all_law->update(all_clamped);
    REQUIRE(a.saturated == 0);  // the laws themselves did not saturate: only the downstream flag differs
    REQUIRE(b.saturated == 0);
    REQUIRE(c.saturated == 0);
    // Reported theta_hat is the one used this step; the next step shows the update (or its absence).
    const Vec6 after_free = free_law->update(in).theta_hat;
    const Vec6 after_arm = arm_law->update(arm_clamped).theta_hat;
    const Vec6 after_all = all_law->update(all_clamped).theta_hat;
    CHECK((after_free - cfg.soil_parameters.theta_initial).norm() > 0);
    CHECK((after_arm - cfg.soil_parameters.theta_initial).norm() > 0);  // the other joints still adapt
    CHECK((after_arm - after_free).norm() > 0);         // without the arm's term
    CHECK(after_all == cfg.soil_parameters.theta_initial);
  }
  // The adaptive law's update with the arm clamped equals its update on the same state with the
  // arm's error removed (P is block-diagonal per joint, and its regressor does not use q_d).
  auto masked = make_controller("adaptive", model, cfg);
  auto no_arm_error = make_controller("adaptive", model, cfg);
  ControlInput arm_clamped = in, arm_on_path = in;
  arm_clamped.actuator_limited = 0b0100;
  arm_on_path.q_d[2] = in.q[2];
  arm_on_path.qd_d[2] = in.qd[2];
  masked->update(arm_clamped);
  no_arm_error->update(arm_on_path);
  const Vec6 m = masked->update(arm_clamped).theta_hat, r = no_arm_error->update(arm_on_path).theta_hat;
  CHECK((m - r).norm() <= 1e-9 * r.norm());
}

TEST_CASE("firmware/adaptive with integral action removes the steady error of a wrong mass model, without it the error stays") {
  // Holding a pose in the air with a controller whose links are 20 % too light: the gravity it does
  // not cancel is a constant disturbance. Without integral action the error settles where K_p e
  // balances it; with K_i the integral takes it over and e goes to zero (s^3 + K_v s^2 + K_p s + K_i
  // is Hurwitz, slowest pole ~ -2 1/s, so 8 s is ~16 time constants).
  const Model truth = build_model(reference_machine());
  Machine light_machine = reference_machine();
  for (BodyInertia& b : light_machine.bodies) {
    b.mass *= 0.8;
    b.inertia *= 0.8;
  }
  const Model light = build_model(light_machine);
  Vec4 q0;
  REQUIRE(inverse_kinematics(truth.machine, 0.0, TipPose{7.0, 1.0, 0.0}, q0) == IkStatus::ok);
  sim::SoilTruth air;
  air.terrain_height = -50;  // never touched
  Terrain air_ground;
  air_ground.height = air.terrain_height;
  Vec4 final_error[2];
  for (int with_integral = 0; with_integral < 2; ++with_integral) {
    ControllerConfig cfg;
    cfg.adaptation.integral_action = with_integral == 1;
    AdaptiveComputedTorque ctrl(light, adaptive_law_settings(cfg), cfg.period, effort_limits_of(truth.machine));
    sim::ModelPlant plant(truth, air);
    plant.reset(q0, Vec4::Zero());
    ControlOutput out;
    for (int k = 0; k < 8000; ++k) {
      ControlInput in;
      in.t = k * cfg.period;
      in.q = plant.q();
      in.qd = plant.qd();
      in.q_d = q0;
      in.soil.site_map = &air_ground;
      out = ctrl.update(in);
      REQUIRE(out.status == ModelStatus::ok);
      REQUIRE(plant.step(out.tau, plant.soil_load(), cfg.period));
    }
    final_error[with_integral] = out.e.cwiseAbs();
  }
  MESSAGE("|e| after 8 s (m): without integral " << final_error[0].transpose() << ", with " << final_error[1].transpose());
  for (int j = 1; j < 4; ++j) {
    CAPTURE(j);
    CHECK(final_error[0][j] > 1e-4);                       // the disturbance is really there
    CHECK(final_error[1][j] < 1e-3 * final_error[0][j]);  // and integral action removes it
  }
}
