// The settings blob (app/settings_blob.hpp) on its own: what a damaged or foreign blob is refused for,
// and the layout fingerprint's reach. The runs from decoded blobs are test_settings_blob_runs.cpp.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/firmware_settings.hpp"
#include "app/settings_blob.hpp"

using namespace exc;

namespace {

// The smallest shipped scene's blob (a few joint waypoints): every truncation and flip is cheap.
app::FirmwareImageSettings free_motion_settings() {
  const app::FirmwareSettings s = app::load_firmware_settings(std::string(EXC_SOURCE_DIR) + "/scenes/paper_free_motion.yaml");
  app::FirmwareNodeConfig node;
  node.controller = s.controller;
  node.site_map = s.terrain;
  return app::image_settings(s, node);
}

void put_u32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(v >> (8 * i));
}

// The CRC made right again after a change: what the decoder says past the CRC.
void reseal(std::vector<std::uint8_t>& b) {
  put_u32(b, b.size() - 4, app::crc32(b.data(), b.size() - 4));
}

// Decodes into settings marked "untouched": a refusal must leave them so.
std::string refusal(const std::vector<std::uint8_t>& b, std::size_t size) {
  app::FirmwareImageSettings out;
  out.scene = "untouched";
  std::string error;
  const bool ok = app::decode_settings_blob(b.data(), size, out, error);
  if (ok) return "";
  CHECK(out.scene == "untouched");
  CHECK(!error.empty());
  return error;
}
std::string refusal(const std::vector<std::uint8_t>& b) { return refusal(b, b.size()); }

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("firmware/settings blob: a blob decodes to what was encoded and encodes to the same bytes again") {
  const app::FirmwareImageSettings s = free_motion_settings();
  const std::vector<std::uint8_t> blob = app::encode_settings_blob(s);
  app::FirmwareImageSettings d;
  std::string error;
  REQUIRE(app::decode_settings_blob(blob.data(), blob.size(), d, error));
  CHECK(error.empty());
  CHECK(d.scene == "paper_free_motion");
  const app::FirmwareSettings scene = app::load_firmware_settings(std::string(EXC_SOURCE_DIR) + "/scenes/paper_free_motion.yaml");
  CHECK(d.cycles == std::llround(scene.duration / scene.controller.period));
  CHECK(d.task.trajectory.times() == s.task.trajectory.times());
  CHECK(d.node.controller.law == s.node.controller.law);
  CHECK(app::encode_settings_blob(d) == blob);
  // The header as docs and the image read it.
  CHECK(std::string(blob.begin(), blob.begin() + 4) == "EXSB");
  CHECK(blob[4] == app::kSettingsBlobVersion);
  CHECK(blob[8] + 256u * blob[9] + 65536u * blob[10] == blob.size());
}

TEST_CASE("firmware/settings blob: every truncation and every flipped byte is refused with its named reason") {
  const std::vector<std::uint8_t> blob = app::encode_settings_blob(free_motion_settings());
  REQUIRE(blob.size() > 100);
  for (std::size_t n = 0; n < blob.size(); ++n) {
    CAPTURE(n);
    const std::string why = refusal(blob, n);
    CHECK((n < 24 ? contains(why, "shorter than its header and CRC") : contains(why, "(truncated)")));
  }
  for (std::size_t i = 0; i < blob.size(); ++i) {
    CAPTURE(i);
    std::vector<std::uint8_t> b = blob;
    b[i] ^= 0xFF;
    const std::string why = refusal(b);
    if (i < 4) CHECK(contains(why, "bad magic"));
    else if (i < 8) CHECK(contains(why, "format version"));
    else if (i < 12) CHECK(contains(why, "length: the header says"));
    else CHECK(contains(why, "CRC-32"));  // the fingerprint, a field or the CRC itself
  }
}

TEST_CASE("firmware/settings blob: a flipped byte past a recomputed CRC is refused by field or decodes, never crashes") {
  // What a broken encoder would send: each payload byte flipped, the CRC made right. The decoder
  // either reads valid values (a changed gain) or names the field it refuses; never reads past the end.
  const std::vector<std::uint8_t> blob = app::encode_settings_blob(free_motion_settings());
  int refused = 0;
  for (std::size_t i = 12; i + 4 < blob.size(); ++i) {
    CAPTURE(i);
    std::vector<std::uint8_t> b = blob;
    b[i] ^= 0xFF;
    reseal(b);
    const std::string why = refusal(b);
    if (why.empty()) continue;
    ++refused;
    const bool named = contains(why, "layout fingerprint") || contains(why, "field ") || contains(why, "after the last field");
    CHECK_MESSAGE(named, why);
  }
  CHECK(refused > 0);
}

TEST_CASE("firmware/settings blob: a wrong version, a foreign layout, a count over its maximum and trailing bytes are refused by name") {
  const std::vector<std::uint8_t> blob = app::encode_settings_blob(free_motion_settings());
  {
    std::vector<std::uint8_t> b = blob;
    put_u32(b, 4, 2);
    CHECK(refusal(b) == "format version 2, this image reads version 1");
  }
  {
    std::vector<std::uint8_t> b = blob;
    b[12] ^= 1;  // the fingerprint's first byte
    reseal(b);
    CHECK(contains(refusal(b), "layout fingerprint"));
    CHECK(contains(refusal(b), "the blob was made from other sources"));
  }
  {
    // The first field is the scene's name: its count one above the maximum.
    std::vector<std::uint8_t> b = blob;
    put_u32(b, 20, static_cast<std::uint32_t>(app::kMaxSceneName + 1));
    reseal(b);
    CHECK(contains(refusal(b), "field scene (at byte 24): count 257 above its maximum 256"));
  }
  {
    // Bytes between the last field and the CRC, the length and CRC made right.
    std::vector<std::uint8_t> b = blob;
    b.insert(b.end() - 4, 8, 0);
    put_u32(b, 8, static_cast<std::uint32_t>(b.size()));
    reseal(b);
    CHECK(refusal(b) == "8 bytes after the last field");
  }
  {
    std::vector<std::uint8_t> b = blob;
    b.push_back(0);
    CHECK(contains(refusal(b), "(bytes after its end)"));
  }
}

TEST_CASE("firmware/settings blob: values the node cannot run are refused, naming the field") {
  const app::FirmwareImageSettings good = free_motion_settings();
  auto refused = [](const app::FirmwareImageSettings& s) { return refusal(app::encode_settings_blob(s)); };
  {
    app::FirmwareImageSettings s = good;
    s.machine.hydraulics.pump_flow = std::numeric_limits<double>::quiet_NaN();
    CHECK(contains(refused(s), "field machine.hydraulics.pump_flow"));
    CHECK(contains(refused(s), "is not a finite number"));
  }
  {
    app::FirmwareImageSettings s = good;
    s.machine.bodies[3].com[1] = std::numeric_limits<double>::infinity();
    CHECK(contains(refused(s), "field machine.bodies[3].com"));
  }
  {
    app::FirmwareImageSettings s = good;
    s.node.controller.law = "bang_bang";
    CHECK(contains(refused(s), "field node.controller.law: 'bang_bang' is not a control law of this image"));
  }
  {
    app::FirmwareImageSettings s = good;
    s.node.controller.law = "flow";  // the scene commands efforts
    CHECK(contains(refused(s), "field node.controller.law: flow commands the valves' flow"));
  }
  {
    app::FirmwareImageSettings s = good;
    s.cycles = 0;
    CHECK(contains(refused(s), "field cycles: 0"));
  }
  {
    app::FirmwareImageSettings s = good;
    s.task.trajectory = control::JointTrajectory();  // no knots: no spline to follow
    CHECK(contains(refused(s), "field task.trajectory.times"));
  }
  {
    app::FirmwareImageSettings s = good;
    s.node.site_map.num_points = 2;
    s.node.site_map.profile[0] = Vec2(1, 0);
    s.node.site_map.profile[1] = Vec2(1, 1);
    CHECK(contains(refused(s), "field node.site_map.profile[1]: x must increase strictly"));
  }
  {
    // Above its maximum the encoder refuses (the host, when the blob is made), naming the field.
    app::FirmwareImageSettings s = good;
    s.task.cycle_starts.assign(control::kMaxTaskCycles + 1, 0.0);
    CHECK_THROWS_WITH_AS(app::encode_settings_blob(s),
                         "settings blob: task.cycle_starts has 1001 entries, more than the blob carries (1000)",
                         std::length_error);
  }
}

namespace {

// A struct and its variants, each with its field list, for the fingerprint.
struct Probe {
  double gain = 1;
  int count = 2;
  std::vector<double> knots;
};
template <typename V>
void visit_fields(V& v, Probe& p) {
  v("gain", p.gain);
  v("count", p.count);
  v("knots", p.knots, 10);
}
struct ProbeSame {  // another struct, the same fields: the same layout
  double gain = 5;
  int count = 7;
  std::vector<double> knots = {1, 2};
};
template <typename V>
void visit_fields(V& v, ProbeSame& p) {
  v("gain", p.gain);
  v("count", p.count);
  v("knots", p.knots, 10);
}
struct ProbeRenamed : Probe {};
template <typename V>
void visit_fields(V& v, ProbeRenamed& p) {
  v("gain_", p.gain);
  v("count", p.count);
  v("knots", p.knots, 10);
}
struct ProbeRetyped {
  double gain = 1;
  double count = 2;
  std::vector<double> knots;
};
template <typename V>
void visit_fields(V& v, ProbeRetyped& p) {
  v("gain", p.gain);
  v("count", p.count);
  v("knots", p.knots, 10);
}
struct ProbeReordered : Probe {};
template <typename V>
void visit_fields(V& v, ProbeReordered& p) {
  v("count", p.count);
  v("gain", p.gain);
  v("knots", p.knots, 10);
}
struct ProbeLonger : Probe {};
template <typename V>
void visit_fields(V& v, ProbeLonger& p) {
  v("gain", p.gain);
  v("count", p.count);
  v("knots", p.knots, 11);
}
struct ProbeNested {
  Probe inner;
};
template <typename V>
void visit_fields(V& v, ProbeNested& p) {
  v("inner", p.inner);
}
struct ProbeNestedRenamed {
  ProbeRenamed inner;
};
template <typename V>
void visit_fields(V& v, ProbeNestedRenamed& p) {
  v("inner", p.inner);
}

}  // namespace

TEST_CASE("firmware/settings blob: the layout fingerprint changes with a field's name, type, order or maximum, not with values") {
  const std::uint64_t probe = app::layout_fingerprint<Probe>();
  CHECK(app::layout_fingerprint<ProbeSame>() == probe);
  CHECK(app::layout_fingerprint<ProbeRenamed>() != probe);
  CHECK(app::layout_fingerprint<ProbeRetyped>() != probe);
  CHECK(app::layout_fingerprint<ProbeReordered>() != probe);
  CHECK(app::layout_fingerprint<ProbeLonger>() != probe);
  CHECK(app::layout_fingerprint<ProbeNestedRenamed>() != app::layout_fingerprint<ProbeNested>());
  app::LayoutDescription d;
  Probe p;
  visit_fields(d, p);
  CHECK(d.text() == "gain:f64;count:i32;knots:vec<=10<f64>;");
  // The settings' own: every visited field, nested by struct (a sample of its text).
  app::LayoutDescription all;
  app::FirmwareImageSettings s;
  visit_fields(all, s);
  CHECK(contains(all.text(), "machine:{gravity:f64;swing_height:f64;C:f64[2];"));
  CHECK(contains(all.text(), "bodies:[12]{mass:f64;com:f64[3];inertia:f64[3];};"));
  CHECK(contains(all.text(), "type:u8{joint_waypoints=0,dig=1,truck_loading=2,};trajectory:{times:vec<=20000<f64>;points:vec<=20000<f64[4]>;};"));
  CHECK(contains(all.text(), "site_map:{height:f64;profile:counted<=64<f64[2]>;};"));
}
