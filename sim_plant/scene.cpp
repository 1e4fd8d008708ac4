// Scene loader: yaml-cpp, every field validated, unknown keys rejected (except controller/task).
#include "sim_plant/scene.hpp"

#include <cmath>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace exc::plant {

SceneError::SceneError(std::string file, std::string field, std::string reason)
    : std::runtime_error(file + ": " + (field.empty() ? std::string("(file)") : field) + ": " + reason),
      file_(std::move(file)),
      field_(std::move(field)),
      reason_(std::move(reason)) {}

namespace {

std::string num(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

std::string join(std::initializer_list<const char*> names) {
  std::string out;
  for (const char* n : names) out += (out.empty() ? "" : ", ") + std::string(n);
  return out;
}

// Reads one YAML mapping with a dotted prefix for error messages.
class Section {
 public:
  Section(const std::string& file, const std::string& prefix, const YAML::Node& node)
      : file_(file), prefix_(prefix), node_(node) {
    if (present() && !node_.IsMap()) fail("", "must be a mapping");
  }

  // An absent or empty section ("checks:" with nothing after it) takes every default.
  bool present() const { return node_.IsDefined() && !node_.IsNull(); }
  bool has(const char* key) const { return present() && node_[key]; }
  std::string field(const std::string& key) const { return prefix_.empty() ? key : prefix_ + "." + key; }
  [[noreturn]] void fail(const std::string& key, const std::string& reason) const {
    throw SceneError(file_, key.empty() ? prefix_ : field(key), reason);
  }

  void only(std::initializer_list<const char*> allowed) const {
    if (!present()) return;
    for (const auto& kv : node_) {
      const std::string key = kv.first.as<std::string>();
      bool ok = false;
      for (const char* a : allowed) ok = ok || key == a;
      if (!ok) fail(key, "unknown key; allowed keys: " + join(allowed));
    }
  }

  double number(const char* key, double lo, double hi, double fallback, bool required = false) const {
    if (!has(key)) {
      if (required) fail(key, "missing; a number in [" + num(lo) + ", " + num(hi) + "]");
      return fallback;
    }
    return to_number(node_[key], field(key), lo, hi);
  }

  double to_number(const YAML::Node& n, const std::string& name, double lo, double hi) const {
    double v = 0;
    bool ok = n.IsScalar();
    if (ok) {
      try {
        v = n.as<double>();
      } catch (const YAML::Exception&) {
        ok = false;
      }
    }
    if (!ok) throw SceneError(file_, name, "must be a number in [" + num(lo) + ", " + num(hi) + "]");
    if (!std::isfinite(v) || v < lo || v > hi)
      throw SceneError(file_, name, "is " + num(v) + "; allowed range [" + num(lo) + ", " + num(hi) + "]");
    return v;
  }

  template <int N>
  Eigen::Matrix<double, N, 1> vector(const char* key, const Eigen::Matrix<double, N, 1>& lo,
                                     const Eigen::Matrix<double, N, 1>& hi, const Eigen::Matrix<double, N, 1>& fallback,
                                     bool required = false) const {
    if (!has(key)) {
      if (required) fail(key, "missing; a list of " + std::to_string(N) + " numbers");
      return fallback;
    }
    const YAML::Node n = node_[key];
    if (!n.IsSequence() || static_cast<int>(n.size()) != N)
      fail(key, "must be a list of " + std::to_string(N) + " numbers");
    Eigen::Matrix<double, N, 1> v;
    for (int i = 0; i < N; ++i) v[i] = to_number(n[i], field(key) + "[" + std::to_string(i) + "]", lo[i], hi[i]);
    return v;
  }

  std::string text(const char* key, const std::string& fallback, bool required = false) const {
    if (!has(key)) {
      if (required) fail(key, "missing; a string");
      return fallback;
    }
    if (!node_[key].IsScalar()) fail(key, "must be a string");
    return node_[key].as<std::string>();
  }

  template <typename E>
  E choice(const char* key, std::initializer_list<std::pair<const char*, E>> options, E fallback) const {
    if (!has(key)) return fallback;
    std::string allowed;
    for (const auto& o : options) allowed += (allowed.empty() ? "" : ", ") + std::string(o.first);
    if (!node_[key].IsScalar()) fail(key, "must be one of: " + allowed);
    const std::string v = node_[key].as<std::string>();
    for (const auto& o : options)
      if (v == o.first) return o.second;
    fail(key, "is '" + v + "'; allowed values: " + allowed);
  }

  Section sub(const char* key) const { return Section(file_, field(key), has(key) ? node_[key] : YAML::Node()); }
  const YAML::Node& node() const { return node_; }

 private:
  std::string file_, prefix_;
  YAML::Node node_;
};

std::string resolve(const std::string& base, const std::string& path) {
  if (path.empty() || path[0] == '/') return path;
  return base + "/" + path;
}

Scene parse(const YAML::Node& root, const std::string& file, const std::string& base) {
  Scene s;
  s.file = file;
  const Section top(file, "", root);
  if (!root || !root.IsMap()) throw SceneError(file, "", "the scene must be a YAML mapping");
  top.only({"name", "description", "machine", "terrain", "soil", "initial_state", "actuators", "integrator",
            "duration", "sensors", "checks", "controller", "task"});
  s.name = top.text("name", "", true);
  s.description = top.text("description", "");
  if (top.has("machine")) {
    s.machine_file = resolve(base, top.text("machine", ""));
    try {
      s.machine = load_machine(s.machine_file);
    } catch (const MachineError& e) {
      throw SceneError(file, "machine", std::string("the machine file does not load: ") + e.what());
    }
  } else {
    s.machine = reference_machine();
  }
  const Machine& m = s.machine;

  // Terrain: flat, or a profile along x.
  const Section terrain = top.sub("terrain");
  terrain.only({"height", "profile"});
  s.terrain.height = terrain.number("height", -20, 20, m.terrain_flat_height);
  if (terrain.has("height") && terrain.has("profile")) terrain.fail("profile", "give either 'height' or 'profile', not both");
  if (terrain.has("profile")) {
    const YAML::Node p = terrain.node()["profile"];
    if (!p.IsSequence() || p.size() < 2 || p.size() > static_cast<std::size_t>(Terrain::kMaxPoints))
      terrain.fail("profile", "must be a list of 2.." + std::to_string(Terrain::kMaxPoints) + " points [x, z]");
    s.terrain.num_points = static_cast<int>(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) {
      const std::string name = terrain.field("profile") + "[" + std::to_string(i) + "]";
      if (!p[i].IsSequence() || p[i].size() != 2) throw SceneError(file, name, "must be a point [x, z]");
      s.terrain.profile[i] = Vec2(terrain.to_number(p[i][0], name + "[0]", -100, 100),
                                  terrain.to_number(p[i][1], name + "[1]", -20, 20));
      if (i > 0 && !(s.terrain.profile[i].x() > s.terrain.profile[i - 1].x()))
        throw SceneError(file, name + "[0]", "x must increase strictly along the profile");
    }
  }

  // Soil: a preset or explicit K, B, M (machine.md).
  const Section soil = top.sub("soil");
  soil.only({"preset", "stiffness", "damping", "mass"});
  const bool explicit_soil = soil.has("stiffness") || soil.has("damping") || soil.has("mass");
  if (explicit_soil && soil.has("preset")) soil.fail("preset", "give either 'preset' or stiffness/damping/mass, not both");
  if (explicit_soil) {
    s.soil.stiffness = soil.vector<2>("stiffness", Vec2::Zero(), Vec2::Constant(1e9), Vec2::Zero(), true);
    s.soil.damping = soil.vector<2>("damping", Vec2::Zero(), Vec2::Constant(1e7), Vec2::Zero(), true);
    s.soil.mass = soil.vector<2>("mass", Vec2::Zero(), Vec2::Constant(1e4), Vec2::Zero(), true);
  } else {
    s.soil_preset = soil.choice<SoilPreset>("preset",
                                            {{"none", SoilPreset::none},
                                             {"loose_sand", SoilPreset::loose_sand},
                                             {"loam", SoilPreset::loam},
                                             {"stiff_clay", SoilPreset::stiff_clay}},
                                            SoilPreset::none);
    s.soil = soil_preset(s.soil_preset);
  }

  // Initial state inside the machine's limits.
  const Section init = top.sub("initial_state");
  init.only({"q_a", "qd_a"});
  const double kBig = 1e3;
  Vec4 qlo = m.q_min(), qhi = m.q_max();
  qlo[0] = -2 * M_PI;
  qhi[0] = 2 * M_PI;
  s.q_a0 = init.vector<4>("q_a", qlo, qhi, Vec4::Zero(), true);
  s.qd_a0 = init.vector<4>("qd_a", -m.speed_max(), m.speed_max(), Vec4::Zero());
  (void)kBig;

  // Actuators.
  const Section act = top.sub("actuators");
  act.only({"fidelity", "lag", "valve_time_constant", "bulk_modulus", "dead_volume", "swing_volume",
            "supply_pressure", "tank_pressure", "valve_pressure_drop", "laminar_pressure"});
  ActuatorParameters& a = s.actuators;
  a.fidelity = act.choice<ActuatorFidelity>("fidelity",
                                            {{"ideal", ActuatorFidelity::ideal},
                                             {"limited", ActuatorFidelity::limited},
                                             {"hydraulic", ActuatorFidelity::hydraulic}},
                                            ActuatorFidelity::ideal);
  a.lag = act.number("lag", 0, 1, a.lag);
  a.valve_time_constant = act.number("valve_time_constant", 0, 1, a.valve_time_constant);
  a.bulk_modulus = act.number("bulk_modulus", 1e7, 5e9, a.bulk_modulus);
  a.dead_volume = act.number("dead_volume", 1e-5, 0.1, a.dead_volume);
  a.swing_volume = act.number("swing_volume", 1e-4, 1, a.swing_volume);
  a.supply_pressure = act.number("supply_pressure", 0, 1e8, a.supply_pressure);
  a.tank_pressure = act.number("tank_pressure", 0, 5e6, a.tank_pressure);
  a.valve_pressure_drop = act.number("valve_pressure_drop", 1e5, 3e7, a.valve_pressure_drop);
  a.laminar_pressure = act.number("laminar_pressure", 1e3, 5e6, a.laminar_pressure);
  if (a.supply_pressure > m.relief_pressure) act.fail("supply_pressure", "must not exceed the machine's relief pressure " + num(m.relief_pressure) + " Pa");

  // Integrator.
  const Section integ = top.sub("integrator");
  integ.only({"method", "formulation", "step", "cycle", "baumgarte_alpha", "baumgarte_beta",
              "implicit_max_iterations", "implicit_tolerance"});
  IntegratorSettings& i = s.integrator;
  i.method = integ.choice<IntegrationMethod>("method",
                                             {{"semi_implicit_euler", IntegrationMethod::semi_implicit_euler},
                                              {"rk4", IntegrationMethod::rk4},
                                              {"implicit_midpoint", IntegrationMethod::implicit_midpoint}},
                                             i.method);
  i.formulation = integ.choice<Formulation>("formulation",
                                            {{"independent", Formulation::independent},
                                             {"augmented_baumgarte", Formulation::augmented_baumgarte},
                                             {"augmented_projection", Formulation::augmented_projection}},
                                            i.formulation);
  s.cycle = integ.number("cycle", 1e-4, 1.0, 1e-3);
  i.step = integ.number("step", 1e-6, 1.0, s.cycle);
  const double ratio = s.cycle / i.step;
  if (i.step > s.cycle * (1 + 1e-9) || std::abs(ratio - std::round(ratio)) > 1e-6 * ratio)
    integ.fail("step", "is " + num(i.step) + " s; must divide integrator.cycle (" + num(s.cycle) +
                           " s) a whole number of times, e.g. " + num(s.cycle) + ", " + num(s.cycle / 2) + ", " +
                           num(s.cycle / 4));
  i.baumgarte_alpha = integ.number("baumgarte_alpha", 0, 1e4, i.baumgarte_alpha);
  i.baumgarte_beta = integ.number("baumgarte_beta", 0, 1e4, i.baumgarte_beta);
  i.implicit_max_iterations = static_cast<int>(integ.number("implicit_max_iterations", 1, 100, i.implicit_max_iterations));
  i.implicit_tolerance = integ.number("implicit_tolerance", 1e-14, 1e-3, i.implicit_tolerance);

  s.duration = top.number("duration", 1e-3, 28800, 10.0, true);  // up to a working shift (8 h)

  // Sensors.
  const Section sens = top.sub("sensors");
  sens.only({"position_quantum", "position_noise", "velocity_noise", "pressure_quantum", "seed", "latency_cycles"});
  SensorParameters& sp = s.sensors;
  sp.position_quantum = sens.vector<4>("position_quantum", Vec4::Zero(), Vec4::Constant(0.1), Vec4::Zero());
  sp.position_noise = sens.vector<4>("position_noise", Vec4::Zero(), Vec4::Constant(0.1), Vec4::Zero());
  sp.velocity_noise = sens.vector<4>("velocity_noise", Vec4::Zero(), Vec4::Constant(1.0), Vec4::Zero());
  sp.pressure_quantum = sens.number("pressure_quantum", 0, 1e7, 0);
  sp.seed = static_cast<std::uint64_t>(sens.number("seed", 0, 4294967295.0, 1));
  if (sens.has("seed") && sens.node()["seed"].as<double>() != std::floor(sens.node()["seed"].as<double>()))
    sens.fail("seed", "must be a whole number in [0, 4294967295]");
  const double lat = sens.number("latency_cycles", 0, SensorParameters::kMaxLatency, 0);
  if (lat != std::floor(lat)) sens.fail("latency_cycles", "must be a whole number in [0, " + std::to_string(SensorParameters::kMaxLatency) + "]");
  sp.latency_cycles = static_cast<int>(lat);

  // Checks.
  const Section chk = top.sub("checks");
  chk.only({"constraint_tolerance", "energy_tolerance", "energy_relative_tolerance", "end_stop_margin"});
  s.checks.constraint_tolerance = chk.number("constraint_tolerance", 1e-12, 1, s.checks.constraint_tolerance);
  s.checks.energy_tolerance = chk.number("energy_tolerance", 0, 1e9, s.checks.energy_tolerance);
  s.checks.energy_relative_tolerance = chk.number("energy_relative_tolerance", 0, 10, s.checks.energy_relative_tolerance);
  s.checks.end_stop_margin = chk.number("end_stop_margin", 0, 1, s.checks.end_stop_margin);

  s.has_controller = static_cast<bool>(root["controller"]);
  s.has_task = static_cast<bool>(root["task"]);
  return s;
}

std::string directory_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? "." : path.substr(0, slash);
}

}  // namespace

Scene load_scene_from_string(const std::string& yaml, const std::string& file_for_errors,
                             const std::string& base_directory) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    throw SceneError(file_for_errors, "", "not valid YAML (line " + std::to_string(e.mark.line + 1) + "): " + e.msg);
  }
  Scene s = parse(root, file_for_errors, base_directory);
  s.text = yaml;
  return s;
}

Scene load_scene(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw SceneError(path, "", "cannot open the file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return load_scene_from_string(buffer.str(), path, directory_of(path));
}

}  // namespace exc::plant
