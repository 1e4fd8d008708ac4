// Loading and validating a machine file (machines/reference-20t.yaml) with the settings reader:
// every field declared once below (type, unit, range, default), errors naming file, line, column,
// field and reason. Start-up code: allocates, throws SettingsError.
#include "model/machine_reader.hpp"

#include <cmath>
#include <initializer_list>
#include <utility>

#include "model/model.hpp"
#include "model/reference_poses.hpp"
#include "settings/section_reader.hpp"

namespace exc {

namespace {

using settings::Bounds;
using settings::format_number;
using settings::Need;
using settings::SectionReader;

constexpr double kMaxCoord = 50.0;  // m: a pin farther than this from its frame is a typo
constexpr Bounds kCoord{-kMaxCoord, kMaxCoord};
constexpr Bounds kEffort{-1e9, 1e9};
constexpr Bounds kSpeed{1e-6, 100.0};
const std::array<const char*, kNumJoints> kBodyNames = {
    "swing", "boom", "boom_barrel", "boom_rod", "arm_barrel", "arm",
    "bucket", "arm_rod", "bucket_barrel", "bucket_rod", "link11", "link12"};
const std::array<const char*, 8> kWorldPins = {"C", "E", "H", "G", "M", "J", "L", "T"};

Vec2 read_pin(SectionReader& section, const char* name) {
  Vec2 p = Vec2::Zero();
  section.numbers(name, p, kCoord, "m", "pin (x, z) in the section's frame", Need::required);
  return p;
}

CylinderLimits read_cylinder(SectionReader& act, const char* name) {
  SectionReader n = act.section(name, "the cylinder's stroke, force and speed limits", Need::required);
  Vec2 len = Vec2::Zero(), f = Vec2::Zero();
  CylinderLimits c;
  n.numbers("length", len, {0.01, kMaxCoord}, "m", "[min, max] pin-to-pin length", Need::required);
  if (!(len[0] < len[1]))
    n.fail("length", "min " + format_number(len[0]) + " must be below max " + format_number(len[1]));
  n.numbers("force", f, kEffort, "N", "[pull, push] force limits", Need::required);
  if (!(f[0] < 0 && f[1] > 0)) n.fail("force", "must be [pull < 0, push > 0] in N");
  n.number("speed", c.max_speed, kSpeed, "m/s", "speed limit", Need::required);
  n.finish();
  c.min_length = len[0];
  c.max_length = len[1];
  c.min_force = f[0];
  c.max_force = f[1];
  return c;
}

void read_body(SectionReader& bodies, const char* name, BodyInertia& b) {
  SectionReader r = bodies.section(name, "the body's mass and inertia", Need::required);
  r.number("mass", b.mass, {1e-3, 1e6}, "kg", "mass", Need::required);
  r.numbers("com", b.com, kCoord, "m", "centre of mass in the body frame", Need::required);
  r.numbers("inertia", b.inertia, {1e-6, 1e8}, "kg m^2", "principal inertia about the com", Need::required);
  // Principal moments of a real body obey the triangle inequality.
  const Vec3& I = b.inertia;
  for (int a = 0; a < 3; ++a) {
    const double others = I[(a + 1) % 3] + I[(a + 2) % 3];
    if (I[a] > others * (1 + 1e-9))
      r.fail("inertia", "principal moment [" + std::to_string(a) + "] = " + format_number(I[a]) +
                            " exceeds the sum of the other two (" + format_number(others) + "): not a physical body");
  }
  r.finish();
}

// One section of pins, each read into its place; the reader is returned for the checks below.
SectionReader read_pin_section(SectionReader& pins, const char* name, std::initializer_list<std::pair<const char*, Vec2*>> named) {
  SectionReader s = pins.section(name, "pins (x, z) in the section's frame", Need::required);
  for (const auto& [pin, at] : named) *at = read_pin(s, pin);
  s.finish();
  return s;
}

void read_pins(SectionReader& root, Machine& m) {
  SectionReader pins = root.section("pins", "the planar pins of each section", Need::required);
  const SectionReader ps = read_pin_section(pins, "swing", {{"C", &m.C}, {"D", &m.D}});
  const SectionReader pb = read_pin_section(pins, "boom", {{"E", &m.E}, {"F", &m.F}, {"H", &m.H}});
  const SectionReader pa = read_pin_section(pins, "arm", {{"G", &m.G}, {"I", &m.I}, {"K", &m.K}, {"M", &m.M}});
  const SectionReader pk = read_pin_section(pins, "bucket", {{"L", &m.L}, {"T", &m.T}});
  SectionReader pl = pins.section("link_lengths", "the bucket linkage's links", Need::required);
  pl.number("JL", m.JL, {0.01, kMaxCoord}, "m", "link 11, J to L", Need::required);
  pl.number("JK", m.JK, {0.01, kMaxCoord}, "m", "link 12, J to K", Need::required);
  pl.finish();
  // The frames fix these: H lies on the boom x axis, M on the arm x axis, L on the bucket x axis.
  if (std::abs(m.H.y()) > 1e-9 || m.H.x() <= 0) pb.fail("H", "must be (x > 0, 0): the boom x axis is C->H");
  if (std::abs(m.M.y()) > 1e-9 || m.M.x() <= 0) pa.fail("M", "must be (x > 0, 0): the arm x axis is H->M");
  if (std::abs(m.L.y()) > 1e-9 || m.L.x() <= 0) pk.fail("L", "must be (x > 0, 0): the bucket x axis is M->L");
  if ((m.C - m.D).norm() < 1e-3) ps.fail("D", "coincides with C");
  if (m.F.norm() < 1e-3) pb.fail("F", "coincides with the boom foot C");
  if ((m.I - m.K).norm() < 1e-3) pa.fail("I", "coincides with K");
  if ((m.K - m.M).norm() < 1e-3) pa.fail("K", "coincides with M");
  pins.finish();
}

void read_actuators(SectionReader& root, Machine& m) {
  SectionReader act = root.section("actuators", "effort, stroke and speed limits", Need::required);
  SectionReader s = act.section("swing", "the swing drive's torque and speed limits", Need::required);
  Vec2 t = Vec2::Zero();
  s.numbers("torque", t, kEffort, "N m", "[min, max] torque", Need::required);
  if (!(t[0] < 0 && t[1] > 0)) s.fail("torque", "must be [min < 0, max > 0] in N m");
  m.swing.min_torque = t[0];
  m.swing.max_torque = t[1];
  s.number("speed", m.swing.max_speed, kSpeed, "rad/s", "speed limit", Need::required);
  s.finish();
  m.boom = read_cylinder(act, "boom");
  m.arm = read_cylinder(act, "arm");
  m.bucket = read_cylinder(act, "bucket");
  act.number("relief_pressure", m.relief_pressure, {1e5, 1e9}, "Pa", "the pressure the effort limits are stated at",
             Need::required);
  act.finish();
}

// The hydraulics section: every field's range, declared once (HydraulicParameters lists the sources).
void read_hydraulics(SectionReader& h, HydraulicParameters& p, double relief_pressure) {
  h.number("valve_time_constant", p.valve_time_constant, {0, 1}, "s", "spool lag of the main valves");
  h.number("bulk_modulus", p.bulk_modulus, {1e7, 5e9}, "Pa", "effective oil bulk modulus (with hoses)");
  h.number("dead_volume", p.dead_volume, {1e-5, 0.1}, "m^3", "oil per cylinder chamber at zero stroke");
  h.number("swing_volume", p.swing_volume, {1e-4, 1}, "m^3", "oil per swing motor side");
  h.number("supply_pressure", p.supply_pressure, {0, 1e8}, "Pa", "the pumps' pressure limit (0: main_relief_pressure)");
  if (p.supply_pressure > relief_pressure)
    h.fail("supply_pressure", "is " + format_number(p.supply_pressure) + " Pa; must not exceed actuators.relief_pressure (" +
                                  format_number(relief_pressure) + " Pa)");
  h.number("tank_pressure", p.tank_pressure, {0, 5e6}, "Pa", "return-line back pressure");
  h.number("valve_pressure_drop", p.valve_pressure_drop, {1e5, 3e7}, "Pa",
           "a fully open meter-out passes the speed-limit flow at this drop");
  h.number("laminar_pressure", p.laminar_pressure, {1e3, 5e6}, "Pa", "orifice flow linear below this drop");
  h.number("pump_flow", p.pump_flow, {1e-4, 0.05}, "m^3/s", "both pumps at rated speed");
  h.flag("pumps_merged", p.pumps_merged, "both pumps feed one gallery");
  std::array<double, 4> pump_of{};
  for (int i = 0; i < 4; ++i) pump_of[i] = p.pump_of[i];
  h.numbers("pump_of", pump_of, {0, 1}, "", "split pumps: the pump (0 or 1) of swing, boom, arm, bucket");
  for (int i = 0; i < 4; ++i) {
    if (pump_of[i] != 0 && pump_of[i] != 1) h.fail("pump_of", i, "is " + format_number(pump_of[i]) + "; allowed values: 0, 1");
    p.pump_of[i] = static_cast<int>(pump_of[i]);
  }
  h.number("load_sensing_margin", p.load_sensing_margin, {0.3e6, 5e6}, "Pa", "pump pressure above the highest load");
  h.number("main_relief_pressure", p.main_relief_pressure, {5e6, 60e6}, "Pa", "main relief");
  h.number("port_relief_pressure", p.port_relief_pressure, {5e6, 60e6}, "Pa", "the cylinders' port reliefs");
  h.number("swing_relief_pressure", p.swing_relief_pressure, {5e6, 60e6}, "Pa", "the swing motor's port reliefs");
  h.number("relief_override", p.relief_override, {1e4, 10e6}, "Pa", "above its setting a relief passes pump_flow");
  h.number("makeup_pressure_drop", p.makeup_pressure_drop, {1e4, 2e6}, "Pa",
           "below tank pressure a make-up valve passes pump_flow");
  h.number("vapour_pressure", p.vapour_pressure, {-0.1e6, 0.1e6}, "Pa", "the floor no chamber goes below");
  // At or above the tank pressure the make-up valves could never open before the floor.
  if (p.vapour_pressure > p.tank_pressure)
    h.fail("vapour_pressure", "is " + format_number(p.vapour_pressure) + " Pa; must not exceed tank_pressure (" +
                                  format_number(p.tank_pressure) + " Pa)");
  h.number("pilot_full_stroke", p.pilot_full_stroke, {1e6, 10e6}, "Pa", "pilot pressure difference for full stroke");
  h.numbers("dead_zone_extend", p.dead_zone_extend, {0, 0.9}, "", "of the spool stroke, swing, boom, arm, bucket");
  h.numbers("dead_zone_retract", p.dead_zone_retract, {0, 0.9}, "", "of the spool stroke, swing, boom, arm, bucket");
  h.numbers("viscous_friction", p.viscous_friction, {0, 1e7}, "",
            "seal friction: N m s/rad (swing), N s/m (cylinders); it damps a held machine's oil columns");
  h.numbers("seal_preload", p.seal_preload, {0, 1e6}, "", "Coulomb friction at zero pressure: N m (swing), N (cylinders)");
  h.numbers("seal_pressure_friction", p.seal_pressure_friction, {0, 1e-2}, "",
            "Coulomb friction per Pa of p_A + p_B: N m/Pa (swing), N/Pa (cylinders)");
  h.number("breakaway_ratio", p.breakaway_ratio, {1, 3}, "", "static over Coulomb friction (the Stribeck peak)");
  h.numbers("stribeck_velocity", p.stribeck_velocity, {1e-4, 1}, "",
            "speed over which the Stribeck peak decays: rad/s (swing), m/s (cylinders)");
  h.number("swing_breakaway_pressure", p.swing_breakaway_pressure, {0, 20e6}, "Pa",
           "the swing motor's breakaway pressure: its static friction over its displacement");
  h.numbers("piston_leakage", p.piston_leakage, {0, 1e-9}, "m^3/(s Pa)",
            "laminar leakage A <-> B across each piston (swing: cross-port)");
  h.numbers("spool_leakage", p.spool_leakage, {0, 1e-9}, "m^3/(s Pa)",
            "laminar leakage from each chamber to tank through its centred spool");
  h.number("swing_drain_leakage", p.swing_drain_leakage, {0, 1e-9}, "m^3/(s Pa)",
           "laminar leakage from each swing-motor port to its case drain");
  h.number("pilot_cutoff_time", p.pilot_cutoff_time, {1e-3, 1}, "s",
           "time constant of the pilot supply after the pilot cut-off (spools spring to centre)");
  h.number("engine_rundown_time", p.engine_rundown_time, {0.05, 10}, "s",
           "after an engine stop the pumps' flow falls linearly to zero over this time");
  h.flag("load_holding_valves", p.load_holding_valves,
         "load-holding valves on the boom's cap and the arm's rod side, closed while the pilot supply is cut");
  h.number("swing_brake_torque", p.swing_brake_torque, {0, 1e7}, "N m",
           "the swing parking brake, applied while the pilot supply is cut or on an emergency stop (0: none)");
  h.number("pump_shutoff_time", p.pump_shutoff_time, {1e-3, 1}, "s",
           "on an emergency stop the pump-line shut-off's flow falls linearly to zero over this time");
  h.number("holding_valve_close_time", p.holding_valve_close_time, {0, 1}, "s",
           "on an emergency stop the load-holding valves close this long after their solenoid drops");
  h.flag("bucket_holding_valve", p.bucket_holding_valve,
         "a holding valve on both bucket ports, closed on an emergency stop (none on the reference machine)");
  h.finish();
}

void read_reference_pose(SectionReader& p, ReferencePose& rp) {
  p.numbers("q_a", rp.q_a, kCoord, "", "[swing rad, L_boom, L_arm, L_bucket m]", Need::required);
  p.number("boom_angle_deg", rp.boom_angle_deg, {-360, 360}, "deg", "C->H above swing x", Need::required);
  p.number("arm_angle_deg", rp.arm_angle_deg, {-360, 360}, "deg", "H->M relative to C->H", Need::required);
  p.number("bucket_angle_deg", rp.bucket_angle_deg, {-360, 360}, "deg", "M->L relative to H->M", Need::required);
  SectionReader pw = p.section("pins_world", "world positions of the named pins");
  for (const char* name : kWorldPins) {
    if (!pw.given(name)) continue;
    Vec3 v = Vec3::Zero();
    pw.numbers(name, v, kCoord, "m", "world position (x, y, z)");
    rp.pins_world.emplace_back(name, v);
  }
  pw.finish();
}

}  // namespace

Machine read_machine(const settings::Document& doc) {
  SectionReader r(doc);
  Machine m;
  m.source = doc.file();
  r.text("name", m.name, "the machine's name", Need::required);
  if (m.name.empty()) r.fail("name", "must be a non-empty string");
  r.number("gravity", m.gravity, {0.1, 100.0}, "m/s^2", "along -z", Need::required);
  SectionReader swing = r.section("swing", "the swing frame", Need::required);
  swing.number("height", m.swing_height, {0.0, kMaxCoord}, "m", "swing frame origin above the ground", Need::required);
  swing.finish();
  r.others({"frames", "assembly"});  // free text for people
  read_pins(r, m);
  SectionReader bodies = r.section("bodies", "mass and inertia of the twelve bodies", Need::required);
  for (int i = 0; i < kNumJoints; ++i) read_body(bodies, kBodyNames[i], m.bodies[i]);
  bodies.finish();
  read_actuators(r, m);
  SectionReader hydraulics = r.section("hydraulics", "the hydraulic machine (docs/plant.md)");
  read_hydraulics(hydraulics, m.hydraulics, m.relief_pressure);
  // Reference poses are optional: a machine without measured poses is still a machine.
  r.sections("reference_poses", 0, 100, "measured poses", [&m](SectionReader& p, std::size_t) {
    ReferencePose rp;
    read_reference_pose(p, rp);
    m.reference_poses.push_back(std::move(rp));
  });
  SectionReader terrain = r.section("terrain", "the site's ground");
  terrain.number("flat_height", m.terrain_flat_height, kCoord, "m", "ground plane z");
  terrain.finish();
  r.finish();
  // The measured poses must be what the geometry assembles: placed at the pose's field.
  if (!m.reference_poses.empty()) {
    const Model model = build_model(m);
    for (std::size_t i = 0; i < m.reference_poses.size(); ++i) {
      if (const auto mismatch = check_reference_pose(model, m.reference_poses[i]))
        r.rethrow_placed(SettingsError(doc.file(), 0, 0, "reference_poses[" + std::to_string(i) + "]." + mismatch->field,
                                       mismatch->reason + ": correct the pose or the geometry, or remove the pose"));
    }
  }
  return m;
}

Machine load_machine_from_string(const std::string& yaml, const std::string& file_for_errors) {
  return read_machine(settings::Document::parse(yaml, file_for_errors));
}

Machine load_machine(const std::string& path) { return read_machine(settings::Document::load(path)); }

void validate_hydraulics(const Machine& machine) {
  // The same declarations over no file: every value is checked as a default is.
  SectionReader h(machine.source, "hydraulics", YAML::Node());
  HydraulicParameters copy = machine.hydraulics;
  read_hydraulics(h, copy, machine.relief_pressure);
}

}  // namespace exc
