#pragma once
// The simulated excavator as a library: load a scene, step one control cycle at a time with actuator
// commands, read the sensors and the full state. step() reads top to bottom: soil -> actuators ->
// dynamics -> integrate -> checks (MuJoCo's mj_step order), with the integrator's substeps inside one
// cycle. After construction nothing allocates; failures stop the plant with a message (PlantStatus).
#include <cstdint>
#include <string>

#include "model/actuator_friction.hpp"
#include "model/workspace.hpp"
#include "sim_plant/actuators.hpp"
#include "sim_plant/integrators.hpp"
#include "sim_plant/plant_checks.hpp"
#include "sim_plant/scene.hpp"
#include "sim_plant/sensors.hpp"
#include "sim_plant/soil.hpp"

namespace exc::plant {

struct PlantState {
  double time = 0;                 // s
  std::int64_t cycle = 0;          // cycles stepped
  Vec4 q_a = Vec4::Zero(), qd_a = Vec4::Zero(), qdd_a = Vec4::Zero();
  Vec12 q = Vec12::Zero(), qd = Vec12::Zero();  // the tree's 12 coordinates (Table 1 order)
  Vec3 tip_world = Vec3::Zero();   // m
  Vec2 rho = Vec2::Zero(), rhod = Vec2::Zero();  // tip in the swing plane (x, world z)
  Vec2 soil_force = Vec2::Zero();  // N, total force of the bucket on the soil (eq. 9)
  Vec2 soil_anchor = Vec2::Zero(); // rho_env
  bool in_soil = false;
  double depth = 0;                // m, terrain height - tip z
  int reanchor_count = 0;          // shear failures so far (eq. 11)
  Vec4 effort = Vec4::Zero();      // N m, N: efforts actually applied (limited: over the last substep)
  Vec4 spool = Vec4::Zero();       // hydraulic: spool positions (-1..1)
  Vec4 pressure_a = Vec4::Zero(), pressure_b = Vec4::Zero();  // Pa (hydraulic; swing motor ports first)
  HydraulicReport hydraulics;      // hydraulic: pumps, flows, relief/cavitation/saturation counts, energy
  double kinetic_energy = 0, potential_energy = 0;  // J
  // J: energy minus (initial energy + work of actuators and soil); hydraulic: energy includes the
  // oil's compression energy and the actuators' work is what the pumps and the tank line supplied
  // net of the circuit's losses (HydraulicEnergy).
  double energy_error = 0;
  double actuator_work = 0, soil_work = 0;          // J, done on the machine
  double constraint_residual = 0;  // m, |h(q)|
  int end_stop_events = 0;         // substeps at which an end stop or a speed limit acted
  double end_stop_loss = 0;        // J the end stops' impacts and the speed limits took (inelastic), in the energy balance
  double friction_loss = 0;        // J the hydraulic machine's friction took, viscous and dry (in the energy balance)
  unsigned friction_stuck = 0;     // hydraulic: bit i set while function i is held by its static friction
  int friction_sweeps = 0;         // hydraulic: Gauss-Seidel sweeps of the last substep's dry friction
  int implicit_iterations = 0;     // of the last substep (implicit_midpoint)
};

// Every double of the plant's state, its circuit's report included, by name, to a state visitor (as
// visit_state(HydraulicReport); held to the struct by `plant/visit_state visits every double of
// PlantState once`).
template <typename Visitor>
void visit_state(const PlantState& s, Visitor& v) {
  v.visit("plant time", s.time);
  v.visit("plant q_a", s.q_a);
  v.visit("plant qd_a", s.qd_a);
  v.visit("plant qdd_a", s.qdd_a);
  v.visit("plant q (tree)", s.q);
  v.visit("plant qd (tree)", s.qd);
  v.visit("plant tip_world", s.tip_world);
  v.visit("plant rho", s.rho);
  v.visit("plant rhod", s.rhod);
  v.visit("plant soil_force", s.soil_force);
  v.visit("plant soil_anchor", s.soil_anchor);
  v.visit("plant depth", s.depth);
  v.visit("plant effort", s.effort);
  v.visit("plant spool", s.spool);
  v.visit("plant pressure_a", s.pressure_a);
  v.visit("plant pressure_b", s.pressure_b);
  visit_state(s.hydraulics, v);
  v.visit("plant kinetic_energy", s.kinetic_energy);
  v.visit("plant potential_energy", s.potential_energy);
  v.visit("plant energy_error", s.energy_error);
  v.visit("plant actuator_work", s.actuator_work);
  v.visit("plant soil_work", s.soil_work);
  v.visit("plant constraint_residual", s.constraint_residual);
  v.visit("plant end_stop_loss", s.end_stop_loss);
  v.visit("plant friction_loss", s.friction_loss);
}

class Plant {
 public:
  explicit Plant(const Scene& scene);
  Plant(const Plant&) = delete;
  Plant& operator=(const Plant&) = delete;

  // Fault injection (the fault campaign): the soil stiffer by `scale` from now on (1: the scene's).
  void set_soil_stiffness_scale(double scale) { soil_.set_stiffness_scale(scale, scene_.soil); }
  // Fault injection (a fidelity with kHydraulicCircuit): the spool of `function` (0 swing .. 3 bucket) stuck at
  // `spool` (-1..1) whatever is commanded, from the next step until release_spool() or reset().
  void stick_spool(int function, double spool) { actuators_.stick_spool(function, spool); }
  void release_spool() { actuators_.release_spool(); }
  // The spools a healthy valve would have (a stuck one's where its command would have taken it;
  // HydraulicCircuit::healthy_spool): the truth a stuck spool's onset of disagreement is judged on.
  Vec4 healthy_spool() const { return actuators_.healthy_spool(); }
  // The hydraulic machine's pumps deliver `scale` of their flow from now on (1: the machine's).
  void set_pump_flow_scale(double scale) { actuators_.set_pump_flow_scale(scale); }
  // The machine's safety hardware (kHydraulicCircuit; HydraulicCircuit): the pilot cut-off, the
  // engine stop and the emergency stop's solenoids (pump-line shut-off, holding valves, swing
  // brake). Their state: state().hydraulics, or PlantNode's PlantState bits.
  void set_pilot_supply(bool on) { actuators_.set_pilot_supply(on); }
  void set_engine_running(bool on) { actuators_.set_engine_running(on); }
  void set_safety_solenoids(bool energised) { actuators_.set_safety_solenoids(energised); }
  void set_swing_lock(bool on) { actuators_.set_swing_lock(on); }
  // Back to the scene's initial state (time 0, soil untouched, sensors reseeded).
  void reset();
  // Advance one control cycle (scene.cycle, 1 ms by default) with this command held.
  PlantStatus step(const ActuatorCommand& command);

  const PlantState& state() const { return state_; }
  const SensorReading& sensors() const { return sensors_.latest(); }
  const PlantStatus& status() const { return status_; }
  const Scene& scene() const { return scene_; }
  // The scene's actuator fidelity: what its actuators take and do (actuator_fidelity.hpp).
  const ActuatorFidelityEntry& fidelity() const { return actuators_.fidelity(); }
  const Model& model() const { return model_; }
  const Workspace& workspace() const { return ws_; }  // the dynamics' buffers at the last evaluation
  // Its state, its sensors' latest reading and the dynamics' workspace, to a state visitor (the
  // subnormal scan of PlantNode::scan_state): what the plant reports of itself from step to step.
  template <typename Visitor>
  void visit_state(Visitor& v) const {
    plant::visit_state(state_, v);
    plant::visit_state(sensors(), v);
    exc::visit_state(ws_, v);
  }
  // Efforts that hold the initial state still (gravity only): the hydraulic chambers start there.
  const Vec4& hold_effort() const { return hold_effort_; }
  double energy() const { return state_.kinetic_energy + state_.potential_energy; }
  double constraint_residual() const { return state_.constraint_residual; }

 private:
  // The spools the sensors measure: the hydraulic circuit's, none on a force-commanded plant.
  const Vec4* measured_spools() const;
  bool accept_command(const ActuatorCommand& command);
  bool apply_limits(const Vec4& qd_start);
  Vec4 apply_dry_friction(const MechanicalState& before);
  void account_work(const Vec4& tau, const MechanicalState& before, const Evaluation& start, const Vec2& rho1,
                    const Vec2& rhod1);
  void fill_state(const Evaluation& last);

  Scene scene_;
  Model model_;
  Workspace ws_;
  SoilModel soil_;
  ActuatorModel actuators_;
  SensorModel sensors_;
  Integrator integrator_;
  MechanicalState mech_;
  PlantState state_;
  PlantStatus status_;
  Vec4 hold_effort_ = Vec4::Zero();
  ActuatorFriction friction_;  // hydraulic: the machine's friction (model/actuator_friction.hpp)
  Vec4 dry_impulse_ = Vec4::Zero();  // the last substep's dry-friction impulses (the next one's first guess)
  Vec4 q_min_, q_max_, speed_max_;
  int substeps_ = 1;
  double energy0_ = 0, work_abs_ = 0;
  Vec2 rho_ = Vec2::Zero(), rhod_ = Vec2::Zero();
};

}  // namespace exc::plant
