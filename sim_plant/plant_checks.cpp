// The plant's watchdogs.
#include "sim_plant/plant_checks.hpp"

#include <cmath>
#include <cstdarg>
#include <cstdio>

#include "sim_plant/integration_methods.hpp"

namespace exc::plant {

const char* to_string(PlantFailure f) {
  switch (f) {
    case PlantFailure::none: return "none";
    case PlantFailure::non_finite: return "non_finite";
    case PlantFailure::model: return "model";
    case PlantFailure::near_toggle: return "near_toggle";
    case PlantFailure::energy_growth: return "energy_growth";
    case PlantFailure::constraint_drift: return "constraint_drift";
    case PlantFailure::end_stop: return "end_stop";
    case PlantFailure::not_converged: return "not_converged";
    case PlantFailure::bad_command: return "bad_command";
    case PlantFailure::pressure_range: return "pressure_range";
  }
  return "?";
}

void set_failure(PlantStatus& status, PlantFailure failure, double time, std::int64_t cycle, const char* format, ...) {
  status.failure = failure;
  status.time = time;
  status.cycle = cycle;
  const int n = std::snprintf(status.message.data(), status.message.size(), "plant stopped at t = %.4f s (cycle %lld): ",
                              time, static_cast<long long>(cycle));
  if (n < 0 || n >= static_cast<int>(status.message.size())) return;
  va_list args;
  va_start(args, format);
  std::vsnprintf(status.message.data() + n, status.message.size() - n, format, args);
  va_end(args);
}

namespace {

// "rk4 / independent at step 2 ms": names the integrator and proposes half the step.
void unstable(PlantStatus& status, PlantFailure failure, const CheckInputs& in, const char* what, double value,
              double limit) {
  const IntegratorSettings& s = *in.integrator;
  // An unstable explicit method: the implicit one; an unstable implicit one: the fourth-order one.
  const char* other = integration_methods().at(s.method).implicit ? "rk4" : "implicit_midpoint";
  // Explicit pressures of a hydraulic machine are the first suspect.
  const bool explicit_pressures = in.pressure_a != nullptr && s.pressure_method == PressureMethod::forward_euler;
  set_failure(status, failure, in.time, in.cycle,
              "%s (%.4g, limit %.4g) with integrator %s / %s%s at step %.4g s: the integration is unstable here; "
              "use a smaller integrator.step (try %.4g s) or another integrator.%s (%s)",
              what, value, limit, s.method.c_str(), to_string(s.formulation),
              explicit_pressures ? " / pressures forward_euler" : "", s.step, 0.5 * s.step,
              explicit_pressures ? "pressure_method" : "method", explicit_pressures ? "backward_euler" : other);
}

}  // namespace

bool run_plant_checks(const CheckSettings& settings, const CheckInputs& in, PlantStatus& status) {
  const MechanicalState& st = *in.state;
  const IntegratorSettings& integ = *in.integrator;
  if (!st.q_a.allFinite() || !st.qd_a.allFinite() || !std::isfinite(in.energy) ||
      in.model_report.status == ModelStatus::non_finite_input) {
    unstable(status, PlantFailure::non_finite, in, "NaN or Inf in the state", NAN, 0);
    return false;
  }
  if (in.pressure_a != nullptr && (!in.pressure_a->allFinite() || !in.pressure_b->allFinite())) {
    unstable(status, PlantFailure::non_finite, in, "NaN or Inf in a chamber pressure", NAN, 0);
    return false;
  }
  if (in.model_report.status == ModelStatus::near_toggle) {
    set_failure(status, PlantFailure::near_toggle, in.time, in.cycle,
                "loop %d is near its toggle (conditioning %.3g) at q_a = [%.4f %.4f %.4f %.4f]; keep the bucket "
                "cylinder inside its stroke limits (fidelity limited or hydraulic stops it) or command it away",
                in.model_report.loop, in.model_report.conditioning, st.q_a[0], st.q_a[1], st.q_a[2], st.q_a[3]);
    return false;
  }
  if (!in.model_report.ok()) {
    set_failure(status, PlantFailure::model, in.time, in.cycle,
                "the model reports %s (loop %d) at q_a = [%.4f %.4f %.4f %.4f] with integrator %s / %s at step "
                "%.4g s; a cylinder left the lengths where the mechanism assembles: use a smaller integrator.step "
                "(try %.4g s) if the motion was unstable, or actuators.fidelity limited (end stops)",
                to_string(in.model_report.status), in.model_report.loop, st.q_a[0], st.q_a[1], st.q_a[2], st.q_a[3],
                integ.method.c_str(), to_string(integ.formulation), integ.step, 0.5 * integ.step);
    return false;
  }
  if (!in.implicit_converged) {
    unstable(status, PlantFailure::not_converged, in, "the implicit midpoint iteration did not converge (iterations used",
             integ.implicit_max_iterations, integ.implicit_max_iterations);
    return false;
  }
  const double energy_limit = settings.energy_tolerance + settings.energy_relative_tolerance * in.work_exchanged;
  const double excess = in.energy - in.energy_expected;
  if (excess > energy_limit) {
    unstable(status, PlantFailure::energy_growth, in, "energy grew beyond the work put in (J)", excess, energy_limit);
    return false;
  }
  if (in.pressure_a != nullptr) {
    for (int i = 0; i < kNumActive; ++i) {
      for (int side = 0; side < 2; ++side) {
        const double p = side == 0 ? (*in.pressure_a)[i] : (*in.pressure_b)[i];
        if (p >= in.pressure_min && p <= in.pressure_max) continue;
        const char* chamber =
            side == 0 ? (i == 0 ? "port A" : "bore-side") : (i == 0 ? "port B" : "rod-side");
        // The likely cause: explicit pressures overshooting, else a load the reliefs cannot hold.
        char cause[320];
        if (integ.pressure_method == PressureMethod::forward_euler)
          std::snprintf(cause, sizeof cause,
                        " with integrator.pressure_method forward_euler at step %.4g s: the explicit update overshoots "
                        "at this step (past a valve that opens in between: a make-up valve, a relief); use "
                        "pressure_method backward_euler or a smaller integrator.step (try %.4g s)",
                        integ.step, 0.5 * integ.step);
        else
          std::snprintf(cause, sizeof cause, "%s",
                        ": a relief passes more than its override allows (a load the reliefs cannot hold) or the "
                        "pressures were integrated wrongly; check the reliefs and hydraulics.bulk_modulus");
        set_failure(status, PlantFailure::pressure_range, in.time, in.cycle,
                    "the %s %s pressure is %.6g MPa, outside [%.4g, %.4g] MPa (vapour .. highest relief + "
                    "checks.pressure_check_margin)%s",
                    kActiveNames[i], chamber, p * 1e-6, in.pressure_min * 1e-6, in.pressure_max * 1e-6, cause);
        return false;
      }
    }
  }
  if (in.constraint_residual > settings.constraint_tolerance) {
    set_failure(status, PlantFailure::constraint_drift, in.time, in.cycle,
                "loop-closure residual %.3g m above the tolerance %.3g m with integrator %s / %s at step %.4g s; "
                "use formulation augmented_projection or independent, larger Baumgarte gains, or a smaller step",
                in.constraint_residual, settings.constraint_tolerance, integ.method.c_str(),
                to_string(integ.formulation), integ.step);
    return false;
  }
  if (!in.end_stops) {
    for (int i = 1; i < kNumActive; ++i) {
      const double below = in.q_min[i] - st.q_a[i], above = st.q_a[i] - in.q_max[i];
      if (below > settings.end_stop_margin || above > settings.end_stop_margin) {
        set_failure(status, PlantFailure::end_stop, in.time, in.cycle,
                    "the %s cylinder was driven through its end stop (%.4f m, stroke %.3f..%.3f m); %s actuators "
                    "have no end stops: command it back inside, or use actuators.fidelity limited or hydraulic",
                    kActiveNames[i], st.q_a[i], in.q_min[i], in.q_max[i], in.fidelity);
        return false;
      }
    }
  }
  return true;
}

}  // namespace exc::plant
