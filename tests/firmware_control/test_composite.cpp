// The adaptive law beyond the paper: the external force observer, the tip force it implies, soil
// contact with and without a site map, and the composite update's least squares (docs/control.md).
#include <doctest/doctest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <random>

#include "closed_loop.hpp"
#include "control/controller_config.hpp"
#include "control/laws/adaptive_computed_torque.hpp"
#include "control/estimation/external_force_observer.hpp"
#include "control/estimation/soil_contact.hpp"
#include "control/estimation/soil_identification.hpp"
#include "control/task/task.hpp"
#include "settings/document.hpp"
#include "scenes.hpp"
#include "tracking_run.hpp"
#include "model/machine_reader.hpp"
#include "control/task/task_reader.hpp"

using namespace exc;
using namespace exc::control;

TEST_CASE("firmware/external force observer: a step of the residual is learnt at its cut-off's time constant, a held joint keeps its estimate") {
  const double period = 1e-3, cutoff = 5;
  ExternalForceObserver obs(period, cutoff);
  obs.update(Vec4::Zero(), 0);  // primed at rest
  const Vec4 step(1000, -2000, 3000, 4000);
  const double tau = 1 / (2 * 3.14159265358979323846 * cutoff);
  const int n = static_cast<int>(std::lround(tau / period));
  for (int k = 0; k < n; ++k) obs.update(step, 0b0100);  // the arm held
  // First order, exact discretisation: 1 - exp(-n T / tau) of the step after n periods.
  const double reached = 1 - std::exp(-n * period / tau);
  for (int j : {0, 1, 3}) CHECK(obs.estimate()[j] == doctest::Approx(step[j] * reached).epsilon(1e-9));
  CHECK(obs.estimate()[2] == 0.0);
  ExternalForceObserver fresh(period, cutoff);
  CHECK(fresh.update(step, 0) == step);  // the first residual is taken as it is: no start-up transient
}

TEST_CASE("firmware/tip_force_from_efforts recovers a tip force from tau = J_t^T F over the cylinders, at any pose") {
  const Model model = build_model(reference_machine());
  Workspace ws(model);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1), f(-5e4, 5e4);
  const Vec4 lo = model.machine.q_min(), hi = model.machine.q_max();
  int checked = 0;
  for (int i = 0; i < 200; ++i) {
    Vec4 q;
    q[0] = 0.5 * u(rng);  // the swing's stroke is unbounded
    for (int j = 1; j < 4; ++j) q[j] = lo[j] + (hi[j] - lo[j]) * (0.05 + 0.9 * u(rng));
    if (!update_closed_chain(model, ws, q, Vec4::Zero()).ok()) continue;
    const Vec2 F(f(rng), f(rng));
    const Vec4 tau = ws.J_t.transpose() * F;
    const Vec2 back = tip_force_from_efforts(ws.J_t, tau);
    CHECK((back - F).norm() < 1e-6 * F.norm());
    ++checked;
  }
  CHECK(checked > 150);
}

TEST_CASE("firmware/soil least squares learns a spring and a damper from a linear regression in a few excitations, and leaves the mass alone") {
  // A synthetic regression: rows of J^T S for random tips, stretches and velocities, the residual
  // r = Y (Theta - Theta_hat) of the true parameters, noise-free.
  const Vec6 truth = (Vec6() << 200, 6e3, 1.2e5, 200, 4e3, 9e4).finished();
  const Vec6 scale = (Vec6() << 500, 3e4, 1e6, 500, 3e4, 1e6).finished();
  SoilLeastSquares ls(scale, 20, 1e-3, 3e4);
  Vec6 theta = (Vec6() << 100, 2e3, 3e4, 100, 2e3, 3e4).finished();
  std::mt19937 rng(3);
  std::normal_distribution<double> n01(0, 1);
  for (int k = 0; k < 3000; ++k) {
    Mat2x4 J;
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 4; ++b) J(a, b) = b == 0 ? 0.0 : n01(rng);
    Mat2x6 S = Mat2x6::Zero();
    S(0, 0) = 0.3 * n01(rng);
    S(0, 1) = 0.3 * n01(rng);
    S(0, 2) = 0.05 * n01(rng);
    S(1, 3) = 0.3 * n01(rng);
    S(1, 4) = 0.3 * n01(rng);
    S(1, 5) = 0.05 * n01(rng);
    const Mat4x6 Y = J.transpose() * S;
    ls.fade();
    theta += ls.measure(Y, Y * (truth - theta), 0b1110);
  }
  for (int i : {1, 2, 4, 5}) {
    CAPTURE(i);
    CHECK(theta[i] == doctest::Approx(truth[i]).epsilon(0.01));
  }
  CHECK(theta[0] == 100);  // the soil's mass is not identified (its prior is zero)
  CHECK(theta[3] == 100);
  // A residual on rows left out moves nothing.
  const Vec6 before = theta;
  Mat4x6 Y = Mat4x6::Ones();
  theta += ls.measure(Y, Vec4::Constant(1e4), 0);
  CHECK(theta == before);
}

TEST_CASE("firmware/soil contact without a map: the tip force tells contact with hysteresis, the ground taken level through the entry point for eq. 11") {
  SoilContactSettings s;
  s.use_site_map = false;
  s.contact_force = 2000;
  SoilContactEstimator c(s);
  Terrain map;  // given, but not to be used
  map.height = 10;
  const Vec2 entry(6.0, -0.10);
  Vec2 force(0, 1500);
  c.update(entry, &map, &force);
  CHECK_FALSE(c.in_soil());  // 1.5 kN: below the threshold (and the map, which says "in soil", is not used)
  force = Vec2(0, 2500);
  c.update(entry, &map, &force);
  REQUIRE(c.in_soil());
  CHECK(c.anchor() == entry);
  // Depth is measured from the entry point's height: 0.2 m below it, S = 0.365 * 0.2 + 0.00754. (The
  // map, 10 m above, would give a depth of 10.3 m and S = 3.8 m: no shear below.)
  const double depth = 0.2, shear = shear_failure_distance(depth);
  force = Vec2(0, 1200);  // above half the threshold: still in contact
  const Vec2 deep(entry.x(), entry.y() - depth);
  c.update(deep, &map, &force);  // 0.2 m from the entry anchor: more than S, re-anchored at the tip
  CHECK(c.in_soil());
  CHECK(c.anchor() == deep);
  c.update(Vec2(deep.x() - 0.9 * shear, deep.y()), &map, &force);
  CHECK(c.anchor() == deep);
  const Vec2 sheared(deep.x() - 1.1 * shear, deep.y());
  c.update(sheared, &map, &force);
  CHECK(c.anchor() == sheared);  // past S_dist: re-anchored at the tip
  force = Vec2(0, 900);           // below half the threshold: out
  c.update(sheared, &map, &force);
  CHECK_FALSE(c.in_soil());
  c.update(sheared, nullptr, nullptr);  // no force known: no contact
  CHECK_FALSE(c.in_soil());
}

TEST_CASE("firmware/soil contact with a site map: contact below a sloped ground, eq. 11's depth from the map") {
  SoilContactEstimator c;  // use_site_map by default
  Terrain slope;           // z = 0.2 (x - 6): rising away from the machine
  slope.num_points = 2;
  slope.profile[0] = Vec2(0, -1.2);
  slope.profile[1] = Vec2(10, 0.8);
  c.update(Vec2(7.0, 0.15), &slope, nullptr);  // the ground is at 0.2 there: in the soil
  CHECK(c.in_soil());
  CHECK(c.anchor() == Vec2(7.0, 0.15));
  Terrain flat;  // the flat ground would put that tip in the air
  SoilContactEstimator d;
  d.update(Vec2(7.0, 0.15), &flat, nullptr);
  CHECK_FALSE(d.in_soil());
  // At x = 6.5 the ground is at 0.1; 0.3 m below it the shear distance is 0.365 * 0.3 + 0.00754.
  const double shear = shear_failure_distance(0.3);
  c.update(Vec2(6.5, -0.2), &slope, nullptr);
  CHECK(c.anchor() == Vec2(6.5, -0.2));  // moved 0.56 m: far past it
  c.update(Vec2(6.5 - 0.9 * shear, -0.2), &slope, nullptr);
  CHECK(c.anchor() == Vec2(6.5, -0.2));
}

TEST_CASE("firmware/adaptive composite update: told the applied efforts, it identifies the soil's spring and damper on a dig pass (exact model, eq. 27 off)") {
  const Model model = build_model(reference_machine());
  const Task task = read_task(settings::Document::parse(sim::kDigTask, "dig"), model.machine);
  ControllerConfig cfg;
  cfg.adaptation.rate.setZero();  // the composite term alone
  sim::SoilTruth loam;            // theta (200, 5e3, 7e4) on both axes
  const sim::TrackingResult told = sim::run_tracking(model, task, "adaptive", cfg, loam, true);
  const sim::TrackingResult blind = sim::run_tracking(model, task, "adaptive", cfg, loam, false);

  REQUIRE(told.ok);
  REQUIRE(blind.ok);
  MESSAGE("Theta_hat told: " << told.theta_hat.transpose() << "; not told: " << blind.theta_hat.transpose());
  for (int i : {1, 2, 4, 5}) {
    CAPTURE(i);
    CHECK(told.theta_hat[i] == doctest::Approx(loam.theta[i]).epsilon(0.2));
  }
  CHECK(blind.theta_hat == cfg.soil_parameters.theta_initial);  // no applied efforts: nothing to learn from (eq. 27 is off)
  // The observer takes the soil the estimate misses: the error falls against the law without it.
  ControllerConfig no_observer = cfg;
  no_observer.adaptation.external_force.observer = false;
  no_observer.adaptation.external_force.identification_memory = 0;
  const sim::TrackingResult paper = sim::run_tracking(model, task, "adaptive", no_observer, loam, true);
  MESSAGE("RMS (mm) with observer and update: " << 1e3 * told.rms.transpose() << "; without: " << 1e3 * paper.rms.transpose());
  for (int j = 2; j < 4; ++j) CHECK(told.rms[j] < 0.5 * paper.rms[j]);
}

TEST_CASE("firmware/adaptive composite update pauses on a joint whose applied effort is suspect, and the observer holds there") {
  const Model model = build_model(reference_machine());
  ControllerConfig cfg;
  cfg.adaptation.rate.setZero();
  EffortLimits unlimited;
  AdaptiveComputedTorque ctrl(model, adaptive_law_settings(cfg), cfg.period, unlimited);
  Workspace ws(model);
  Vec4 q0;
  REQUIRE(inverse_kinematics(model.machine, 0.0, TipPose{7.0, -0.3, 0.5}, q0) == IkStatus::ok);
  update_closed_chain(model, ws, q0, Vec4::Zero());
  ControlInput in;
  in.q = in.q_d = q0;
  in.soil.anchor_given = true;
  in.soil.in_soil = true;
  in.soil.rho_env = ws.rho + Vec2(0.05, 0.03);  // a stretched spring: the model predicts a soil force
  in.applied.valid = true;
  in.applied.effort = Vec4(0, 9e5, -4e5, 2e5);  // far from what the model and the prediction say
  in.applied.suspect = 0x0F;                     // but every joint's effort is known off the model
  ControlOutput out;
  for (int k = 0; k < 300; ++k) out = ctrl.update(in);
  CHECK(ctrl.theta_hat() == cfg.soil_parameters.theta_initial);
  CHECK(out.disturbance == Vec4::Zero());  // the observer holds (never primed on a suspect effort)
  in.applied.suspect = 0b0100;  // only the arm's effort is suspect
  for (int k = 0; k < 300; ++k) out = ctrl.update(in);
  CHECK(out.disturbance[2] == 0.0);
  CHECK(std::abs(out.disturbance[1]) > 1e3);  // the others primed and learning
  const Vec6 arm_out = ctrl.theta_hat();
  CHECK(arm_out != cfg.soil_parameters.theta_initial);  // the update runs on boom and bucket
  in.applied.suspect = 0;
  for (int k = 0; k < 300; ++k) out = ctrl.update(in);
  CHECK(std::abs(out.disturbance[2]) > 1e3);  // trusted again: primed at its first residual
}
