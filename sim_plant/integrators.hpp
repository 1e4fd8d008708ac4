#pragma once
// Time integration of the closed chain: the registered methods (integration_methods.hpp) x three
// formulations (model.md s.4).
//   methods       semi_implicit_euler (symplectic Euler: v then q), rk4 (classical), implicit_midpoint
//                 (symplectic, A-stable; solved by a chord iteration whose Jacobian carries the
//                 soil's stiffness and damping exactly on the constraint manifold, the identity off it)
//   formulations  independent (q_a, qd_a: the loop is closed exactly at every evaluation),
//                 augmented_baumgarte (all 12 coordinates, eq. 8 with Baumgarte terms),
//                 augmented_projection (all 12, eq. 8 as written, then projected back onto h = 0
//                 after every step: passive q from the closed form, qd = Psi qd_a)
// The efforts are held over a step. Nothing here allocates.
#include <string>

#include "settings/enum_table.hpp"
#include "model/closed_chain.hpp"
#include "sim_plant/chamber.hpp"
#include "sim_plant/soil.hpp"

namespace exc::plant {

enum class Formulation { independent, augmented_baumgarte, augmented_projection };

// The names a scene's integrator.formulation takes (and the benches' options).
inline constexpr settings::EnumTable<Formulation, 3> kFormulations{{{
    {Formulation::independent, "independent", "the active coordinates, loops solved each step (eqs. 14-17)"},
    {Formulation::augmented_baumgarte, "augmented_baumgarte", "all joints with loop forces, Baumgarte stabilised (eq. 8)"},
    {Formulation::augmented_projection, "augmented_projection", "all joints with loop forces, projected back on h(q) = 0"},
}}};
inline const char* to_string(Formulation f) { return kFormulations.name_of(f); }

struct IntegratorSettings {
  std::string method = "semi_implicit_euler";  // a registered method's name (integration_methods.hpp)
  Formulation formulation = Formulation::independent;
  double step = 1e-3;              // s
  double baumgarte_alpha = 20.0;   // 1/s (augmented_baumgarte)
  double baumgarte_beta = 20.0;    // 1/s
  int implicit_max_iterations = 12;
  double implicit_tolerance = 1e-10;  // on the midpoint velocity residual (m/s, rad/s)
  // Hydraulic: how the chamber pressures are integrated over each substep (chamber.hpp).
  PressureMethod pressure_method = PressureMethod::backward_euler;
};

// Position and velocity in both coordinate sets. The independent formulation integrates q_a, qd_a
// and fills q, qd from the loop closure; the augmented ones integrate q, qd and read q_a, qd_a off.
struct MechanicalState {
  Vec4 q_a = Vec4::Zero(), qd_a = Vec4::Zero();
  Vec12 q = Vec12::Zero(), qd = Vec12::Zero();
};

// One dynamics evaluation: accelerations and the tip's kinematics at that state.
struct Evaluation {
  ModelReport report;
  Vec4 qdd_a = Vec4::Zero();
  Vec12 qdd = Vec12::Zero();
  Vec2 rho = Vec2::Zero(), rhod = Vec2::Zero(), rhodd = Vec2::Zero();
  TipLoad load;
};

struct StepOutcome {
  ModelReport report;       // the first model failure met, if any
  bool converged = true;    // implicit iteration reached its tolerance
  int iterations = 0;
};

struct IntegrationMethodEntry;

class Integrator {
 public:
  // std::invalid_argument for a method not registered.
  Integrator(const Model& model, const IntegratorSettings& settings);
  const IntegratorSettings& settings() const { return settings_; }
  const IntegrationMethodEntry& method() const { return *method_; }

  // Advance s by dt with efforts tau_a held and the soil's anchor fixed (re-anchoring is the plant's
  // discrete event after the step). 'start' receives the evaluation at the initial state.
  StepOutcome step(Workspace& ws, const SoilModel& soil, const Vec4& tau_a, double dt, MechanicalState& s,
                   Evaluation& start);

  // The dynamics at a state, in the configured formulation.
  Evaluation evaluate(Workspace& ws, const SoilModel& soil, const Vec4& tau_a, const MechanicalState& s);

  // Closes the loop exactly from q_a, qd_a (independent and projection; also the initial state).
  ModelReport project(Workspace& ws, MechanicalState& s);

  // Tip position, velocity and the tree poses/twists (for energy) at s, without dynamics.
  ModelReport kinematics(Workspace& ws, const MechanicalState& s, Vec2& rho, Vec2& rhod);

  // M_a of the independent formulation's last evaluation (semi-implicit Euler: the step's start).
  const Mat4& mass_matrix_a() const { return last_mass_; }

  // Forget the cached loop closure (call when something else wrote the workspace).
  void invalidate_cache() { cache_valid_ = false; }

 private:
  Evaluation evaluate_independent(Workspace& ws, const SoilModel& soil, const Vec4& tau_a, const Vec4& q_a,
                                  const Vec4& qd_a);
  Evaluation evaluate_augmented(Workspace& ws, const SoilModel& soil, const Vec4& tau_a, const Vec12& q,
                                const Vec12& qd);
  StepOutcome step_independent(Workspace& ws, const SoilModel& soil, const Vec4& tau, double h,
                               MechanicalState& s, Evaluation& start);
  StepOutcome step_augmented(Workspace& ws, const SoilModel& soil, const Vec4& tau, double h, MechanicalState& s,
                             Evaluation& start);

  // update_closed_chain, skipped when ws already holds this very state (the end-of-step kinematics
  // are the next step's first evaluation).
  ModelReport closed_chain(Workspace& ws, const Vec4& q_a, const Vec4& qd_a);

  const Model* model_;
  const IntegrationMethodEntry* method_;
  bool cache_valid_ = false;
  Vec4 cached_q_ = Vec4::Zero(), cached_qd_ = Vec4::Zero();
  ModelReport cached_report_;
  IntegratorSettings settings_;
  Mat4 last_effective_mass_ = Mat4::Identity();  // M_a + J_t^T M_t J_t of the last evaluation
  Mat4 last_mass_ = Mat4::Identity();            // M_a of the last evaluation
  Mat2x4 last_J_t_ = Mat2x4::Zero();
};

}  // namespace exc::plant
