// The integrator's formulations (independent, augmented): the dynamics a registered method's step
// evaluates (integration_methods.hpp), and the implicit methods' iteration matrices.
#include "sim_plant/integrators.hpp"

#include <cmath>

#include <Eigen/Cholesky>

#include "model/forward_dynamics.hpp"
#include "model/front_kinematics.hpp"
#include "model/newton_euler.hpp"
#include "sim_plant/integration_methods.hpp"

namespace exc::plant {

Integrator::Integrator(const Model& model, const IntegratorSettings& settings)
    : model_(&model), method_(&integration_methods().at(settings.method)), settings_(settings) {}

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
  struct Independent final : StepDynamics<Vec4> {
    Independent(Integrator& i, Workspace& w, const SoilModel& so, const Vec4& t, double step)
        : integrator(i), ws(w), soil(so), tau(t), h(step) {}
    Evaluation evaluate(const Vec4& q, const Vec4& v) override { return integrator.evaluate_independent(ws, soil, tau, q, v); }
    const Vec4& acceleration(const Evaluation& e) const override { return e.qdd_a; }
    // Newton with the Jacobian I + h/2 A^-1 J_t^T (B_t + h/2 K_t) J_t, exact for the soil (the stiff
    // part), the rigid-body terms left to the iteration.
    bool correct(const Evaluation& e, const Vec4& r, Vec4& dw) override {
      Mat4 jac = integrator.last_effective_mass_;
      if (e.load.added_mass.any() || e.load.force.any()) {
        const Vec2 c = soil.parameters().damping + 0.5 * h * soil.parameters().stiffness;
        jac += 0.5 * h * integrator.last_J_t_.transpose() * c.asDiagonal() * integrator.last_J_t_;
      }
      const Eigen::LLT<Mat4> llt(jac);
      dw = -llt.solve(integrator.last_effective_mass_ * r);
      return dw.allFinite();
    }
    Integrator& integrator;
    Workspace& ws;
    const SoilModel& soil;
    const Vec4& tau;
    double h;
  } dynamics(*this, ws, soil, tau, h);
  out = method_->step_independent(settings_, h, q0, v0, start, dynamics, s.q_a, s.qd_a);
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
  const bool soil_active = method_->implicit && (start.load.added_mass.any() || start.load.force.any());
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
  struct Augmented final : StepDynamics<Vec12> {
    Augmented(Integrator& i, Workspace& w, const SoilModel& so, const Vec4& t, bool active, const Mat12x4& psi,
              const Mat4& a, const Eigen::LLT<Mat4>& l)
        : integrator(i), ws(w), soil(so), tau(t), soil_active(active), Psi(psi), A(a), llt(l) {}
    Evaluation evaluate(const Vec12& q, const Vec12& v) override { return integrator.evaluate_augmented(ws, soil, tau, q, v); }
    const Vec12& acceleration(const Evaluation& e) const override { return e.qdd; }
    bool correct(const Evaluation&, const Vec12& r, Vec12& dw) override {
      dw = -r;
      if (soil_active) {
        Vec4 r_a;
        for (int k = 0; k < kNumActive; ++k) r_a[k] = r[kActiveJoints[k]];
        const Vec4 dw_a = -llt.solve(A * r_a);
        dw = -(r - Psi * r_a) + Psi * dw_a;
      }
      return true;
    }
    Integrator& integrator;
    Workspace& ws;
    const SoilModel& soil;
    const Vec4& tau;
    bool soil_active;
    const Mat12x4& Psi;
    const Mat4& A;
    const Eigen::LLT<Mat4>& llt;
  } dynamics(*this, ws, soil, tau, soil_active, Psi, A, llt);
  out = method_->step_augmented(settings_, h, q0, v0, start, dynamics, s.q, s.qd);
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
