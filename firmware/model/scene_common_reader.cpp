#include "model/scene_common_reader.hpp"

namespace exc {

using settings::Need;

SceneMachine read_scene_machine(settings::SectionReader& top, const settings::Document& scene) {
  SceneMachine m;
  if (!top.given("machine")) {
    m.document = settings::Document::parse(reference_machine_text(), "<embedded>");
    m.machine = read_machine(m.document);
    return m;
  }
  std::string path;
  top.text("machine", path, "machine file, relative to the scene file");
  m.file = scene.resolve(path);
  try {
    m.document = settings::Document::load(m.file);
    m.machine = read_machine(m.document);
  } catch (const SettingsError& e) {
    top.fail("machine", std::string("the machine file does not load: ") + e.what());
  }
  top.record("machine", m.file);
  return m;
}

SceneCommon read_scene_common(settings::SectionReader& top, const SceneMachine& machine) {
  SceneCommon c;
  top.text("name", c.name, "the scene's name", Need::required);
  top.text("description", c.description, "one line for people");
  // The key read by read_scene_machine, declared and recorded here as well (the file is not read again).
  if (top.given("machine")) top.record("machine", machine.file);
  c.machine_file = machine.file;
  c.machine = machine.machine;
  settings::SectionReader terrain = top.section("terrain", "the ground");
  if (terrain.has("height") && terrain.has("profile"))
    terrain.fail("profile", "give either 'height' or 'profile', not both");
  c.terrain.height = c.machine.terrain_flat_height;
  if (terrain.given("profile")) {
    terrain.others({"height"});
    std::vector<Vec2> profile;
    terrain.rows("profile", profile, 2, Terrain::kMaxPoints, Vec2(-100, -20), Vec2(100, 20), "m",
                 "points [x, z] of a piecewise-linear ground along the swing plane's x");
    for (std::size_t i = 1; i < profile.size(); ++i)
      if (!(profile[i].x() > profile[i - 1].x())) terrain.fail("profile", i, "x must increase strictly along the profile");
    c.terrain.num_points = static_cast<int>(profile.size());
    for (std::size_t i = 0; i < profile.size(); ++i) c.terrain.profile[i] = profile[i];
  } else {
    terrain.others({"profile"});
    terrain.number("height", c.terrain.height, {-20, 20}, "m", "flat ground at world z");
  }
  terrain.finish();
  top.number("duration", c.duration, kRunDurationBounds, "s", "how long the run lasts (up to a working shift)", Need::required);
  return c;
}

}  // namespace exc
