// The plant: soil -> actuators -> dynamics -> integrate -> checks, once per substep.
#include "sim_plant/plant.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "model/loop_closure.hpp"
#include "sim_plant/coulomb_friction.hpp"
#include "sim_plant/integration_methods.hpp"
#include "sim_plant/mechanical_energy.hpp"

namespace exc::plant {

Plant::Plant(const Scene& scene)
    : scene_(scene),
      model_(build_model(scene.machine)),
      ws_(model_),
      soil_(scene.terrain, scene.soil),
      actuators_(scene.machine, scene.actuators, scene.integrator.pressure_method),
      sensors_(scene.sensors),
      integrator_(model_, scene.integrator) {
  q_min_ = scene.machine.q_min();
  q_max_ = scene.machine.q_max();
  speed_max_ = scene.machine.speed_max();
  friction_ = actuator_friction(scene.machine);
  substeps_ = static_cast<int>(std::lround(scene.cycle / scene.integrator.step));
  if (substeps_ < 1) substeps_ = 1;
  reset();
}

void Plant::reset() {
  status_ = PlantStatus{};
  state_ = PlantState{};
  soil_.reset();
  sensors_.reset();
  mech_ = MechanicalState{};
  dry_impulse_.setZero();
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
  sensors_.sample(0, mech_.q_a, mech_.qd_a, actuators_.pressure_a(), actuators_.pressure_b(),
                  actuators_.hydraulics().report().pump_pressure, measured_spools());
}

const Vec4* Plant::measured_spools() const {
  return actuators_.fidelity().has(kHydraulicCircuit) ? &actuators_.spool() : nullptr;
}

bool Plant::accept_command(const ActuatorCommand& command) {
  const ActuatorFidelityEntry& fidelity = actuators_.fidelity();
  if (!command.value.allFinite() || !command.pilot_a.allFinite() || !command.pilot_b.allFinite()) {
    set_failure(status_, PlantFailure::bad_command, state_.time, state_.cycle,
                "the command holds NaN or Inf; send finite values");
    return false;
  }
  // A command of a kind the actuators cannot use stops the plant: running on would silently ignore it.
  if (!fidelity.takes(command.mode)) {
    set_failure(status_, PlantFailure::bad_command, state_.time, state_.cycle,
                "%s commands for actuators.fidelity %s; %s actuators take %s", to_string(command.mode),
                fidelity.name.c_str(), fidelity.name.c_str(),
                fidelity.takes_valves() ? "valve openings -1..1 or pilot pressures, not efforts"
                                        : "efforts (N m, N), not valve or pilot commands");
    return false;
  }
  if (command.mode == ActuatorCommand::valve && command.value.cwiseAbs().maxCoeff() > 1.0 + 1e-12) {
    set_failure(status_, PlantFailure::bad_command, state_.time, state_.cycle,
                "valve opening outside -1..1 (largest %.4g); clamp the command", command.value.cwiseAbs().maxCoeff());
    return false;
  }
  if (command.mode == ActuatorCommand::pilot) {
    const double full = scene_.machine.hydraulics.pilot_full_stroke;
    const double lo = std::min(command.pilot_a.minCoeff(), command.pilot_b.minCoeff());
    const double hi = std::max(command.pilot_a.maxCoeff(), command.pilot_b.maxCoeff());
    if (lo < 0 || hi > full * (1 + 1e-12)) {
      set_failure(status_, PlantFailure::bad_command, state_.time, state_.cycle,
                  "pilot pressure outside 0..%.4g MPa (%.4g .. %.4g MPa); clamp the command", full * 1e-6, lo * 1e-6,
                  hi * 1e-6);
      return false;
    }
  }
  return true;
}

// End stops (fidelities with kEndStops) and the flow (speed) limit (kSpeedLimits): inelastic, so the state
// stays on its stroke. A cylinder through its stop is put back on it, and its velocity into the stop
// removed, both along M_a^-1 e_i: an inelastic contact of the coupled coordinates (the other joints
// keep the momentum the stop does not absorb; kinetic energy can only fall). Clamping the one
// coordinate alone let a force held against the stop accelerate the joints coupled to it through
// M_a without doing work on them: energy from nowhere. The impact's energy 1/2 v^2 / (M_a^-1)_ii,
// v the speed into the stop at the substep's start, goes to state_.end_stop_loss; a cylinder resting
// on its stop (v = 0) loses nothing. The limited actuators' speed limit acts the same way (below),
// and its loss is booked there too. Returns true if the state was changed.
bool Plant::apply_limits(const Vec4& qd_start) {
  const bool end_stops = actuators_.fidelity().has(kEndStops);
  const bool speed_limits = actuators_.fidelity().has(kSpeedLimits);
  if (!end_stops && !speed_limits) return false;
  bool changed = false;
  bool have_inverse = false;
  Mat4 m_inv = Mat4::Identity();
  // M_a^-1 at the state, once per substep and only when a limit acts.
  auto inverse = [&]() -> const Mat4& {
    if (!have_inverse) {
      integrator_.invalidate_cache();
      Mat4 M;
      if (update_closed_chain(model_, ws_, mech_.q_a, mech_.qd_a).ok()) {
        mass_matrix(model_, ws_, M);
        m_inv = M.inverse();
      }
      have_inverse = true;
    }
    return m_inv;
  };
  for (int i = 0; i < kNumActive; ++i) {
    const bool below = mech_.q_a[i] < q_min_[i], above = mech_.q_a[i] > q_max_[i];
    if (end_stops && (below || above)) {
      changed = true;
      const Mat4& mi = inverse();
      const double stop = below ? q_min_[i] : q_max_[i];
      // Back onto the stop along the same direction: the joints coupled to the cylinder give back the
      // displacement the stop's reaction would have denied them within the substep, whatever the
      // integrator's position update was.
      mech_.q_a -= mi.col(i) * ((mech_.q_a[i] - stop) / mi(i, i));
      mech_.q_a[i] = stop;
      const double into = below ? std::min(mech_.qd_a[i], 0.0) : std::max(mech_.qd_a[i], 0.0);
      if (into != 0) {
        mech_.qd_a -= mi.col(i) * (into / mi(i, i));
        mech_.qd_a[i] = 0;
        const double arriving = below ? std::min(qd_start[i], 0.0) : std::max(qd_start[i], 0.0);
        state_.end_stop_loss += 0.5 * arriving * arriving / mi(i, i);
      }
    }
    const double v = mech_.qd_a[i];
    if (speed_limits && std::abs(v) > speed_max_[i]) {
      // The flow limit as an impulse along M_a^-1 e_i (the same as the end stop's): it takes the
      // excess d off this joint and lets the coupled joints keep their momentum (setting the one
      // coordinate instead can add energy through the mass matrix's coupling). The positions give
      // back what the excess moved them within the substep: all of it for semi-implicit Euler, which
      // moves with the end velocity, half for the others, whose velocity grew through the substep.
      // The motion is then the one the valve allows, at the limit over the substep, and the impulse
      // lambda = d / (M_a^-1)_ii spread over it does the work lambda v_limit: the valve's loss,
      // booked in the balance (first order in the step, like the integrator's own error).
      const Mat4& mi = inverse();
      const double limit = std::copysign(speed_max_[i], v);
      const double d = v - limit;
      const double lambda = d / mi(i, i);
      const double moved = integrator_.method().impulse_position_share;
      const Vec4 excess = mi.col(i) * lambda;
      mech_.qd_a -= excess;
      mech_.q_a -= moved * scene_.integrator.step * excess;
      mech_.qd_a[i] = limit;
      state_.end_stop_loss += lambda * limit;
      changed = true;
    }
  }
  if (changed) integrator_.invalidate_cache();
  return changed;
}

// The hydraulic machine's dry friction (coulomb_friction.hpp): impulses along W = M_a^-1 after the
// integrator's step (independent coordinates: M_a of the step's last evaluation, for semi-implicit
// Euler its start, the matrix of its velocity update; the augmented forms M_a at the end state, as
// the end stops). The soil's added mass is left out of W as it is of the end stops': the soil's load
// is held over the step, and its work is booked from the integrator's accelerations, which the
// impulses do not change (with the added mass in W the soil would take a share of every friction
// impulse that no book records: 60 J in 0.3 s of digging, whatever the step). The bound is the
// Stribeck force at the substep's starting speed and chamber pressures, explicit in both: the
// curve's negative slope (Kbrk - 1) Fc / v_brk times h over the effective mass is under 0.1 (the
// bucket at its relief), against 2 for instability. The positions give back what the impulses'
// velocity change moved them within the substep, as the speed limit does (apply_limits); a function
// held by its static friction ends exactly where it would with zero end velocity (at rest, where it
// started). Returns the friction as the generalised force held over the substep, -lambda / h, whose
// work the caller books (friction_loss).
Vec4 Plant::apply_dry_friction(const MechanicalState& before) {
  const double h = scene_.integrator.step;
  const Vec4 fc = coulomb_level(friction_, actuators_.pressure_a(), actuators_.pressure_b());
  Vec4 bound;
  for (int i = 0; i < kNumActive; ++i) bound[i] = h * dry_friction(friction_, i, fc[i], before.qd_a[i]);
  // The swing parking brake, applied while the pilot supply is cut (HydraulicParameters).
  const HydraulicCircuit& circuit = actuators_.hydraulics();
  if (circuit.swing_brake_applied()) bound[0] += h * circuit.parameters().swing_brake_torque;
  const bool independent = scene_.integrator.formulation == Formulation::independent;
  Mat4 inverse_mass;
  if (independent) {
    inverse_mass = integrator_.mass_matrix_a().inverse();
  } else {
    integrator_.invalidate_cache();
    if (!update_closed_chain(model_, ws_, mech_.q_a, mech_.qd_a).ok()) return Vec4::Zero();  // the checks report it
    Mat4 M;
    mass_matrix(model_, ws_, M);
    inverse_mass = M.inverse();
  }
  // A function that stood on an end stop and is pushed into it (a stuck spool at relief): the stop's
  // reaction joins the solve. Left to apply_limits after it, the push's acceleration of the functions
  // coupled to it within the step was still in the velocities friction saw, so their friction opposed
  // a motion the stop then took away and did no net work (a boom and arm ringing on for seconds).
  // Arrivals from free motion stay apply_limits's, which books their impact.
  Vec4 lower = -bound, upper = bound;
  for (int i = 0; i < kNumActive && actuators_.fidelity().has(kEndStops); ++i) {
    if (before.q_a[i] >= q_max_[i] && mech_.qd_a[i] > 0) upper[i] = std::numeric_limits<double>::infinity();
    if (before.q_a[i] <= q_min_[i] && mech_.qd_a[i] < 0) lower[i] = -std::numeric_limits<double>::infinity();
  }
  const DryFrictionImpulses r = dry_friction_impulses(inverse_mass, mech_.qd_a, lower, upper, dry_impulse_);
  dry_impulse_ = r.impulse;
  state_.friction_stuck = r.stuck;
  state_.friction_sweeps = r.sweeps;
  const double moved = integrator_.method().impulse_position_share;
  const Vec4 dv = inverse_mass * r.impulse;
  if (!independent) {
    const Vec12 dv_tree = ws_.Psi * dv;
    mech_.qd -= dv_tree;
    mech_.q -= moved * h * dv_tree;
  }
  mech_.qd_a -= dv;
  mech_.q_a -= moved * h * dv;
  for (int i = 0; i < kNumActive; ++i) {
    if (!(r.stuck & (1u << i))) continue;
    mech_.qd_a[i] = 0;
    mech_.q_a[i] = before.q_a[i] + (1.0 - moved) * h * before.qd_a[i];
    if (!independent) {
      mech_.qd[kActiveJoints[i]] = 0;
      mech_.q[kActiveJoints[i]] = mech_.q_a[i];
    }
  }
  integrator_.invalidate_cache();
  return -r.impulse / h;
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
  const bool hydraulic = actuators_.fidelity().has(kHydraulicCircuit);
  Evaluation start;
  for (int k = 0; k < substeps_; ++k) {
    const double t = state_.time + (k + 1) * h;
    const MechanicalState before = mech_;
    // Soil and dynamics are evaluated inside the integrator's stages (the soil load at each stage's
    // tip); the actuators' effort is held over the substep.
    const Vec4 tau = actuators_.effort_over(h, mech_.q_a);
    // The hydraulic machine's viscous friction, held over the substep from its starting speed (b h / m
    // is under 1e-2 for every function: explicit is stable); its dry friction after the step.
    Vec4 friction = hydraulic ? Vec4(-friction_.viscous.cwiseProduct(mech_.qd_a)) : Vec4::Zero();
    const StepOutcome out = integrator_.step(ws_, soil_, tau + friction, h, mech_, start);
    state_.implicit_iterations = out.iterations;
    ModelReport report = out.report;
    if (report.ok()) {
      if (hydraulic) friction += apply_dry_friction(before);
      if (apply_limits(before.qd_a)) {
        ++state_.end_stop_events;
        report = integrator_.project(ws_, mech_);
      }
      // The actuators follow the motion (after the stops): the chambers sweep A qd h with the
      // substep's end velocity. With the effort held from the substep's start this pairs the oil
      // spring and the mass as symplectic Euler does (stable for every integrator); sweeping the
      // mean velocity (q1 - q0) / h instead makes RK4 and the midpoint rule grow the oil columns'
      // ringing. Against the positions the swept volume is off by h (v_end - v_start) / 2: bounded.
      actuators_.advance(h, mech_.q_a, mech_.qd_a);
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
    in.fidelity = actuators_.fidelity().name.c_str();
    in.end_stops = actuators_.fidelity().has(kEndStops);
    in.integrator = &scene_.integrator;
    if (report.ok()) {
      account_work(tau, before, start, rho_, rhod_);
      state_.friction_loss -= friction.dot(mech_.q_a - before.q_a);
      state_.kinetic_energy = kinetic_energy(model_, ws_);
      state_.potential_energy = potential_energy(model_, ws_);
      in.energy = state_.kinetic_energy + state_.potential_energy;
      in.energy_expected =
          energy0_ + state_.actuator_work + state_.soil_work - state_.end_stop_loss - state_.friction_loss;
      if (hydraulic) {
        const HydraulicEnergy& e = actuators_.hydraulics().report().energy;
        in.energy += e.stored;
        in.energy_expected += e.stored0 + e.supplied() - state_.actuator_work;
        in.pressure_a = &actuators_.pressure_a();
        in.pressure_b = &actuators_.pressure_b();
        in.pressure_min = actuators_.hydraulics().pressure_floor();
        in.pressure_max = actuators_.hydraulics().highest_relief() + scene_.checks.pressure_check_margin;
      }
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
  sensors_.sample(state_.cycle, mech_.q_a, mech_.qd_a, actuators_.pressure_a(), actuators_.pressure_b(),
                  actuators_.hydraulics().report().pump_pressure, measured_spools());
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
  const bool hydraulic = actuators_.fidelity().has(kHydraulicCircuit);
  state_.effort = hydraulic ? actuators_.effort(mech_.q_a) : actuators_.applied();
  state_.spool = actuators_.spool();
  state_.pressure_a = actuators_.pressure_a();
  state_.pressure_b = actuators_.pressure_b();
  state_.hydraulics = actuators_.hydraulics().report();
  state_.energy_error = state_.kinetic_energy + state_.potential_energy -
                        (energy0_ + state_.actuator_work + state_.soil_work - state_.end_stop_loss - state_.friction_loss);
  if (hydraulic) {
    const HydraulicEnergy& e = state_.hydraulics.energy;
    state_.energy_error += e.stored - e.stored0 - e.supplied() + state_.actuator_work;
  }
  if (state_.cycle == 0) {
    state_.kinetic_energy = kinetic_energy(model_, ws_);
    state_.potential_energy = potential_energy(model_, ws_);
    state_.energy_error = 0;
  }
}

}  // namespace exc::plant
