// The plant: soil -> actuators -> dynamics -> integrate -> checks, once per substep.
#include "sim_plant/plant.hpp"

#include <cmath>

#include "model/loop_closure.hpp"
#include "sim_plant/mechanical_energy.hpp"

namespace exc::plant {

Plant::Plant(const Scene& scene)
    : scene_(scene),
      model_(build_model(scene.machine)),
      ws_(model_),
      soil_(scene.terrain, scene.soil),
      actuators_(scene.machine, scene.actuators),
      sensors_(scene.sensors),
      integrator_(model_, scene.integrator) {
  q_min_ = scene.machine.q_min();
  q_max_ = scene.machine.q_max();
  speed_max_ = scene.machine.speed_max();
  substeps_ = static_cast<int>(std::lround(scene.cycle / scene.integrator.step));
  if (substeps_ < 1) substeps_ = 1;
  reset();
}

Plant Plant::load(const std::string& scene_path) { return Plant(load_scene(scene_path)); }

void Plant::reset() {
  status_ = PlantStatus{};
  state_ = PlantState{};
  soil_.reset();
  sensors_.reset();
  mech_ = MechanicalState{};
  mech_.q_a = scene_.q_a0;
  mech_.qd_a = scene_.qd_a0;
  integrator_.invalidate_cache();
  const ModelReport r = integrator_.project(ws_, mech_);
  if (!r.ok()) {
    set_failure(status_, r.status == ModelStatus::near_toggle ? PlantFailure::near_toggle : PlantFailure::model, 0, 0,
                "the initial state q_a = [%.4f %.4f %.4f %.4f] does not assemble (%s, loop %d); change "
                "initial_state.q_a",
                mech_.q_a[0], mech_.q_a[1], mech_.q_a[2], mech_.q_a[3], to_string(r.status), r.loop);
    return;
  }
  // Gravity-holding efforts at rest (inverse dynamics, eq. 16b, with qdd = 0 and no soil).
  MechanicalState rest = mech_;
  rest.qd_a.setZero();
  integrator_.invalidate_cache();
  integrator_.project(ws_, rest);
  inverse_dynamics(model_, ws_, Vec4::Zero(), Vec2::Zero(), hold_effort_);
  actuators_.reset(mech_.q_a, hold_effort_);
  integrator_.invalidate_cache();
  integrator_.kinematics(ws_, mech_, rho_, rhod_);
  soil_.commit(rho_);  // a scene may start with the tip in the soil: anchored where it is
  energy0_ = kinetic_energy(model_, ws_) + potential_energy(model_, ws_);
  work_abs_ = 0;
  Evaluation none;
  none.rho = rho_;
  none.rhod = rhod_;
  fill_state(none);
  sensors_.sample(0, mech_.q_a, mech_.qd_a, actuators_.pressure_a(), actuators_.pressure_b());
}

bool Plant::accept_command(const ActuatorCommand& command) {
  const bool hydraulic = scene_.actuators.fidelity == ActuatorFidelity::hydraulic;
  if (!command.value.allFinite()) {
    set_failure(status_, PlantFailure::bad_command, state_.time, state_.cycle,
                "the command holds NaN or Inf; send finite values");
    return false;
  }
  if (hydraulic != (command.mode == ActuatorCommand::valve)) {
    set_failure(status_, PlantFailure::bad_command, state_.time, state_.cycle,
                "a %s command for actuators.fidelity %s; %s", command.mode == ActuatorCommand::valve ? "valve" : "effort",
                to_string(scene_.actuators.fidelity),
                hydraulic ? "hydraulic actuators take valve openings -1..1" : "ideal and limited actuators take efforts");
    return false;
  }
  if (hydraulic && command.value.cwiseAbs().maxCoeff() > 1.0 + 1e-12) {
    set_failure(status_, PlantFailure::bad_command, state_.time, state_.cycle,
                "valve opening outside -1..1 (largest %.4g); clamp the command", command.value.cwiseAbs().maxCoeff());
    return false;
  }
  return true;
}

// End stops and the flow (speed) limit of limited and hydraulic actuators: inelastic, so the state
// stays on its stroke. Returns true if the state was changed.
bool Plant::apply_limits() {
  if (scene_.actuators.fidelity == ActuatorFidelity::ideal) return false;
  bool changed = false;
  for (int i = 0; i < kNumActive; ++i) {
    if (mech_.q_a[i] < q_min_[i]) {
      mech_.q_a[i] = q_min_[i];
      mech_.qd_a[i] = std::max(mech_.qd_a[i], 0.0);
      changed = true;
    } else if (mech_.q_a[i] > q_max_[i]) {
      mech_.q_a[i] = q_max_[i];
      mech_.qd_a[i] = std::min(mech_.qd_a[i], 0.0);
      changed = true;
    }
    if (scene_.actuators.fidelity == ActuatorFidelity::limited && std::abs(mech_.qd_a[i]) > speed_max_[i]) {
      mech_.qd_a[i] = std::copysign(speed_max_[i], mech_.qd_a[i]);
      changed = true;
    }
  }
  return changed;
}

void Plant::account_work(const Vec4& tau, const MechanicalState& before, const Evaluation& start, const Vec2& rho1,
                         const Vec2& rhod1) {
  // Efforts are held over the substep, so their work is exact: tau . (q_a1 - q_a0).
  const double w_act = tau.dot(mech_.q_a - before.q_a);
  // The soil's force on the machine is -F (eq. 9); trapezoid over the tip's displacement.
  const Vec2 f0 = soil_.total_force(start.rho, start.rhod, start.rhodd);
  const Vec2 f1 = soil_.total_force(rho1, rhod1, start.rhodd);
  const double w_soil = -0.5 * (f0 + f1).dot(rho1 - start.rho);
  state_.actuator_work += w_act;
  state_.soil_work += w_soil;
  work_abs_ += std::abs(w_act) + std::abs(w_soil);
}

PlantStatus Plant::step(const ActuatorCommand& command) {
  if (!status_.ok()) return status_;
  if (!accept_command(command)) return status_;
  actuators_.set_command(command);
  const double h = scene_.integrator.step;
  const bool augmented = scene_.integrator.formulation != Formulation::independent;
  Evaluation start;
  for (int k = 0; k < substeps_; ++k) {
    const double t = state_.time + (k + 1) * h;
    const MechanicalState before = mech_;
    // Soil and dynamics are evaluated inside the integrator's stages (the soil load at each stage's
    // tip); the actuators' effort is held over the substep.
    const Vec4 tau = actuators_.effort_over(h, mech_.q_a);
    const StepOutcome out = integrator_.step(ws_, soil_, tau, h, mech_, start);
    state_.implicit_iterations = out.iterations;
    ModelReport report = out.report;
    if (report.ok()) {
      actuators_.advance(h, mech_.q_a, mech_.qd_a);
      if (apply_limits()) {
        ++state_.end_stop_events;
        report = integrator_.project(ws_, mech_);
      }
    }
    if (report.ok() && mech_.q_a.allFinite() && mech_.qd_a.allFinite()) {
      report = integrator_.kinematics(ws_, mech_, rho_, rhod_);
      if (!augmented) {
        mech_.q = ws_.q;
        mech_.qd = ws_.qd;
      }
    }
    CheckInputs in;
    in.time = t;
    in.cycle = state_.cycle + 1;
    in.state = &mech_;
    in.model_report = report;
    in.implicit_converged = out.converged;
    in.q_min = q_min_;
    in.q_max = q_max_;
    in.fidelity = scene_.actuators.fidelity;
    in.integrator = &scene_.integrator;
    if (report.ok()) {
      account_work(tau, before, start, rho_, rhod_);
      state_.kinetic_energy = kinetic_energy(model_, ws_);
      state_.potential_energy = potential_energy(model_, ws_);
      in.energy = state_.kinetic_energy + state_.potential_energy;
      in.energy_expected = energy0_ + state_.actuator_work + state_.soil_work;
      in.work_exchanged = work_abs_;
      if (augmented) {
        Vec8 residual;
        loop_residual(model_, mech_.q, residual);
        state_.constraint_residual = residual.norm();
      }
      in.constraint_residual = state_.constraint_residual;
    }
    if (!run_plant_checks(scene_.checks, in, status_)) {
      state_.time = t;
      return status_;
    }
    state_.soil_force = soil_.total_force(rho_, rhod_, start.rhodd);
    soil_.commit(rho_);  // entry anchor and shear re-anchoring (eqs. 10-11)
  }
  state_.time += substeps_ * h;
  ++state_.cycle;
  // The independent form closes the loop in closed form at every evaluation, so its residual is
  // round-off; it is measured every kResidualPeriod cycles (and at the first) to keep the step cheap.
  constexpr int kResidualPeriod = 64;
  if (!augmented && (state_.cycle % kResidualPeriod == 1 || kResidualPeriod == 1)) {
    Vec8 residual;
    loop_residual(model_, mech_.q, residual);
    state_.constraint_residual = residual.norm();
  }
  fill_state(start);
  sensors_.sample(state_.cycle, mech_.q_a, mech_.qd_a, actuators_.pressure_a(), actuators_.pressure_b());
  return status_;
}

void Plant::fill_state(const Evaluation& last) {
  state_.q_a = mech_.q_a;
  state_.qd_a = mech_.qd_a;
  state_.qdd_a = last.qdd_a;
  state_.q = mech_.q;
  state_.qd = mech_.qd;
  state_.rho = rho_;
  state_.rhod = rhod_;
  const double c = std::cos(mech_.q_a[0]), s = std::sin(mech_.q_a[0]);
  state_.tip_world = Vec3(c * rho_.x(), s * rho_.x(), rho_.y());
  state_.soil_anchor = soil_.anchor();
  state_.in_soil = soil_.in_soil();
  state_.depth = soil_.depth(rho_);
  state_.reanchor_count = soil_.reanchor_count();
  const bool hydraulic = scene_.actuators.fidelity == ActuatorFidelity::hydraulic;
  state_.effort = hydraulic ? actuators_.effort(mech_.q_a) : actuators_.applied();
  state_.spool = actuators_.spool();
  state_.pressure_a = actuators_.pressure_a();
  state_.pressure_b = actuators_.pressure_b();
  state_.energy_error =
      state_.kinetic_energy + state_.potential_energy - (energy0_ + state_.actuator_work + state_.soil_work);
  if (state_.cycle == 0) {
    state_.kinetic_energy = kinetic_energy(model_, ws_);
    state_.potential_energy = potential_energy(model_, ws_);
    state_.energy_error = 0;
  }
}

}  // namespace exc::plant
