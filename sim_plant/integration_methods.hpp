#pragma once
// The integration methods, each declared once: its name (a scene's integrator.method, the benches'
// rows), its one-line description, its step on either coordinate set, and what the plant needs to
// know of it. The scene reader, the benches and the sweeps read this registry. The shipped methods
// are registered one line each in integration_methods.cpp at the registry's first use (an explicit
// list: a static library drops self-registering objects nothing references); a program or test adds
// its own with register_integration_method before it reads a scene. A method's step runs every plant
// step: nothing in it allocates.
#include <string>

#include "settings/name_registry.hpp"
#include "sim_plant/integrators.hpp"

namespace exc::plant {

// What a method's step may ask of the dynamics, on the independent coordinates (V = Vec4) or on all
// twelve (V = Vec12). The efforts and the soil's anchor are held over the step.
template <class V>
class StepDynamics {
 public:
  // The dynamics at (q, v); its accelerations are acceleration(e).
  virtual Evaluation evaluate(const V& q, const V& v) = 0;
  virtual const V& acceleration(const Evaluation& e) const = 0;
  // An implicit method's update dw of its unknown velocity from the residual r at evaluation e:
  // Newton on the independent coordinates, a chord iteration on the augmented ones, both carrying the
  // soil's stiffness and damping exactly (integrators.cpp). false: the iteration matrix is singular.
  virtual bool correct(const Evaluation& e, const V& r, V& dw) = 0;

 protected:
  ~StepDynamics() = default;
};

// One step of size h from (q0, v0), where `start` was evaluated, to (q, v).
template <class V>
using MethodStep = StepOutcome (*)(const IntegratorSettings& settings, double h, const V& q0, const V& v0,
                                   const Evaluation& start, StepDynamics<V>& dynamics, V& q, V& v);

struct IntegrationMethodEntry {
  std::string name;
  std::string what;
  MethodStep<Vec4> step_independent = nullptr;
  MethodStep<Vec12> step_augmented = nullptr;
  // The method calls StepDynamics::correct: the augmented step then prepares the soil's iteration
  // matrix at the step's start (a cost the explicit methods do not pay).
  bool implicit = false;
  // Of a velocity change made at the step's end (an end stop's or dry friction's impulse), the share
  // that moved the position over the step: 1 when the position advanced with the end velocity
  // (semi-implicit Euler), 1/2 when it advanced with the step's mean velocity.
  double impulse_position_share = 0.5;
};

enum class Solve : bool { explicitly, implicitly };

// The entry of a method type whose `template <class V> static StepOutcome step(...)` is a MethodStep
// for either V.
template <class Method>
IntegrationMethodEntry integration_method(std::string name, std::string what, Solve solve = Solve::explicitly,
                                          double impulse_position_share = 0.5) {
  return {std::move(name), std::move(what), &Method::template step<Vec4>, &Method::template step<Vec12>,
          solve == Solve::implicitly, impulse_position_share};
}

class IntegrationMethodRegistry : public settings::NameRegistry<IntegrationMethodEntry> {
 public:
  IntegrationMethodRegistry() : NameRegistry("integration method") {}
  // Throws std::invalid_argument for an empty or taken name or a missing step.
  void add(IntegrationMethodEntry entry);
};

// The process's methods: the shipped ones, then whatever was registered (before threads start).
IntegrationMethodRegistry& integration_methods();
void register_integration_method(IntegrationMethodEntry entry);

}  // namespace exc::plant
