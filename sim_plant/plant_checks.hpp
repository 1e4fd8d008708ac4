#pragma once
// The plant's watchdogs (run after every substep): non-finite state, energy growing beyond what the
// actuators and the soil put in (with hydraulic actuators: the pumps and the tank line, net of the
// circuit's losses, with the oil's compression energy counted in), a chamber pressure outside
// [vapour, highest relief + margin], constraint residual above tolerance, the loop solver near the
// four-bar toggle (or with no assembly), a cylinder driven through its end stop, an implicit solve
// that did not converge. A failure stops the plant with a message naming what failed, when, and
// what to change. Messages are written into a fixed buffer: nothing allocates.
#include <array>
#include <cstdint>

#include "model/model_status.hpp"
#include "model/types.hpp"
#include "sim_plant/actuators.hpp"
#include "sim_plant/integrators.hpp"

namespace exc::plant {

struct CheckSettings {
  double constraint_tolerance = 1e-4;      // m, |h(q)| of the loop closure
  double energy_tolerance = 100.0;         // J, absolute slack of the energy balance
  double energy_relative_tolerance = 0.05; // of the work exchanged with actuators and soil so far
  double end_stop_margin = 0.005;          // m, how far past a stroke limit counts as "through" it
  // Pa above the highest relief setting a chamber may reach before the check stops the plant (a
  // relief's override at full flow is ~hydraulics.relief_override).
  double pressure_check_margin = 5.0e6;
};

enum class PlantFailure {
  none = 0,
  non_finite,        // NaN or Inf in the state
  model,             // no assembly / singular dynamics
  near_toggle,       // the loop solver at the four-bar toggle
  energy_growth,     // energy above its balance: the integration is unstable
  constraint_drift,  // augmented form drifted off h(q) = 0
  end_stop,          // a cylinder driven through its end stop (ideal actuators have none)
  not_converged,     // the implicit iteration did not converge
  bad_command,       // command not finite, or of the wrong mode for the fidelity
  pressure_range,    // a hydraulic chamber pressure outside [vapour, highest relief + margin]
};
const char* to_string(PlantFailure f);

struct PlantStatus {
  PlantFailure failure = PlantFailure::none;
  double time = 0;        // s, simulated time of the failure
  std::int64_t cycle = 0;
  std::array<char, 512> message{};  // what failed, when, what to change ("" when ok)
  bool ok() const { return failure == PlantFailure::none; }
  const char* text() const { return message.data(); }
};

// What the checks look at after a substep.
struct CheckInputs {
  double time = 0;
  std::int64_t cycle = 0;
  const MechanicalState* state = nullptr;
  double energy = 0;            // J, kinetic + potential now (hydraulic: + the oil's compression energy)
  double energy_expected = 0;   // J, initial energy + work of actuators (hydraulic: of pumps and tank
                                // line net of losses) and soil so far
  double work_exchanged = 0;    // J, integral of |power| exchanged (scale for the tolerance)
  double constraint_residual = 0;  // m
  ModelReport model_report;
  bool implicit_converged = true;
  Vec4 q_min = Vec4::Zero(), q_max = Vec4::Zero();
  const char* fidelity = "";  // actuators.fidelity's name
  bool end_stops = false;      // the fidelity stops the cylinders at their strokes' ends (kEndStops)
  const IntegratorSettings* integrator = nullptr;
  // Hydraulic chamber pressures (Pa, swing motor ports first) and the range they must stay in;
  // null for the other fidelities.
  const Vec4* pressure_a = nullptr;
  const Vec4* pressure_b = nullptr;
  double pressure_min = 0, pressure_max = 0;
};

// Runs every check in order of severity; on failure fills 'status' and returns false.
bool run_plant_checks(const CheckSettings& settings, const CheckInputs& in, PlantStatus& status);

// Fills status with a failure and a formatted message (printf style, truncated to the buffer).
void set_failure(PlantStatus& status, PlantFailure failure, double time, std::int64_t cycle, const char* format, ...)
    __attribute__((format(printf, 5, 6)));

}  // namespace exc::plant
