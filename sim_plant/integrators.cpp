// Integrators: semi-implicit Euler, RK4, implicit midpoint; independent and augmented formulations.
#include "sim_plant/integrators.hpp"

#include <cmath>

#include <Eigen/Cholesky>

#include "model/forward_dynamics.hpp"
#include "model/front_kinematics.hpp"
#include "model/newton_euler.hpp"

namespace exc::plant {

namespace {

// One step of the configured method on one coordinate set: V is Vec4 (the independent formulation,
// accelerations in Evaluation::qdd_a) or Vec12 (the augmented ones, Evaluation::qdd). The step starts
// at (q0, v0), where `start` was evaluated, and ends in (q, v). evaluate(q, v) gives the dynamics at
// a state; correct(e, r, dw) gives the implicit midpoint's update dw of its midpoint velocity from the
// residual r at evaluation e (false: singular).
template <class V, class Evaluate, class Correct>
StepOutcome advance(const IntegratorSettings& settings, double h, const V& q0, const V& v0, const Evaluation& start,
                    V Evaluation::*acceleration, Evaluate&& evaluate, Correct&& correct, V& q, V& v) {
  StepOutcome out;
  switch (settings.method) {
    case IntegrationMethod::semi_implicit_euler: {
      v = v0 + h * (start.*acceleration);
      q = q0 + h * v;
      break;
    }
    case IntegrationMethod::rk4: {
      const V k1v = start.*acceleration, k1q = v0;
      Evaluation e = evaluate(q0 + 0.5 * h * k1q, v0 + 0.5 * h * k1v);
      if (!e.report.ok()) return out.report = e.report, out;
      const V k2v = e.*acceleration, k2q = v0 + 0.5 * h * k1v;
      e = evaluate(q0 + 0.5 * h * k2q, v0 + 0.5 * h * k2v);
      if (!e.report.ok()) return out.report = e.report, out;
      const V k3v = e.*acceleration, k3q = v0 + 0.5 * h * k2v;
      e = evaluate(q0 + h * k3q, v0 + h * k3v);
      if (!e.report.ok()) return out.report = e.report, out;
      const V k4v = e.*acceleration, k4q = v0 + h * k3v;
      q = q0 + h / 6.0 * (k1q + 2 * k2q + 2 * k3q + k4q);
      v = v0 + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
      break;
    }
    case IntegrationMethod::implicit_midpoint: {
      // Unknown: the midpoint velocity w, with w = v0 + h/2 a(q0 + h/2 w, w).
      V w = v0 + 0.5 * h * (start.*acceleration);
      out.converged = false;
      for (int it = 0; it < settings.implicit_max_iterations; ++it) {
        const Evaluation e = evaluate(q0 + 0.5 * h * w, w);
        if (!e.report.ok()) return out.report = e.report, out;
        const V r = w - v0 - 0.5 * h * (e.*acceleration);
        out.iterations = it + 1;
        V dw;
        if (!correct(e, r, dw)) return out.report = ModelReport{ModelStatus::singular, -1, 0}, out;
        w += dw;
        if (r.template lpNorm<Eigen::Infinity>() <
            settings.implicit_tolerance * (1.0 + w.template lpNorm<Eigen::Infinity>())) {
          out.converged = true;
          break;
        }
      }
      q = q0 + h * w;
      v = 2.0 * w - v0;
      break;
    }
  }
  return out;
}

}  // namespace

Integrator::Integrator(const Model& model, const IntegratorSettings& settings)
    : model_(&model), settings_(settings) {}

ModelReport Integrator::closed_chain(Workspace& ws, const Vec4& q_a, const Vec4& qd_a) {
  if (cache_valid_ && q_a == cached_q_ && qd_a == cached_qd_) return cached_report_;
  cached_report_ = update_closed_chain(*model_, ws, q_a, qd_a);
  cached_q_ = q_a;
  cached_qd_ = qd_a;
  cache_valid_ = settings_.formulation == Formulation::independent && cached_report_.ok();
  return cached_report_;
}

ModelReport Integrator::project(Workspace& ws, MechanicalState& s) {
  const ModelReport r = closed_chain(ws, s.q_a, s.qd_a);
  if (r.ok()) {
    s.q = ws.q;
    s.qd = ws.qd;
  }
  return r;
}

ModelReport Integrator::kinematics(Workspace& ws, const MechanicalState& s, Vec2& rho, Vec2& rhod) {
  if (settings_.formulation == Formulation::independent) {
    const ModelReport r = closed_chain(ws, s.q_a, s.qd_a);
    rho = ws.rho;
    rhod = ws.rhod;
    return r;
  }
  if (!s.q.allFinite() || !s.qd.allFinite()) return ModelReport{ModelStatus::non_finite_input, -1, 0};
  Vec2 tip;
  front_positions(*model_, s.q, ws);
  front_rates(*model_, s.qd, Vec12::Zero(), ws);
  front_tip(*model_, ws, tip, ws.J_tip_tree, ws.tip_acc_tree);
  rho = tip + Vec2(0.0, model_->machine.swing_height);
  rhod = ws.J_tip_tree * s.qd;
  tree_kinematics(*model_, ws, s.q, s.qd);
  return ModelReport{};
}

Evaluation Integrator::evaluate(Workspace& ws, const SoilModel& soil, const Vec4& tau_a, const MechanicalState& s) {
  if (settings_.formulation == Formulation::independent) return evaluate_independent(ws, soil, tau_a, s.q_a, s.qd_a);
  return evaluate_augmented(ws, soil, tau_a, s.q, s.qd);
}

Evaluation Integrator::evaluate_independent(Workspace& ws, const SoilModel& soil, const Vec4& tau_a, const Vec4& q_a,
                                            const Vec4& qd_a) {
  Evaluation e;
  e.report = closed_chain(ws, q_a, qd_a);
  if (!e.report.ok()) return e;
  e.rho = ws.rho;
  e.rhod = ws.rhod;
  e.load = soil.load(ws.rho, ws.rhod);
  // Independent coordinates with the soil's added mass (model.md s.4, eq. 9):
  // (M_a + J_t^T M_t J_t) qdd_a = tau_a - h_a - J_t^T (f + M_t rhodd_bias).
  Mat4 M_a;
  Vec4 h_a;
  mass_matrix(*model_, ws, M_a);
  bias_forces(*model_, ws, h_a);
  const Mat2 M_t = e.load.added_mass.asDiagonal();
  last_mass_ = M_a;
  last_effective_mass_ = M_a + ws.J_t.transpose() * M_t * ws.J_t;
  last_J_t_ = ws.J_t;
  const Vec4 b = tau_a - h_a - ws.J_t.transpose() * (e.load.force + M_t * ws.rhodd_bias);
  const Eigen::LLT<Mat4> llt(last_effective_mass_);
  if (llt.info() != Eigen::Success) {
    e.report.status = ModelStatus::singular;
    return e;
  }
  e.qdd_a = llt.solve(b);
  if (!e.qdd_a.allFinite()) {
    e.report.status = ModelStatus::singular;
    return e;
  }
  e.qdd = ws.Psi * e.qdd_a + ws.gamma;
  e.rhodd = ws.J_t * e.qdd_a + ws.rhodd_bias;
  return e;
}

Evaluation Integrator::evaluate_augmented(Workspace& ws, const SoilModel& soil, const Vec4& tau_a, const Vec12& q,
                                          const Vec12& qd) {
  Evaluation e;
  if (!q.allFinite() || !qd.allFinite()) {
    e.report.status = ModelStatus::non_finite_input;
    return e;
  }
  // The tip on the (possibly drifted) tree coordinates, for the soil.
  Vec2 tip;
  front_positions(*model_, q, ws);
  front_rates(*model_, qd, Vec12::Zero(), ws);
  front_tip(*model_, ws, tip, ws.J_tip_tree, ws.tip_acc_tree);
  e.rho = tip + Vec2(0.0, model_->machine.swing_height);
  e.rhod = ws.J_tip_tree * qd;
  e.load = soil.load(e.rho, e.rhod);
  const bool baumgarte = settings_.formulation == Formulation::augmented_baumgarte;
  Vec8 lambda;
  e.report = forward_dynamics_augmented(*model_, ws, q, qd, tau_a, e.load, baumgarte ? settings_.baumgarte_alpha : 0.0,
                                        baumgarte ? settings_.baumgarte_beta : 0.0, e.qdd, lambda);
  if (!e.report.ok()) return e;
  for (int k = 0; k < kNumActive; ++k) e.qdd_a[k] = e.qdd[kActiveJoints[k]];
  e.rhodd = ws.J_tip_tree * e.qdd + ws.tip_acc_tree;
  return e;
}

StepOutcome Integrator::step(Workspace& ws, const SoilModel& soil, const Vec4& tau_a, double dt, MechanicalState& s,
                             Evaluation& start) {
  if (settings_.formulation == Formulation::independent) return step_independent(ws, soil, tau_a, dt, s, start);
  return step_augmented(ws, soil, tau_a, dt, s, start);
}

StepOutcome Integrator::step_independent(Workspace& ws, const SoilModel& soil, const Vec4& tau, double h,
                                         MechanicalState& s, Evaluation& start) {
  StepOutcome out;
  const Vec4 q0 = s.q_a, v0 = s.qd_a;
  start = evaluate_independent(ws, soil, tau, q0, v0);
  if (!start.report.ok()) return out.report = start.report, out;
  const auto evaluate = [&](const Vec4& q, const Vec4& v) { return evaluate_independent(ws, soil, tau, q, v); };
  // Implicit midpoint: Newton with the Jacobian I + h/2 A^-1 J_t^T (B_t + h/2 K_t) J_t, exact for the
  // soil (the stiff part), the rigid-body terms left to the iteration.
  const auto newton = [&](const Evaluation& e, const Vec4& r, Vec4& dw) {
    Mat4 jac = last_effective_mass_;
    if (e.load.added_mass.any() || e.load.force.any()) {
      const Vec2 c = soil.parameters().damping + 0.5 * h * soil.parameters().stiffness;
      jac += 0.5 * h * last_J_t_.transpose() * c.asDiagonal() * last_J_t_;
    }
    const Eigen::LLT<Mat4> llt(jac);
    dw = -llt.solve(last_effective_mass_ * r);
    return dw.allFinite();
  };
  out = advance(settings_, h, q0, v0, start, &Evaluation::qdd_a, evaluate, newton, s.q_a, s.qd_a);
  if (!out.report.ok()) return out;
  if (!s.q_a.allFinite() || !s.qd_a.allFinite()) out.report = ModelReport{ModelStatus::non_finite_input, -1, 0};
  return out;
}

StepOutcome Integrator::step_augmented(Workspace& ws, const SoilModel& soil, const Vec4& tau, double h,
                                       MechanicalState& s, Evaluation& start) {
  StepOutcome out;
  const Vec12 q0 = s.q, v0 = s.qd;
  start = evaluate_augmented(ws, soil, tau, q0, v0);
  if (!start.report.ok()) return out.report = start.report, out;
  // Implicit midpoint: a chord iteration whose Jacobian is frozen at the step's start: on the
  // constraint manifold (range of Psi) it is the independent-coordinate one with the soil's stiffness
  // and damping, A^-1 (A + h/2 J_t^T (B + h/2 K) J_t); off the manifold the identity (plain fixed point).
  const bool soil_active = settings_.method == IntegrationMethod::implicit_midpoint &&
                           (start.load.added_mass.any() || start.load.force.any());
  Mat12x4 Psi = Mat12x4::Zero();
  Mat4 A = Mat4::Identity();
  Eigen::LLT<Mat4> llt;
  if (soil_active) {
    Vec4 qa0, va0;
    for (int k = 0; k < kNumActive; ++k) {
      qa0[k] = q0[kActiveJoints[k]];
      va0[k] = v0[kActiveJoints[k]];
    }
    const ModelReport r = update_closed_chain(*model_, ws, qa0, va0);
    cache_valid_ = false;
    if (!r.ok()) return out.report = r, out;
    mass_matrix(*model_, ws, A);
    A += ws.J_t.transpose() * start.load.added_mass.asDiagonal() * ws.J_t;
    const Vec2 c = soil.parameters().damping + 0.5 * h * soil.parameters().stiffness;
    const Mat4 N = A + 0.5 * h * ws.J_t.transpose() * c.asDiagonal() * ws.J_t;
    llt.compute(N);
    Psi = ws.Psi;
  }
  const auto evaluate = [&](const Vec12& q, const Vec12& v) { return evaluate_augmented(ws, soil, tau, q, v); };
  const auto chord = [&](const Evaluation&, const Vec12& r, Vec12& dw) {
    dw = -r;
    if (soil_active) {
      Vec4 r_a;
      for (int k = 0; k < kNumActive; ++k) r_a[k] = r[kActiveJoints[k]];
      const Vec4 dw_a = -llt.solve(A * r_a);
      dw = -(r - Psi * r_a) + Psi * dw_a;
    }
    return true;
  };
  out = advance(settings_, h, q0, v0, start, &Evaluation::qdd, evaluate, chord, s.q, s.qd);
  if (!out.report.ok()) return out;
  if (!s.q.allFinite() || !s.qd.allFinite()) return out.report = ModelReport{ModelStatus::non_finite_input, -1, 0}, out;
  for (int k = 0; k < kNumActive; ++k) {
    s.q_a[k] = s.q[kActiveJoints[k]];
    s.qd_a[k] = s.qd[kActiveJoints[k]];
  }
  if (settings_.formulation == Formulation::augmented_projection) {
    const ModelReport r = project(ws, s);
    if (!r.ok()) out.report = r;
  }
  return out;
}

}  // namespace exc::plant
