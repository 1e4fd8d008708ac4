#include "sweep_knobs.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "model/terrain.hpp"
#include "settings/section_reader.hpp"
#include "sim_plant/soil.hpp"

namespace exc::sim {
namespace {

using settings::Declaration;
using settings::format_number;

YAML::Node numbers(const Vec2& v) {
  YAML::Node list(YAML::NodeType::Sequence);
  list.SetStyle(YAML::EmitterStyle::Flow);
  for (const double x : v) list.push_back(format_number(x));
  return list;
}

// The soil written out (a preset's numbers too): what the soil knobs change.
void set_soil(SceneChanges& c, const Vec2& stiffness, const Vec2& damping, const Vec2& mass) {
  YAML::Node soil(YAML::NodeType::Map);
  soil["stiffness"] = numbers(stiffness);
  soil["damping"] = numbers(damping);
  soil["mass"] = numbers(mass);
  c.set("soil", soil);
}

// The firmware's model: every body's mass and inertia x (1 + value); the plant keeps the true machine.
void scale_model_masses(SceneChanges& c, const SweepValue& v) {
  for (const auto& body : c.nominal("firmware.machine.bodies")) {
    const std::string path = "firmware.machine.bodies." + body.first.Scalar();
    c.set(path + ".mass", scaled(body.second["mass"], 1 + v.number));
    c.set(path + ".inertia", scaled(body.second["inertia"], 1 + v.number));
  }
}

// Soil between the presets: loose sand (0) to stiff clay (1), K, B and the added mass each
// interpolated geometrically (log-linear), since the presets span a factor of ten in K; the middle
// (K 63 kN/m, B 4.7 kN s/m) lies within 10 % of loam's (70 kN/m, 5 kN s/m).
void blend_soil(SceneChanges& c, const SweepValue& v) {
  const plant::SoilParameters a = plant::soil_preset(plant::SoilPreset::loose_sand);
  const plant::SoilParameters b = plant::soil_preset(plant::SoilPreset::stiff_clay);
  const auto between = [&v](const Vec2& x, const Vec2& y) -> Vec2 {
    return Vec2(std::pow(x.x(), 1 - v.number) * std::pow(y.x(), v.number), std::pow(x.y(), 1 - v.number) * std::pow(y.y(), v.number));
  };
  set_soil(c, between(a.stiffness, b.stiffness), between(a.damping, b.damping), between(a.mass, b.mass));
}

double number_at(const YAML::Node& map, const char* key) { return map[key].as<double>(); }

// The ground tilted by `value` degrees (rising away from the machine when positive): a straight
// terrain.profile through the nominal ground at the dig's working area (the mean x of the path's
// poses at or below the nominal ground + 0.1 m), from x = 0 to twice that x; the firmware reads the
// same profile as its site map. The path follows the ground: every pose but the first moves up by the
// ground's rise at its x, so the pass digs as deep as on the nominal ground; the first (the approach,
// in the air) stays, as the scene's initial state is its inverse kinematics.
void tilt_terrain(SceneChanges& c, const SweepValue& v) {
  const Terrain& ground = c.source().nominal.firmware.terrain;
  if (!c.nominal("task")["path"])
    throw std::invalid_argument("needs a task path (task.type dig or truck_loading) to tilt the ground under; " +
                                c.source().scene.file() + " has none");
  const YAML::Node nominal_path = c.nominal("task.path");
  double sum = 0;
  int n = 0;
  for (const YAML::Node& pose : nominal_path) {
    const double x = number_at(pose, "x");
    if (number_at(pose, "z") <= ground.height_at(x) + 0.1) sum += x, ++n;
  }
  if (n == 0) throw std::invalid_argument("needs a task path that reaches the ground (task.path: no pose at or below the terrain)");
  const double pivot = sum / n, h = ground.height_at(pivot);
  const double rise = std::tan(v.number * 3.14159265358979323846 / 180);
  YAML::Node terrain(YAML::NodeType::Map);
  YAML::Node profile(YAML::NodeType::Sequence);
  profile.SetStyle(YAML::EmitterStyle::Flow);
  profile.push_back(numbers(Vec2(0, h - rise * pivot)));
  profile.push_back(numbers(Vec2(2 * pivot, h + rise * pivot)));
  terrain["profile"] = profile;
  c.set("terrain", terrain);
  YAML::Node path = c.current("task.path");
  for (std::size_t i = 1; i < path.size(); ++i)
    path[i]["z"] = format_number(number_at(path[i], "z") + rise * (number_at(path[i], "x") - pivot));
  c.set("task.path", path);
}

// The task run `value` times faster: every time of the task (its path's or waypoints' t, the return
// move, the truck cycle's move times) and the run's duration / value. The effort check before the
// run then checks the faster path as it checks the file's.
void scale_path_speed(SceneChanges& c, const SweepValue& v) {
  const YAML::Node task = c.nominal("task");
  for (const char* key : {"path", "waypoints"}) {
    if (!task[key]) continue;
    const std::string list = std::string("task.") + key;
    YAML::Node poses = c.current(list);
    const double t0 = number_at(poses[0], "t");
    for (YAML::Node pose : poses) pose["t"] = format_number(t0 + (number_at(pose, "t") - t0) / v.number);
    c.set(list, poses);
  }
  if (task["return_time"]) c.set("task.return_time", scaled(c.current("task.return_time"), 1 / v.number));
  for (const char* move : {"to_dump", "dump", "back"})
    if (task["times"] && task["times"][move]) {
      const std::string t = std::string("task.times.") + move;
      c.set(t, scaled(c.current(t), 1 / v.number));
    }
  c.set("duration", scaled(c.current("duration"), 1 / v.number));
}

void scale_soil_stiffness(SceneChanges& c, const SweepValue& v) {
  const plant::SoilParameters& s = c.source().nominal.scene.soil;
  set_soil(c, s.stiffness * v.number, s.damping, s.mass);
}

// omega_n of the outer law's error dynamics x value.
void scale_gains(SceneChanges& c, const SweepValue& v) {
  const double s = v.number;
  for (const auto& [setting, factor] : {std::pair<const char*, double>{"controller.kp", s * s},
                                        {"controller.kv", s},
                                        {"controller.ki", s * s * s},
                                        {"controller.slotine_li.lambda", s},
                                        {"controller.slotine_li.kd", s}})
    c.set(setting, scaled(c.nominal(setting), factor));
}

void scale_adaptation(SceneChanges& c, const SweepValue& v) {
  for (const char* setting : {"controller.adaptation_rate", "controller.slotine_li.adaptation_rate"})
    c.set(setting, scaled(c.nominal(setting), v.number));
}

void set_integrator(SceneChanges& c, const SweepValue& v) {
  const std::size_t slash = v.name.find('/');
  if (slash == std::string::npos)
    throw std::invalid_argument("is '" + v.name + "'; must be method/formulation, e.g. rk4/augmented_baumgarte");
  c.set("integrator.method", YAML::Node(v.name.substr(0, slash)));
  c.set("integrator.formulation", YAML::Node(v.name.substr(slash + 1)));
}

void set_open_loop_step(SceneChanges& c, const SweepValue& v) {
  c.set("integrator.step", YAML::Node(format_number(v.number)));
  c.set("integrator.cycle", YAML::Node(format_number(open_loop_cycle(v.number))));
}

// The soil's K_t on both axes, its damping ratio kept (B x sqrt of K's factor).
void set_soil_stiffness(SceneChanges& c, const SweepValue& v) {
  const plant::SoilParameters& s = c.source().nominal.scene.soil;
  const double scale = v.number / (s.stiffness.x() > 0 ? s.stiffness.x() : 7e4);
  set_soil(c, s.stiffness * scale, s.damping * std::sqrt(scale), s.mass);
}

const Knob* named(SweepRun run, const std::string& name) {
  const std::vector<Knob>& knobs = named_knobs(run);
  const auto it = std::find_if(knobs.begin(), knobs.end(), [&name](const Knob& k) { return name == k.name; });
  return it == knobs.end() ? nullptr : &*it;
}

}  // namespace

double open_loop_cycle(double step) { return std::max(step, 1e-3); }

const std::vector<Knob>& named_knobs(SweepRun run) {
  static const std::vector<Knob> closed = {
      {"model_mass", nullptr, {-0.9, 9}, "", "the firmware's link masses and inertias x (1 + value)", scale_model_masses, false,
       "firmware.machine.bodies"},
      {"soil_stiffness", nullptr, {0.01, 100}, "", "the plant's soil K x value", scale_soil_stiffness, false, "soil"},
      {"soil_blend", nullptr, {0, 1}, "", "the plant's soil from loose sand (0) to stiff clay (1), K, B and mass log-linear",
       blend_soil, false, "soil"},
      {"terrain_slope", nullptr, {-45, 45}, "deg",
       "the ground tilted through the dig's working area (terrain.profile), the path's poses after the first moved with it",
       tilt_terrain, false, "terrain"},
      {"path_speed", nullptr, {0.1, 10}, "", "the task's times and the run's duration / value", scale_path_speed},
      {"position_noise", "sensors.position_noise"},
      {"velocity_noise", "sensors.velocity_noise"},
      {"pressure_noise", "sensors.pressure_noise"},
      {"delay_cycles", "sensors.latency_cycles"},
      {"gain_scale", nullptr, {0.01, 100}, "",
       "the outer law's omega_n x value (kp x s^2, kv x s, ki x s^3, Slotine-Li's lambda and kd x s)", scale_gains, false,
       "controller.kp controller.kv controller.ki controller.slotine_li.lambda controller.slotine_li.kd"},
      {"adaptation_scale", nullptr, {1e-6, 1e6}, "", "adaptation rates x value", scale_adaptation, false,
       "controller.adaptation_rate controller.slotine_li.adaptation_rate"},
  };
  static const std::vector<Knob> open = {
      {"integrator", nullptr, {0, 0}, "", "method/formulation, e.g. rk4/augmented_baumgarte", set_integrator, true,
       "integrator.method integrator.formulation"},
      {"integrator.step", nullptr, {1e-6, 1e-2}, "s", "the plant's step (its cycle: the step above 1 ms, else 1 ms)",
       set_open_loop_step, false, "integrator.step integrator.cycle"},
      {"soil.stiffness", nullptr, {1, 1e9}, "N/m", "the soil's K_t, its damping ratio kept", set_soil_stiffness, false, "soil"},
      {"profile.speed", nullptr, {0.1, 10}, "", "the effort profile's task run this many times faster"},
  };
  return run == SweepRun::open_loop ? open : closed;
}

Declaration knob_values(SweepRun run, const std::string& knob, const SceneSource& scene) {
  const Knob* k = named(run, knob);
  if (k != nullptr && k->setting == nullptr) {
    Declaration d;
    d.field = knob;
    d.type = k->names ? Declaration::Type::choice : Declaration::Type::number;
    if (!k->names) d.bounds = {k->range};
    d.unit = k->unit;
    d.what = k->what;
    return d;
  }
  const std::string path = k != nullptr ? k->setting : knob;
  const Declaration* d = path.find('[') == std::string::npos ? scene.declaration(path) : nullptr;
  if (d == nullptr) {
    std::string names;
    for (const Knob& n : named_knobs(run)) names += (names.empty() ? "" : ", ") + std::string(n.name);
    throw std::invalid_argument("is no knob: neither a named one (" + names + ") nor a number's, a name's or a flag's path in " +
                                scene.scene.file() + " (e.g. sensors.latency_cycles) or its machine file (machine.<path>: the "
                                "plant's, firmware.machine.<path>: the firmware's model)");
  }
  Declaration values = *d;
  values.field = path;
  return values;
}

std::vector<std::string> knob_writes(SweepRun run, const std::string& knob) {
  const Knob* k = named(run, knob);
  if (k == nullptr) return {knob};
  if (k->setting != nullptr) return {k->setting};
  std::vector<std::string> paths;
  const std::string all = k->writes;
  for (std::size_t start = 0; start < all.size();) {
    const std::size_t end = std::min(all.find(' ', start), all.size());
    if (end > start) paths.push_back(all.substr(start, end - start));
    start = end + 1;
  }
  return paths;
}

void set_knob(SweepRun run, const std::string& knob, const SweepValue& value, SceneChanges& changes) {
  const Knob* k = named(run, knob);
  if (k != nullptr && k->setting == nullptr) {
    if (k->apply != nullptr) k->apply(changes, value);
    return;
  }
  const std::string path = k != nullptr ? k->setting : knob;
  const Declaration& d = knob_values(run, knob, changes.source());
  YAML::Node node;
  if (value.type == SweepValue::Type::name) {
    node = YAML::Node(value.name);
  } else if (value.type == SweepValue::Type::number && d.type != Declaration::Type::numbers) {
    node = YAML::Node(format_number(value.number));
  } else {
    // A list, or one number for every element of a setting that takes a list.
    const int n = d.count;
    if (value.type == SweepValue::Type::list && static_cast<int>(value.list.size()) != n)
      throw std::invalid_argument(path + " takes " + std::to_string(n) + " numbers in " + changes.source().scene.file());
    node = YAML::Node(YAML::NodeType::Sequence);
    node.SetStyle(YAML::EmitterStyle::Flow);
    for (int i = 0; i < n; ++i)
      node.push_back(format_number(value.type == SweepValue::Type::list ? value.list[static_cast<std::size_t>(i)] : value.number));
  }
  changes.set(path, node);
}

}  // namespace exc::sim
