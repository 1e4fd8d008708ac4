// The shipped integration methods (model.md s.4), one line each in shipped_methods, and
// the registry that holds them.
#include "sim_plant/integration_methods.hpp"

#include <stdexcept>

namespace exc::plant {
namespace {

// Symplectic Euler: the velocity first, then the position with the new velocity (so an impulse at the
// step's end moved the position by all of it: impulse_position_share 1).
struct SemiImplicitEuler {
  template <class V>
  static StepOutcome step(const IntegratorSettings&, double h, const V& q0, const V& v0, const Evaluation& start,
                          StepDynamics<V>& dynamics, V& q, V& v) {
    v = v0 + h * dynamics.acceleration(start);
    q = q0 + h * v;
    return StepOutcome{};
  }
};

// Classical Runge-Kutta, fourth order.
struct Rk4 {
  template <class V>
  static StepOutcome step(const IntegratorSettings&, double h, const V& q0, const V& v0, const Evaluation& start,
                          StepDynamics<V>& dynamics, V& q, V& v) {
    StepOutcome out;
    const V k1v = dynamics.acceleration(start), k1q = v0;
    Evaluation e = dynamics.evaluate(q0 + 0.5 * h * k1q, v0 + 0.5 * h * k1v);
    if (!e.report.ok()) return out.report = e.report, out;
    const V k2v = dynamics.acceleration(e), k2q = v0 + 0.5 * h * k1v;
    e = dynamics.evaluate(q0 + 0.5 * h * k2q, v0 + 0.5 * h * k2v);
    if (!e.report.ok()) return out.report = e.report, out;
    const V k3v = dynamics.acceleration(e), k3q = v0 + 0.5 * h * k2v;
    e = dynamics.evaluate(q0 + h * k3q, v0 + h * k3v);
    if (!e.report.ok()) return out.report = e.report, out;
    const V k4v = dynamics.acceleration(e), k4q = v0 + h * k3v;
    q = q0 + h / 6.0 * (k1q + 2 * k2q + 2 * k3q + k4q);
    v = v0 + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
    return out;
  }
};

// Implicit midpoint, symplectic and A-stable. Unknown: the midpoint velocity w, with
// w = v0 + h/2 a(q0 + h/2 w, w), iterated with StepDynamics::correct.
struct ImplicitMidpoint {
  template <class V>
  static StepOutcome step(const IntegratorSettings& settings, double h, const V& q0, const V& v0, const Evaluation& start,
                          StepDynamics<V>& dynamics, V& q, V& v) {
    StepOutcome out;
    V w = v0 + 0.5 * h * dynamics.acceleration(start);
    out.converged = false;
    for (int it = 0; it < settings.implicit_max_iterations; ++it) {
      const Evaluation e = dynamics.evaluate(q0 + 0.5 * h * w, w);
      if (!e.report.ok()) return out.report = e.report, out;
      const V r = w - v0 - 0.5 * h * dynamics.acceleration(e);
      out.iterations = it + 1;
      V dw;
      if (!dynamics.correct(e, r, dw)) return out.report = ModelReport{ModelStatus::singular, -1, 0}, out;
      w += dw;
      if (r.template lpNorm<Eigen::Infinity>() < settings.implicit_tolerance * (1.0 + w.template lpNorm<Eigen::Infinity>())) {
        out.converged = true;
        break;
      }
    }
    q = q0 + h * w;
    v = 2.0 * w - v0;
    return out;
  }
};

IntegrationMethodRegistry shipped_methods() {
  IntegrationMethodRegistry r;
  r.add(integration_method<SemiImplicitEuler>("semi_implicit_euler", "symplectic Euler, first order (the default)",
                                              Solve::explicitly, 1.0));
  r.add(integration_method<Rk4>("rk4", "classical Runge-Kutta, fourth order"));
  r.add(integration_method<ImplicitMidpoint>("implicit_midpoint", "implicit midpoint, second order, symplectic",
                                             Solve::implicitly));
  return r;
}

}  // namespace

void IntegrationMethodRegistry::add(IntegrationMethodEntry entry) {
  if (!entry.step_independent || !entry.step_augmented)
    throw std::invalid_argument("integration method '" + entry.name + "' needs a step on both coordinate sets");
  NameRegistry::add(std::move(entry));
}

IntegrationMethodRegistry& integration_methods() {
  static IntegrationMethodRegistry registry = shipped_methods();
  return registry;
}

void register_integration_method(IntegrationMethodEntry entry) { integration_methods().add(std::move(entry)); }

}  // namespace exc::plant
