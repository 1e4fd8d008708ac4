#pragma once
// The machine description (pins, bodies, limits, hydraulics) as read from a machine file such as
// machines/reference-20t.yaml by machine_reader.hpp (which validates every field). The structs and
// what the cycle asks of them; nothing here reads a file, so the firmware's image compiles it. Each
// struct's visit_fields lists the fields the settings blob carries (app/settings_blob.hpp).
#include <array>
#include <string>
#include <vector>

#include "types.hpp"

namespace exc {

struct BodyInertia {
  double mass = 0;             // kg
  Vec3 com = Vec3::Zero();     // centre of mass in the body frame (m)
  Vec3 inertia = Vec3::Zero(); // principal inertia about the com, body axes [Ixx Iyy Izz] (kg m^2)
};
// The settings blob's field list (app/settings_blob.hpp): a field added above is added here too.
template <typename Visitor>
void visit_fields(Visitor& v, BodyInertia& b) {
  v("mass", b.mass);
  v("com", b.com);
  v("inertia", b.inertia);
}

struct CylinderLimits {
  double min_length = 0, max_length = 0;  // pin to pin (m)
  double min_force = 0, max_force = 0;    // N (negative = pull)
  double max_speed = 0;                   // m/s
};
template <typename Visitor>
void visit_fields(Visitor& v, CylinderLimits& c) {
  v("min_length", c.min_length);
  v("max_length", c.max_length);
  v("min_force", c.min_force);
  v("max_force", c.max_force);
  v("max_speed", c.max_speed);
}

struct SwingLimits {
  double min_torque = 0, max_torque = 0;  // N m
  double max_speed = 0;                   // rad/s
};
template <typename Visitor>
void visit_fields(Visitor& v, SwingLimits& s) {
  v("min_torque", s.min_torque);
  v("max_torque", s.max_torque);
  v("max_speed", s.max_speed);
}

struct ReferencePose {
  Vec4 q_a = Vec4::Zero();
  double boom_angle_deg = 0, arm_angle_deg = 0, bucket_angle_deg = 0;
  // World positions of the named pins (C, E, H, G, M, J, L, T), in this order when present.
  std::vector<std::pair<std::string, Vec3>> pins_world;
};

// The machine's hydraulics (docs/plant.md, "The hydraulic machine"; the machine file's
// `hydraulics:` section, optional: a file without it gets these defaults). The plant runs the
// circuit with its true machine's numbers; the firmware reads its nominal machine's (for a valve
// loop). Plain numbers: unit, source and allowed range with each; the ranges are declared once, by
// the reader in machine_reader.cpp, which also checks a struct built in C++ (validate_hydraulics).
struct HydraulicParameters {
  // s, spool lag of the pilot-operated main valves (mobile valves: 30-100 ms). Range [0, 1].
  double valve_time_constant = 0.03;
  // Pa, effective bulk modulus of the oil with its hoses. Range [1e7, 5e9].
  double bulk_modulus = 1.0e9;
  // m^3, oil in each cylinder chamber's lines at full retraction. Range [1e-5, 0.1].
  double dead_volume = 0.002;
  // m^3, oil on each side of the swing motor. Range [1e-4, 1].
  double swing_volume = 0.01;
  // Pa, the pumps' pressure limit; 0: main_relief_pressure. Range [0, 1e8], at most the
  // actuators' relief_pressure.
  double supply_pressure = 0;
  // Pa: what the pumps deliver at most (supply_pressure, or the main relief when it is 0).
  double pump_pressure_limit() const { return supply_pressure > 0 ? supply_pressure : main_relief_pressure; }
  // Pa, return-line back pressure (the make-up valves draw from it). Range [0, 5e6].
  double tank_pressure = 0.3e6;
  // Pa: a fully open meter-out passes the speed-limit flow at this drop. Range [1e5, 3e7].
  double valve_pressure_drop = 5e6;
  // Pa: below this drop the orifice flow is linear in dp. Range [1e3, 5e6].
  double laminar_pressure = 0.2e6;
  // m^3/s, both pumps together at rated speed: 2 x 112 cm^3/rev, 439 L/min (Komatsu PC200-8,
  // hydraulics.md). Range [1e-4, 0.05].
  double pump_flow = 439.0 / 60000.0;
  // true: both pumps feed one gallery (the PC200-8's CLSS joins them in normal work); false: each
  // pump feeds its own functions (pump_of) with half the flow.
  bool pumps_merged = true;
  // With split pumps, the pump (0 or 1) of swing, boom, arm, bucket (estimate: the usual two-pump
  // layout, boom and bucket on one, swing and arm on the other).
  std::array<int, 4> pump_of = {1, 0, 1, 0};
  // Pa, pump pressure above the highest load (the load-sensing differential; estimate, typical
  // 1.5-3 MPa, not on the spec page). The meter-in orifices are sized to pass the speed-limit flow
  // at this drop. Range [0.3e6, 5e6].
  double load_sensing_margin = 2.0e6;
  // Pa, main relief: the pumps' pressure limit (34.3 MPa, Cat 320C service data, hydraulics.md).
  // supply_pressure, when set (> 0), takes its place. Range [5e6, 60e6].
  double main_relief_pressure = 34.3e6;
  // Pa, port reliefs on the boom, arm and bucket chambers (36.8 MPa, Cat 320C, hydraulics.md).
  // Range [5e6, 60e6].
  double port_relief_pressure = 36.8e6;
  // Pa, the swing motor's port reliefs (estimate: the spec page gives none; 34.3 MPa is the pressure
  // at which the machine file's 65 kN m swing torque is stated). Range [5e6, 60e6].
  double swing_relief_pressure = 34.3e6;
  // Pa above its setting at which a relief passes pump_flow (linear override; estimate).
  // Range [1e4, 10e6].
  double relief_override = 1.5e6;
  // Pa below tank pressure at which a make-up (anti-cavitation) valve passes pump_flow (estimate).
  // Range [1e4, 2e6].
  double makeup_pressure_drop = 0.2e6;
  // Pa (gauge, like every pressure of the plant): the floor no chamber goes below; below it the
  // oil would release air and vapour (hydraulics.md: never below zero or vapour pressure).
  // Range [-0.1e6, 0.1e6], and at most tank_pressure.
  double vapour_pressure = 0.0;
  // Pa, pilot pressure difference for full spool stroke (0-5 MPa pilots, the ZX200's 0.02 MPa/bit
  // commands, hydraulics.md). Range [1e6, 10e6].
  double pilot_full_stroke = 5.0e6;
  // Fraction of the spool stroke before the metering notch opens, per function (swing, boom, arm,
  // bucket) and direction (estimate: ~0.75 MPa of a 5 MPa pilot; hydraulics.md: calibrated per
  // machine and direction). Range [0, 0.9].
  Vec4 dead_zone_extend = Vec4::Constant(0.15);
  Vec4 dead_zone_retract = Vec4::Constant(0.15);
  // Viscous friction of the cylinders' seals and the swing's drive (N s/m; swing N m s/rad): what
  // damps a held machine's oil columns (estimate: 2-3 % of their critical damping at the dig pose,
  // where they ring at 0.4, 3, 7.5 and 23 Hz; a few kN at working speeds, well under the Coulomb
  // friction of real seals, the Coulomb terms below). Range [0, 1e7].
  Vec4 viscous_friction = (Vec4() << 2e4, 1e5, 3e4, 1e4).finished();

  // Coulomb friction with a Stribeck peak (model/actuator_friction.hpp), per function:
  //   F = Fc (1 + (breakaway_ratio - 1) exp(-|v| / stribeck_velocity)) sign(v) + viscous_friction v,
  //   Fc = seal_preload + seal_pressure_friction (p_A + p_B)  (+ the swing's breakaway, below).
  // Seal preload, N (cylinders; the swing N m): 20 N per cylinder (hydraulics.md's published
  // excavator model), the boom's two cylinders 40 N; the swing's friction is its breakaway pressure's.
  // Range [0, 1e6].
  Vec4 seal_preload = (Vec4() << 0, 40, 20, 20).finished();
  // N/Pa (swing N m/Pa): seal friction growing with the chamber pressures, 1e-4 N/Pa per cylinder
  // (hydraulics.md: about 3.4 kN at p_A + p_B = 34 MPa), the boom's pair 2e-4. Range [0, 1e-2].
  Vec4 seal_pressure_friction = (Vec4() << 0, 2e-4, 1e-4, 1e-4).finished();
  // Static over Coulomb friction, Kbrk (1.2, hydraulics.md). Range [1, 3].
  double breakaway_ratio = 1.2;
  // m/s (swing rad/s): the Stribeck velocity over which the breakaway peak decays to Fc (0.01 m/s,
  // hydraulics.md; the swing's 0.01 rad/s an estimate). Range [1e-4, 1].
  Vec4 stribeck_velocity = Vec4::Constant(0.01);
  // Pa: the swing motor's breakaway pressure (3.2-3.8 MPa on 20-36 t machines, field tests,
  // hydraulics.md): the swing's static friction torque is this times its displacement D.
  // Range [0, 20e6].
  double swing_breakaway_pressure = 3.5e6;

  // Internal leakage, laminar, m^3/(s Pa), per function (swing, boom, arm, bucket):
  // A <-> B across each piston (the swing motor: cross-port), 1e-16 per piston seal of a new machine
  // (hydraulics.md: 1e-16 to 1e-14 from new to worn; the boom's two pistons 2e-16); the swing's from
  // its volumetric efficiency (docs/plant.md, "Friction and leakage"). Range [0, 1e-9].
  Vec4 piston_leakage = (Vec4() << 1.9e-12, 2e-16, 1e-16, 1e-16).finished();
  // Each chamber to tank through its centred spool's clearance: chosen so that a held boom with a
  // 1050 kg bucket load and no firmware creeps 2 mm/min, the new-machine drift of safety.md (derived in
  // docs/plant.md). Range [0, 1e-9].
  Vec4 spool_leakage = Vec4::Constant(5.0e-14);
  // Each swing-motor port to the motor's case drain (tank), m^3/(s Pa) (docs/plant.md: with the
  // cross-port leakage, a volumetric efficiency of 95 % at 34.3 MPa and full swing speed). Range [0, 1e-9].
  double swing_drain_leakage = 1.9e-12;

  // The machine's safety hardware (safety.md, "The machine's safety hardware"; docs/safety.md).
  // s, time constant of the pilot supply once the pilot cut-off (gate-lock) solenoid drops: the
  // solenoid's switching and the pilot line's bleed-down (safety.md: tens of ms; no figure found,
  // stated). The spools' targets scale with the supply, so they spring to centre. Range [1e-3, 1].
  double pilot_cutoff_time = 0.05;
  // s, the engine's run-down after an engine stop: the pumps' flow falls linearly to zero over it
  // (safety.md: not found; a diesel from rated speed stops in about a second). Range [0.05, 10].
  double engine_rundown_time = 1.0;
  // Load-holding (hose-burst) valves on the boom's cap side and the arm's rod side (ISO 8643;
  // safety.md: on those sides of 20 t machines). Modelled as closed, blocking every outflow of their
  // chamber (meter-out and spool leakage), while the pilot supply is cut (below half): with the
  // supply on, the calibrated spool leakage stands for the drift past them (the drift test lumps it).
  bool load_holding_valves = true;
  // N m at the swing axis: the swing parking brake, spring-applied and released by the pilot
  // supply, so applied while the supply is below half (safety.md: applied some seconds after the
  // levers return to neutral in normal work; on a pilot cut at once). No figure found: stated as the
  // swing motor's own torque (machine file's swing.max_torque, 65 kN m), a brake that holds what the
  // motor can drive. 0: none. Range [0, 1e7].
  double swing_brake_torque = 65e3;
  // The emergency stop's own safety solenoids (safety.md, "Stopping a stuck spool"), de-energised to
  // stop by the machine's safety controller on FW_EMERGENCY, whatever the main spools do:
  // s, the pump-line shut-off with load-sensing unloading: the pumps' delivered flow falls linearly to
  // zero over it (estimate: 50-150 ms for unloading and de-stroke, no datasheet figure found; 50 ms
  // nominal). The engine stop stays beside it. Range [1e-3, 1].
  double pump_shutoff_time = 0.05;
  // s, the load-holding valves' closing once their solenoid drops (estimate: a solenoid-piloted
  // poppet, tens of ms). They also close while the pilot supply is cut, as before. Range [0, 1].
  double holding_valve_close_time = 0.05;
  // A double pilot-operated check valve on both bucket ports, on the same solenoid (no source puts
  // one on a 20 t machine's bucket: off on the reference machine).
  bool bucket_holding_valve = false;
};
// The settings blob's field list (app/settings_blob.hpp): what the firmware's cycle reads (valve
// stage, friction model, pump pacing, pressure monitor). Left out, the plant's alone: piston_leakage,
// spool_leakage, swing_drain_leakage, pilot_cutoff_time, engine_rundown_time, load_holding_valves,
// swing_brake_torque, pump_shutoff_time, holding_valve_close_time, bucket_holding_valve. A field the firmware comes to read is added here (the blob's round-trip test,
// tests/firmware_control/test_settings_blob_runs.cpp, runs with the left-out ones poisoned).
template <typename Visitor>
void visit_fields(Visitor& v, HydraulicParameters& p) {
  v("valve_time_constant", p.valve_time_constant);
  v("bulk_modulus", p.bulk_modulus);
  v("dead_volume", p.dead_volume);
  v("swing_volume", p.swing_volume);
  v("supply_pressure", p.supply_pressure);
  v("tank_pressure", p.tank_pressure);
  v("valve_pressure_drop", p.valve_pressure_drop);
  v("laminar_pressure", p.laminar_pressure);
  v("pump_flow", p.pump_flow);
  v("pumps_merged", p.pumps_merged);
  v("pump_of", p.pump_of);
  v("load_sensing_margin", p.load_sensing_margin);
  v("main_relief_pressure", p.main_relief_pressure);
  v("port_relief_pressure", p.port_relief_pressure);
  v("swing_relief_pressure", p.swing_relief_pressure);
  v("relief_override", p.relief_override);
  v("makeup_pressure_drop", p.makeup_pressure_drop);
  v("vapour_pressure", p.vapour_pressure);
  v("pilot_full_stroke", p.pilot_full_stroke);
  v("dead_zone_extend", p.dead_zone_extend);
  v("dead_zone_retract", p.dead_zone_retract);
  v("viscous_friction", p.viscous_friction);
  v("seal_preload", p.seal_preload);
  v("seal_pressure_friction", p.seal_pressure_friction);
  v("breakaway_ratio", p.breakaway_ratio);
  v("stribeck_velocity", p.stribeck_velocity);
  v("swing_breakaway_pressure", p.swing_breakaway_pressure);
}

struct Machine {
  std::string name;
  std::string source;    // file the machine was loaded from ("<embedded>" for the built-in one)
  double gravity = 9.81; // m/s^2, along -z
  double swing_height = 0;

  // Planar pins (x, z) in the frame of their section (see the machine file's 'frames').
  Vec2 C, D;        // swing frame
  Vec2 E, F, H;     // boom frame
  Vec2 G, I, K, M;  // arm frame
  Vec2 L, T;        // bucket frame (T: tip)
  double JL = 0, JK = 0;  // link lengths

  std::array<BodyInertia, kNumJoints> bodies;  // indexed by JointIndex

  SwingLimits swing;
  CylinderLimits boom, arm, bucket;
  double relief_pressure = 0;  // Pa
  HydraulicParameters hydraulics;

  std::vector<ReferencePose> reference_poses;
  double terrain_flat_height = 0;

  // Limits of the active coordinates, q_a order: swing (+-inf if unlimited), then cylinder lengths.
  Vec4 q_min() const;
  Vec4 q_max() const;
  Vec4 effort_min() const;
  Vec4 effort_max() const;
  Vec4 speed_max() const;
};
// The settings blob's field list (app/settings_blob.hpp): everything build_model and the cycle read.
// Left out: name and source (the run is named by its scene), reference_poses (checked against the
// geometry when the file is read) and terrain_flat_height (the scene's terrain carries the ground).
template <typename Visitor>
void visit_fields(Visitor& v, Machine& m) {
  v("gravity", m.gravity);
  v("swing_height", m.swing_height);
  v("C", m.C);
  v("D", m.D);
  v("E", m.E);
  v("F", m.F);
  v("H", m.H);
  v("G", m.G);
  v("I", m.I);
  v("K", m.K);
  v("M", m.M);
  v("L", m.L);
  v("T", m.T);
  v("JL", m.JL);
  v("JK", m.JK);
  v("bodies", m.bodies);
  v("swing", m.swing);
  v("boom", m.boom);
  v("arm", m.arm);
  v("bucket", m.bucket);
  v("relief_pressure", m.relief_pressure);
  v("hydraulics", m.hydraulics);
}

// The hydraulics without dry friction and internal leakage, viscous friction kept: the machine as it
// was modelled before them, for comparisons (the fidelity chart) and for tests of one element.
HydraulicParameters without_dry_friction_and_leakage(HydraulicParameters p);

}  // namespace exc
