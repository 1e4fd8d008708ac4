#include "sweep_knobs.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "settings/section_reader.hpp"

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
      {"model_mass", nullptr, {-0.9, 9}, "", "the firmware's link masses and inertias x (1 + value)", scale_model_masses},
      {"soil_stiffness", nullptr, {0.01, 100}, "", "the plant's soil K x value", scale_soil_stiffness},
      {"position_noise", "sensors.position_noise"},
      {"velocity_noise", "sensors.velocity_noise"},
      {"delay_cycles", "sensors.latency_cycles"},
      {"gain_scale", nullptr, {0.01, 100}, "",
       "the outer law's omega_n x value (kp x s^2, kv x s, ki x s^3, Slotine-Li's lambda and kd x s)", scale_gains},
      {"adaptation_scale", nullptr, {1e-6, 1e6}, "", "adaptation rates x value", scale_adaptation},
  };
  static const std::vector<Knob> open = {
      {"integrator", nullptr, {0, 0}, "", "method/formulation, e.g. rk4/augmented_baumgarte", set_integrator, true},
      {"integrator.step", nullptr, {1e-6, 1e-2}, "s", "the plant's step (its cycle: the step above 1 ms, else 1 ms)",
       set_open_loop_step},
      {"soil.stiffness", nullptr, {1, 1e9}, "N/m", "the soil's K_t, its damping ratio kept", set_soil_stiffness},
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
    throw std::invalid_argument("is no knob: neither a named one (" + names + ") nor a number's or a name's path in " +
                                scene.scene.file() + " (e.g. sensors.latency_cycles) or its machine file (machine.<path>: the "
                                "plant's, firmware.machine.<path>: the firmware's model)");
  }
  Declaration values = *d;
  values.field = path;
  return values;
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
