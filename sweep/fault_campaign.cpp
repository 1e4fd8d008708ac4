#include "fault_campaign.hpp"

#include <stdexcept>

#include "safety/firmware_faults.hpp"
#include "control/task/path_stop.hpp"
#include "report/run_report.hpp"

namespace exc::sim {
namespace {

using Kind = FaultSchedule::Kind;

// The size of a fault of this kind from a uniform draw x in [0, 1) (docs/sweeps.md).
double fault_magnitude(Kind kind, double x) {
  switch (kind) {
    case Kind::bus_burst: return 0.2 + 0.7 * x;      // fraction of frames damaged
    case Kind::sensor_jump: return 0.02 + 0.3 * x;   // m
    case Kind::actuator_loss: return 0.3 + 0.7 * x;  // fraction of the effort lost
    case Kind::rock: return 5 + 45 * x;              // soil stiffness x
    case Kind::pump_loss: return 0.3 + 0.7 * x;      // fraction of the pumps' flow lost
    case Kind::spool_stuck: return -1 + 2 * x;       // the spool's position, any opening either way
    case Kind::pressure_jump: return 3e6 + 20e6 * x;   // Pa, up (a reading below zero is not on the bus)
    case Kind::pressure_drift: return 5e6 + 45e6 * x;  // Pa/s, up
    default: return 0;
  }
}

constexpr double kToRunEnd = 1e6;  // s: a fault that lasts to the run's end

// Keeps the larger of a table's time and t (null: none yet).
void keep_worst(nlohmann::json& worst, double t) {
  if (worst.is_null() || t > worst.get<double>()) worst = t;
}

nlohmann::json& row(nlohmann::json& table, const std::string& key) {
  nlohmann::json& k = table[key];
  if (k.is_null()) k = {{"runs", 0}, {"tracked", 0}, {"safe_state", 0}, {"neither", 0}};
  return k;
}

}  // namespace

void draw_fault(std::mt19937_64& rng, const std::vector<std::string>& kinds, SweepCase& c) {
  const auto pick = std::uniform_int_distribution<std::size_t>(0, kinds.size() - 1)(rng);
  c.fault = kinds[pick];
  std::uniform_real_distribution<double> u(0.0, 1.0);
  c.fault_start = 1.0 + 5.0 * u(rng);
  c.fault_duration = 0.05 + 0.95 * u(rng);
  c.fault_joint = 1 + static_cast<int>(std::uniform_int_distribution<int>(0, 2)(rng));
  c.fault_magnitude = fault_magnitude(*kFaultKinds.named(c.fault), u(rng));
  if (c.fault == "spool_stuck") {
    // Any of the four functions, swing included, from its start to the run's end (drawn after the
    // others, so the other kinds' draws are those of before).
    c.fault_joint = std::uniform_int_distribution<int>(0, 3)(rng);
    c.fault_duration = kToRunEnd;
  }
}

void check_faults_fit(const std::vector<std::string>& kinds, const SceneBundle& scene) {
  for (const std::string& kind : kinds)
    if (const std::string why = fault_misfit(*kFaultKinds.named(kind), scene.scene); !why.empty())
      throw std::invalid_argument("sweep.faults: " + why);
}

FaultSchedule fault_schedule(const SweepCase& c, std::uint64_t seed) {
  FaultSchedule f;
  if (c.fault == "none") return f;
  f.kind = *kFaultKinds.named(c.fault);
  f.start = c.fault_start;
  f.duration = c.fault_duration;
  f.joint = c.fault_joint;
  f.magnitude = c.fault_magnitude;
  f.seed = seed * 1000003ull + static_cast<std::uint64_t>(c.id);
  return f;
}

nlohmann::json run_outcome(const RunRecord& r, const app::FirmwareSettings& firmware) {
  nlohmann::json o;
  const double watchdog = firmware.controller.watchdog_timeout;
  if (r.first_safe_stop_time >= 0) {
    o["safe_state_time"] = r.first_safe_stop_time;
    o["fault_detected_time"] = r.first_fault_detected_time;
    o["fault_code"] = r.first_fault_code;
  }
  // Judged by the machine, not the mode: when it came to rest for good (plant truth), and whether the
  // emergency stop was sent.
  o["machine_at_rest_time"] = r.machine_at_rest_time >= 0 ? nlohmann::json(r.machine_at_rest_time) : nlohmann::json(nullptr);
  o["estop"] = r.estop;
  if (r.stop_judgement) o["stop"] = stop_json(*r.stop_judgement);
  std::string why;
  if (r.failure.rfind("plant stopped", 0) == 0) {
    why = r.failure;
  } else if (r.first_safe_stop_time >= 0) {
    // A stop along the path latches once the path is at rest: it may take the deceleration's time too.
    const double allowed =
        watchdog + (safety::stops_along_path(static_cast<safety::FirmwareFault>(r.first_fault_code))
                        ? control::PathStop::longest(firmware.controller.path_clock.stop_ramp_time)
                        : 0.0);
    const double late = r.first_safe_stop_time - r.first_fault_detected_time - allowed;
    if (late > 1e-9)
      why = "the safe state " + std::to_string(late * 1e3) + " ms later than allowed after detection (the watchdog time" +
            (allowed > watchdog ? " and the deceleration along the path)" : ")");
    else if (r.stop_judgement && !r.stop_judgement->meets_r3) why = "the stop misses R3: " + r.stop_judgement->why;
    else if (!r.stop_judgement && r.machine_at_rest_time < 0) why = "the firmware stopped but the machine still moved at the run's end";
  } else if (r.tracking_samples == 0) {
    why = r.failure;
  } else {
    const auto& limit = firmware.controller.supervisor.tracking_error_limit;
    for (int j = 0; j < 4 && why.empty(); ++j)
      if (r.max_error[j] > limit[j])
        why = "joint " + std::to_string(j) + "'s true error " + std::to_string(r.max_error[j]) + " beyond its limit " +
              std::to_string(limit[j]) + " without a safe stop";
  }
  o["outcome"] = !why.empty() ? "neither" : r.first_safe_stop_time >= 0 ? "safe_state" : "tracked";
  if (!why.empty()) o["why"] = why;
  return o;
}

void count_campaign_run(nlohmann::json& table, const nlohmann::json& line, const std::string& controller) {
  const nlohmann::json& r = line[controller];
  const nlohmann::json& fault = line["fault"];
  const std::string outcome = r.value("outcome", r["ok"].get<bool>() ? "tracked" : "neither");
  nlohmann::json& k = row(table[controller], fault["kind"].get<std::string>());
  for (nlohmann::json* counts : {&k, line.contains("scene") ? &row(k["scenes"], line["scene"].get<std::string>()) : nullptr}) {
    if (counts == nullptr) continue;
    (*counts)["runs"] = (*counts)["runs"].get<int>() + 1;
    (*counts)[outcome] = (*counts)[outcome].get<int>() + 1;
  }
  if (outcome == "neither") k["neither_cases"].push_back(line["case"]);
  if (!k.contains("worst_time_to_safe_state")) k["worst_time_to_safe_state"] = k["worst_time_from_detection"] = nullptr;
  if (!k.contains("worst_detection")) k["worst_detection"] = k["worst_time_to_rest"] = nullptr;
  if (!k.contains("estop")) k["estop"] = 0;
  if (outcome == "safe_state" && r.contains("safe_state_time")) {
    const double stop = r["safe_state_time"].get<double>();
    const double start = fault["start"].get<double>();
    keep_worst(k["worst_time_to_safe_state"], stop - start);
    if (r.contains("fault_detected_time")) {
      keep_worst(k["worst_time_from_detection"], stop - r["fault_detected_time"].get<double>());
      keep_worst(k["worst_detection"], r["fault_detected_time"].get<double>() - start);
    }
    if (r.contains("machine_at_rest_time") && !r["machine_at_rest_time"].is_null())
      keep_worst(k["worst_time_to_rest"], std::max(0.0, r["machine_at_rest_time"].get<double>() - start));
  }
  if (r.value("estop", false)) k["estop"] = k["estop"].get<int>() + 1;
}

void count_safety_function(nlohmann::json& table, const nlohmann::json& line, const std::string& controller) {
  const nlohmann::json& r = line[controller];
  const nlohmann::json& fault = line["fault"];
  const bool stopped = r.contains("fault_code") && !r["fault_code"].is_null();
  const std::string name = stopped ? safety::to_string(static_cast<safety::FirmwareFault>(r["fault_code"].get<int>())) : "none";
  nlohmann::json& k = table[controller][name];
  if (k.is_null())
    k = {{"runs", 0}, {"never_at_rest", 0}, {"estop", 0}, {"kinds", nlohmann::json::object()},
         {"worst_detection", nullptr}, {"worst_time_to_rest", nullptr}};
  k["runs"] = k["runs"].get<int>() + 1;
  const std::string kind = fault["kind"].get<std::string>();
  k["kinds"][kind] = k["kinds"].value(kind, 0) + 1;
  if (r.value("estop", false)) k["estop"] = k["estop"].get<int>() + 1;
  if (!stopped) return;
  const double start = fault["start"].get<double>();
  if (r.contains("fault_detected_time")) keep_worst(k["worst_detection"], std::max(0.0, r["fault_detected_time"].get<double>() - start));
  if (r.contains("machine_at_rest_time") && !r["machine_at_rest_time"].is_null())
    keep_worst(k["worst_time_to_rest"], std::max(0.0, r["machine_at_rest_time"].get<double>() - start));
  else
    k["never_at_rest"] = k["never_at_rest"].get<int>() + 1;
  // The stop against R1-R3 (docs/safety.md): R1 counted for the faults that stick a spool (a jammed
  // valve actuator sticks its spool where it is) from the onset of the spool's disagreement, or
  // apart when it was found before its spool disagreed past the monitor's limits; R2 and R3 for
  // every stop; exemptions per function.
  if (!r.contains("stop")) return;
  const nlohmann::json& s = r["stop"];
  auto add = [&k](const char* key) { k[key] = k.value(key, 0) + 1; };
  if (kind == "spool_stuck" || kind == "actuator_jam") {
    if (!s.contains("onset_after_s") || s["onset_after_s"].is_null())
      add("r1_found_before_disagreement");
    else
      add(s["meets_r1"].get<bool>() ? "r1_within_100ms_of_onset" : "r1_later_than_100ms_of_onset");
  }
  add(s["meets_r2"].get<bool>() ? "r2_met" : "r2_missed");
  add(s["meets_r3"].get<bool>() ? "r3_met" : "r3_missed");
  if (!s["exempt"].empty()) add("exempt");
  double drift = 0, ring = 0;
  for (int f = 0; f < 4; ++f) {
    bool exempt = false;
    for (const auto& e : s["exempt"]) exempt = exempt || e["function"] == kActiveNames[static_cast<std::size_t>(f)];
    if (exempt) continue;
    drift = std::max(drift, std::abs(s["drift_after_1_5_s"][static_cast<std::size_t>(f)].get<double>()));
    ring = std::max(ring, s["ring_tau_s"][static_cast<std::size_t>(f)].get<double>());
  }
  keep_worst(k["worst_drift"], drift);
  keep_worst(k["worst_ring_tau"], ring);
  if (!s["exempt"].empty()) {
    double travel = 0;
    for (const auto& e : s["exempt"]) travel = std::max(travel, e["travel"].get<double>());
    keep_worst(k["worst_exempt_travel"], travel);
  }
}

}  // namespace exc::sim
