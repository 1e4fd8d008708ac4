// Loading and validating a machine file (machines/reference-20t.yaml). Start-up code: allocates and
// throws MachineError naming the file, the field and the reason.
#include "machine.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

namespace exc {

namespace {

std::string format_what(const std::string& file, const std::string& field, const std::string& reason) {
  return file + ": " + (field.empty() ? std::string("(file)") : field) + ": " + reason;
}

std::string num(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

// Reads fields of one YAML document, each by its dotted path, with the checks the model needs.
class MachineFileReader {
 public:
  MachineFileReader(const YAML::Node& root, std::string file) : root_(root), file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& field, const std::string& reason) const {
    throw MachineError(file_, field, reason);
  }

  YAML::Node map(const YAML::Node& parent, const std::string& key, const std::string& path) const {
    const YAML::Node n = parent[key];
    if (!n) fail(path, "missing (a mapping is required)");
    if (!n.IsMap()) fail(path, "must be a mapping");
    return n;
  }

  // Rejects keys the format does not define, so a misspelt field is an error, not a silent default.
  void only_keys(const YAML::Node& n, const std::string& path, const std::set<std::string>& allowed) const {
    for (const auto& kv : n) {
      const std::string k = kv.first.as<std::string>();
      if (!allowed.count(k)) {
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        fail(path.empty() ? k : path + "." + k, "unknown field (allowed: " + list + ")");
      }
    }
  }

  double number(const YAML::Node& n, const std::string& path, double lo, double hi) const {
    if (!n) fail(path, "missing (a number in [" + num(lo) + ", " + num(hi) + "] is required)");
    if (!n.IsScalar()) fail(path, "must be a number");
    double x = 0;
    try {
      x = n.as<double>();
    } catch (const YAML::Exception&) {
      fail(path, "'" + n.Scalar() + "' is not a number");
    }
    if (!std::isfinite(x)) fail(path, "must be finite");
    if (x < lo || x > hi) fail(path, num(x) + " is outside the allowed range [" + num(lo) + ", " + num(hi) + "]");
    return x;
  }

  double number(const YAML::Node& parent, const std::string& key, const std::string& path, double lo,
                double hi) const {
    return number(parent[key], path, lo, hi);
  }

  template <int N>
  Eigen::Matrix<double, N, 1> vec(const YAML::Node& n, const std::string& path, double lo, double hi) const {
    if (!n) fail(path, "missing (a list of " + std::to_string(N) + " numbers is required)");
    if (!n.IsSequence() || n.size() != static_cast<std::size_t>(N))
      fail(path, "must be a list of " + std::to_string(N) + " numbers");
    Eigen::Matrix<double, N, 1> v;
    for (int i = 0; i < N; ++i) v[i] = number(n[i], path + "[" + std::to_string(i) + "]", lo, hi);
    return v;
  }

  std::string text(const YAML::Node& n, const std::string& path) const {
    if (!n) fail(path, "missing (a string is required)");
    if (!n.IsScalar() || n.Scalar().empty()) fail(path, "must be a non-empty string");
    return n.Scalar();
  }

  const YAML::Node& root() const { return root_; }

 private:
  YAML::Node root_;
  std::string file_;
};

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMaxCoord = 50.0;  // m: a pin farther than this from its frame is a typo
const std::array<const char*, kNumJoints> kBodyNames = {
    "swing", "boom", "boom_barrel", "boom_rod", "arm_barrel", "arm",
    "bucket", "arm_rod", "bucket_barrel", "bucket_rod", "link11", "link12"};

CylinderLimits read_cylinder(const MachineFileReader& r, const YAML::Node& act, const std::string& name) {
  const std::string path = "actuators." + name;
  const YAML::Node n = r.map(act, name, path);
  r.only_keys(n, path, {"length", "force", "speed"});
  CylinderLimits c;
  const Vec2 len = r.vec<2>(n["length"], path + ".length", 0.01, kMaxCoord);
  if (!(len[0] < len[1])) r.fail(path + ".length", "min " + num(len[0]) + " must be below max " + num(len[1]));
  const Vec2 f = r.vec<2>(n["force"], path + ".force", -1e9, 1e9);
  if (!(f[0] < 0 && f[1] > 0)) r.fail(path + ".force", "must be [pull < 0, push > 0] in N");
  c.min_length = len[0];
  c.max_length = len[1];
  c.min_force = f[0];
  c.max_force = f[1];
  c.max_speed = r.number(n, "speed", path + ".speed", 1e-6, 100.0);
  return c;
}

Vec2 read_pin(const MachineFileReader& r, const YAML::Node& section, const std::string& path,
              const char* name) {
  return r.vec<2>(section[name], path + "." + name, -kMaxCoord, kMaxCoord);
}

}  // namespace

MachineError::MachineError(std::string file, std::string field, std::string reason)
    : std::runtime_error(format_what(file, field, reason)),
      file_(std::move(file)),
      field_(std::move(field)),
      reason_(std::move(reason)) {}

Vec4 Machine::q_min() const { return Vec4(-kInf, boom.min_length, arm.min_length, bucket.min_length); }
Vec4 Machine::q_max() const { return Vec4(kInf, boom.max_length, arm.max_length, bucket.max_length); }
Vec4 Machine::effort_min() const {
  return Vec4(swing.min_torque, boom.min_force, arm.min_force, bucket.min_force);
}
Vec4 Machine::effort_max() const {
  return Vec4(swing.max_torque, boom.max_force, arm.max_force, bucket.max_force);
}
Vec4 Machine::speed_max() const {
  return Vec4(swing.max_speed, boom.max_speed, arm.max_speed, bucket.max_speed);
}

Machine load_machine_from_string(const std::string& yaml, const std::string& file_for_errors) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::ParserException& e) {
    throw MachineError(file_for_errors, "line " + std::to_string(e.mark.line + 1), "YAML syntax: " + e.msg);
  }
  if (!root || !root.IsMap()) throw MachineError(file_for_errors, "", "not a YAML mapping (empty file?)");
  const MachineFileReader r(root, file_for_errors);
  r.only_keys(root, "", {"name", "gravity", "swing", "frames", "pins", "assembly", "bodies", "actuators",
                         "reference_poses", "terrain"});

  Machine m;
  m.source = file_for_errors;
  m.name = r.text(root["name"], "name");
  m.gravity = r.number(root, "gravity", "gravity", 0.1, 100.0);

  const YAML::Node swing = r.map(root, "swing", "swing");
  r.only_keys(swing, "swing", {"height"});
  m.swing_height = r.number(swing, "height", "swing.height", 0.0, kMaxCoord);

  // pins
  const YAML::Node pins = r.map(root, "pins", "pins");
  r.only_keys(pins, "pins", {"swing", "boom", "arm", "bucket", "link_lengths"});
  const YAML::Node ps = r.map(pins, "swing", "pins.swing");
  r.only_keys(ps, "pins.swing", {"C", "D"});
  m.C = read_pin(r, ps, "pins.swing", "C");
  m.D = read_pin(r, ps, "pins.swing", "D");
  const YAML::Node pb = r.map(pins, "boom", "pins.boom");
  r.only_keys(pb, "pins.boom", {"E", "F", "H"});
  m.E = read_pin(r, pb, "pins.boom", "E");
  m.F = read_pin(r, pb, "pins.boom", "F");
  m.H = read_pin(r, pb, "pins.boom", "H");
  const YAML::Node pa = r.map(pins, "arm", "pins.arm");
  r.only_keys(pa, "pins.arm", {"G", "I", "K", "M"});
  m.G = read_pin(r, pa, "pins.arm", "G");
  m.I = read_pin(r, pa, "pins.arm", "I");
  m.K = read_pin(r, pa, "pins.arm", "K");
  m.M = read_pin(r, pa, "pins.arm", "M");
  const YAML::Node pk = r.map(pins, "bucket", "pins.bucket");
  r.only_keys(pk, "pins.bucket", {"L", "T"});
  m.L = read_pin(r, pk, "pins.bucket", "L");
  m.T = read_pin(r, pk, "pins.bucket", "T");
  const YAML::Node pl = r.map(pins, "link_lengths", "pins.link_lengths");
  r.only_keys(pl, "pins.link_lengths", {"JL", "JK"});
  m.JL = r.number(pl, "JL", "pins.link_lengths.JL", 0.01, kMaxCoord);
  m.JK = r.number(pl, "JK", "pins.link_lengths.JK", 0.01, kMaxCoord);

  // The frames fix these: H lies on the boom x axis, M on the arm x axis, L on the bucket x axis.
  if (std::abs(m.H.y()) > 1e-9 || m.H.x() <= 0) r.fail("pins.boom.H", "must be (x > 0, 0): the boom x axis is C->H");
  if (std::abs(m.M.y()) > 1e-9 || m.M.x() <= 0) r.fail("pins.arm.M", "must be (x > 0, 0): the arm x axis is H->M");
  if (std::abs(m.L.y()) > 1e-9 || m.L.x() <= 0) r.fail("pins.bucket.L", "must be (x > 0, 0): the bucket x axis is M->L");
  if ((m.C - m.D).norm() < 1e-3) r.fail("pins.swing.D", "coincides with C");
  if (m.F.norm() < 1e-3) r.fail("pins.boom.F", "coincides with the boom foot C");
  if ((m.I - m.K).norm() < 1e-3) r.fail("pins.arm.I", "coincides with K");
  if ((m.K - m.M).norm() < 1e-3) r.fail("pins.arm.K", "coincides with M");

  // bodies
  const YAML::Node bodies = r.map(root, "bodies", "bodies");
  {
    std::set<std::string> names(kBodyNames.begin(), kBodyNames.end());
    r.only_keys(bodies, "bodies", names);
  }
  for (int i = 0; i < kNumJoints; ++i) {
    const std::string path = std::string("bodies.") + kBodyNames[i];
    const YAML::Node b = r.map(bodies, kBodyNames[i], path);
    r.only_keys(b, path, {"mass", "com", "inertia"});
    BodyInertia& bi = m.bodies[i];
    bi.mass = r.number(b, "mass", path + ".mass", 1e-3, 1e6);
    bi.com = r.vec<3>(b["com"], path + ".com", -kMaxCoord, kMaxCoord);
    bi.inertia = r.vec<3>(b["inertia"], path + ".inertia", 1e-6, 1e8);
    const Vec3& I = bi.inertia;
    // Principal moments of a real body obey the triangle inequality.
    for (int a = 0; a < 3; ++a) {
      const double others = I[(a + 1) % 3] + I[(a + 2) % 3];
      if (I[a] > others * (1 + 1e-9))
        r.fail(path + ".inertia", "principal moment [" + std::to_string(a) + "] = " + num(I[a]) +
                                      " exceeds the sum of the other two (" + num(others) +
                                      "): not a physical body");
    }
  }

  // actuators
  const YAML::Node act = r.map(root, "actuators", "actuators");
  r.only_keys(act, "actuators", {"swing", "boom", "arm", "bucket", "relief_pressure"});
  {
    const YAML::Node s = r.map(act, "swing", "actuators.swing");
    r.only_keys(s, "actuators.swing", {"torque", "speed"});
    const Vec2 t = r.vec<2>(s["torque"], "actuators.swing.torque", -1e9, 1e9);
    if (!(t[0] < 0 && t[1] > 0)) r.fail("actuators.swing.torque", "must be [min < 0, max > 0] in N m");
    m.swing.min_torque = t[0];
    m.swing.max_torque = t[1];
    m.swing.max_speed = r.number(s, "speed", "actuators.swing.speed", 1e-6, 100.0);
  }
  m.boom = read_cylinder(r, act, "boom");
  m.arm = read_cylinder(r, act, "arm");
  m.bucket = read_cylinder(r, act, "bucket");
  m.relief_pressure = r.number(act, "relief_pressure", "actuators.relief_pressure", 1e5, 1e9);

  // reference poses (optional: a machine without measured poses is still a machine)
  if (const YAML::Node poses = root["reference_poses"]) {
    if (!poses.IsSequence()) r.fail("reference_poses", "must be a list");
    for (std::size_t k = 0; k < poses.size(); ++k) {
      const std::string path = "reference_poses[" + std::to_string(k) + "]";
      const YAML::Node p = poses[k];
      if (!p.IsMap()) r.fail(path, "must be a mapping");
      r.only_keys(p, path, {"q_a", "boom_angle_deg", "arm_angle_deg", "bucket_angle_deg", "pins_world"});
      ReferencePose rp;
      rp.q_a = r.vec<4>(p["q_a"], path + ".q_a", -kMaxCoord, kMaxCoord);
      rp.boom_angle_deg = r.number(p, "boom_angle_deg", path + ".boom_angle_deg", -360, 360);
      rp.arm_angle_deg = r.number(p, "arm_angle_deg", path + ".arm_angle_deg", -360, 360);
      rp.bucket_angle_deg = r.number(p, "bucket_angle_deg", path + ".bucket_angle_deg", -360, 360);
      if (const YAML::Node pw = p["pins_world"]) {
        if (!pw.IsMap()) r.fail(path + ".pins_world", "must be a mapping");
        r.only_keys(pw, path + ".pins_world", {"C", "E", "H", "G", "M", "J", "L", "T"});
        for (const char* name : {"C", "E", "H", "G", "M", "J", "L", "T"}) {
          if (pw[name])
            rp.pins_world.emplace_back(name, r.vec<3>(pw[name], path + ".pins_world." + name, -kMaxCoord, kMaxCoord));
        }
      }
      m.reference_poses.push_back(std::move(rp));
    }
  }

  if (const YAML::Node terrain = root["terrain"]) {
    if (!terrain.IsMap()) r.fail("terrain", "must be a mapping");
    r.only_keys(terrain, "terrain", {"flat_height"});
    m.terrain_flat_height = r.number(terrain, "flat_height", "terrain.flat_height", -kMaxCoord, kMaxCoord);
  }
  return m;
}

Machine load_machine(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw MachineError(path, "", "cannot open the file for reading");
  std::ostringstream text;
  text << in.rdbuf();
  return load_machine_from_string(text.str(), path);
}

}  // namespace exc
