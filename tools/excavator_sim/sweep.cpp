#include "sweep.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <stdexcept>

#include "settings/section_reader.hpp"
#include "control/controller_kinds.hpp"
#include "model/machine.hpp"
#include "model/scene_common.hpp"
#include "fault_campaign.hpp"
#include "sweep_tables.hpp"

namespace exc::sim {
namespace {

using settings::Need;
using settings::SectionReader;

void read_range(SectionReader& p, const char* key, SweepRange& r, settings::Bounds bounds, const char* what) {
  if (!p.given(key)) return;
  std::array<double, 2> v{};
  p.numbers(key, v, bounds, "", what);
  if (v[1] < v[0]) p.fail(key, "max " + settings::format_number(v[1]) + " is below min " + settings::format_number(v[0]));
  r = SweepRange{true, v[0], v[1]};
}

double draw(std::mt19937_64& rng, const SweepRange& r, double fallback) {
  if (!r.given) return fallback;
  return r.min + (r.max - r.min) * std::uniform_real_distribution<double>(0.0, 1.0)(rng);
}

// One value of a knob from its node: a number, four numbers where the knob takes one per joint, or a
// name where it takes names; range-checked. Errors at the key (index >= 0: at the list's element).
SweepValue read_value(const SectionReader& r, const std::string& key, long index, const YAML::Node& n, const KnobInfo& k) {
  auto fail = [&](const std::string& why) {
    if (index >= 0) r.fail(key, static_cast<std::size_t>(index), why);
    r.fail(key, why);
  };
  const std::string range = "in " + settings::format_number(k.lo) + ".." + settings::format_number(k.hi);
  auto checked = [&](double x) {
    if (x < k.lo || x > k.hi) fail("is " + settings::format_number(x) + "; must be " + range + " (" + k.what + ")");
    return x;
  };
  SweepValue v;
  if (n.IsSequence() && k.joints) {
    if (n.size() != 4) fail("must be one number or four (swing, boom, arm, bucket)");
    v.type = SweepValue::Type::joints;
    for (std::size_t j = 0; j < 4; ++j) {
      double x = 0;
      if (!settings::finite_number(n[j], x)) fail("must be four numbers " + range);
      v.joints[j] = checked(x);
    }
    return v;
  }
  if (!n.IsScalar()) fail(std::string("must be ") + (k.names ? "a name" : "a number " + range) + " (" + k.what + ")");
  if (k.names) {
    if (!k.names(n.Scalar())) fail("is '" + n.Scalar() + "'; " + k.what);
    v.type = SweepValue::Type::name;
    v.name = n.Scalar();
    return v;
  }
  if (!settings::finite_number(n, v.number)) fail("is '" + n.Scalar() + "'; must be a number " + range + " (" + k.what + ")");
  checked(v.number);
  return v;
}

// The knobs given in a mapping (a grid, the search): each a list of values.
std::vector<SweepAxis> read_axes(SectionReader& r, const YAML::Node& node, SweepRun run) {
  std::vector<SweepAxis> axes;
  for (const KnobInfo& k : knob_table(run)) {
    if (!r.given(k.name)) continue;
    const YAML::Node list = node[k.name];
    if (!list.IsSequence() || list.size() == 0) r.fail(k.name, "must be a list of values (" + std::string(k.what) + ")");
    SweepAxis a{k.name, {}};
    for (std::size_t i = 0; i < list.size(); ++i) a.values.push_back(read_value(r, k.name, static_cast<long>(i), list[i], k));
    axes.push_back(a);
  }
  r.finish();
  return axes;
}

}  // namespace

std::string SweepValue::text() const {
  if (type == Type::name) return name;
  if (type == Type::number) return settings::format_number(number);
  std::string s;
  for (double x : joints) s += (s.empty() ? "" : " ") + settings::format_number(x);
  return s;
}

nlohmann::json SweepValue::to_json() const {
  if (type == Type::name) return name;
  if (type == Type::number) return number;
  return joints;
}

namespace {
// The points of one grid: its axes crossed.
int grid_size(const SweepGrid& g) {
  int p = 1;
  for (const SweepAxis& a : g) p *= static_cast<int>(a.values.size());
  return p;
}
}  // namespace

int SweepSpec::grid_points() const {
  int n = 0;
  for (const SweepGrid& g : grids) n += grid_size(g);
  return grids.empty() ? 1 : n;
}

int SweepSpec::total_cases() const {
  return static_cast<int>(scenes.size()) * std::max<int>(1, static_cast<int>(variants.size())) * grid_points() * cases;
}

bool SweepSpec::records(const std::string& what) const { return std::find(record.begin(), record.end(), what) != record.end(); }

std::vector<std::string> SweepSpec::set_knobs() const {
  std::vector<std::string> knobs;
  auto add = [&knobs](const std::string& k) {
    if (std::find(knobs.begin(), knobs.end(), k) == knobs.end()) knobs.push_back(k);
  };
  for (const SweepGrid& g : grids)
    for (const SweepAxis& a : g) add(a.knob);
  for (const SweepVariant& v : variants)
    for (const SweepSetting& s : v.values) add(s.first);
  return knobs;
}

const SweepValue* SweepCase::value(const std::string& knob) const {
  for (const SweepSetting& s : set)
    if (s.first == knob) return &s.second;
  return nullptr;
}

bool parse_shard(const std::string& text, int& shard, int& shards) {
  const std::size_t slash = text.find('/');
  if (slash == std::string::npos) return false;
  auto whole = [](const char* first, const char* last, int& value) {
    if (first == last || *first < '0' || *first > '9') return false;  // from_chars takes a '-'
    const auto [end, error] = std::from_chars(first, last, value);
    return error == std::errc() && end == last;
  };
  const char* const begin = text.data();
  return whole(begin, begin + slash, shard) && whole(begin + slash + 1, begin + text.size(), shards) && shards >= 1 &&
         shard < shards;
}

namespace {
// The machine file a scene names (absolute, as the scene's reader resolves it), "" when it names none
// (the built-in machine) or its shared keys do not load: the scene's own load, when a case runs, says
// what is wrong with it.
std::string named_machine_file(const std::string& scene) {
  try {
    const settings::Document doc = settings::Document::load(scene);
    SectionReader top(doc);
    return read_scene_common(top, doc).machine_file;
  } catch (const SettingsError&) {
  }
  return "";
}

// FNV-1a (64 bit) of the spec's text (as read once by its Document), then each scene's bytes and its
// machine's (the file it names, or the built-in machine's text), as 16 hex digits: what a shard line
// carries so that the merge can tell a line of this spec from one of another or an edited one.
std::string content_digest(const std::string& spec_text, const std::vector<std::string>& scenes) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  const auto add = [&h](char c) { h = (h ^ static_cast<unsigned char>(c)) * 0x100000001b3ULL; };
  const auto end_of_file = [&h] { h = (h ^ 0xFF) * 0x100000001b3ULL; };  // so that bytes moved between files count
  const auto add_file = [&](const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    for (char c; in.get(c);) add(c);
    end_of_file();
  };
  for (const char c : spec_text) add(c);
  end_of_file();
  for (const std::string& scene : scenes) {
    add_file(scene);
    if (const std::string machine = named_machine_file(scene); !machine.empty()) {
      add_file(machine);
    } else {
      for (const char* c = reference_machine_text(); *c != 0; ++c) add(*c);
      end_of_file();
    }
  }
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}
}  // namespace

SweepSpec load_sweep_spec(const std::string& path) {
  const settings::Document doc = settings::Document::load(path);
  // The reader first: it refuses a file that is no mapping naming it (indexing a scalar root would
  // throw yaml-cpp's own error, which names no file).
  SectionReader top(doc);
  SectionReader s = top.section("sweep", "the sweep's mapping", Need::required);
  const YAML::Node raw = doc.root()["sweep"];
  SweepSpec spec;
  spec.file = path;
  // One scene, or several: case i runs scene i mod their number.
  // A scene that is not a file is refused here, at its line, not when the first case runs.
  auto scene_problem = [](const std::string& resolved) -> std::string {
    std::error_code ec;
    if (std::filesystem::is_regular_file(resolved, ec)) return "";
    return resolved + (std::filesystem::is_directory(resolved, ec) ? ": is a directory, not a scene file" : ": no such file");
  };
  std::string scene;
  if (s.given("scene")) {
    s.text("scene", scene, "the scene file, relative to the spec");
    spec.scenes.push_back(doc.resolve(scene));
    if (const std::string problem = scene_problem(spec.scenes.back()); !problem.empty()) s.fail("scene", problem);
  }
  if (s.given("scenes")) {
    const YAML::Node list = raw["scenes"];
    if (!list.IsSequence() || list.size() == 0) s.fail("scenes", "must be a list of scene files");
    for (std::size_t i = 0; i < list.size(); ++i) {
      if (!list[i].IsScalar()) s.fail("scenes", i, "must be a scene file");
      spec.scenes.push_back(doc.resolve(list[i].Scalar()));
      if (const std::string problem = scene_problem(spec.scenes.back()); !problem.empty()) s.fail("scenes", i, problem);
    }
  }
  if (s.given("scene") == s.given("scenes")) s.fail_here("name the scenes: scene: FILE or scenes: [FILE, ...] (one of them)");
  s.choice("run", spec.run, kSweepRuns, "what one run of a case is");
  s.choices("controllers", spec.controllers, control::kControllerKinds, 1, "the controllers each case runs");
  s.whole("cases", spec.cases, 1, 1e6, "", "seeded random draws per grid point and variant, case i from (seed, i)");
  s.whole("seed", spec.seed, 0, 4e9, "", "the draws' seed");
  if (s.given("duration")) s.number("duration", spec.duration, {1e-3, 3600}, "s", "per run (absent: the scene's)");
  s.flag("stop_at_safe_state", spec.stop_at_safe_state, "end each run at the firmware's first safe stop");
  SectionReader w = s.section("window", "open loop: the task's window the effort profile covers");
  w.number("start", spec.window_start, {0, 3600}, "s", "of the task where the window starts");
  w.number("horizon", spec.window_horizon, {0.01, 3600}, "s", "simulated");
  w.finish();
  SectionReader p = s.section("perturbations", "each drawn uniformly in [min, max] per case");
  read_range(p, "model_mass", spec.model_mass, {-0.9, 9}, "the firmware's link masses x (1 + value)");
  read_range(p, "soil_stiffness", spec.soil_stiffness, {0.01, 100}, "the plant's soil K x value");
  read_range(p, "position_noise", spec.position_noise, {0, 0.1}, "m (rad on the swing), 1 sigma");
  read_range(p, "delay_cycles", spec.delay_cycles, {0, 100}, "whole cycles, drawn as integers");
  p.finish();
  s.choices("faults", spec.faults, kFaultKinds, 0, "one fault per case, its kind drawn from the list");
  if (s.given("grid")) {
    if (raw["grid"].IsSequence()) {
      s.sections("grid", 1, 1000, "grids run one after the other", [&](SectionReader& g, std::size_t i) {
        spec.grids.push_back(read_axes(g, raw["grid"][i], spec.run));
      });
    } else {
      SectionReader g = s.section("grid", "lists of values, crossed");
      spec.grids.push_back(read_axes(g, raw["grid"], spec.run));
    }
    for (const SweepGrid& g : spec.grids)
      if (g.empty()) s.fail("grid", "a grid names no knob; allowed: " + knob_names(spec.run));
  }
  s.sections("variants", 0, 10000, "named cases", [&](SectionReader& v, std::size_t i) {
    SweepVariant variant;
    v.text("name", variant.name, "the variant's short name", Need::required);
    v.text("description", variant.description, "what is changed, in words");
    for (const KnobInfo& k : knob_table(spec.run))
      if (v.given(k.name)) variant.values.push_back({k.name, read_value(v, k.name, -1, raw["variants"][i][k.name], k)});
    spec.variants.push_back(variant);
  });
  if (s.given("search")) {
    SectionReader q = s.section("search", "one knob: per case, the first of its values whose run passes");
    const std::vector<SweepAxis> axes = read_axes(q, raw["search"], spec.run);
    if (axes.size() != 1) s.fail("search", "must name exactly one knob; allowed: " + knob_names(spec.run));
    spec.search = axes.front();
  }
  s.choices("record", spec.record, kSweepRecords, 1, "what the merge writes");
  // A knob is either drawn or set, and set by one of grid, variants and search.
  const std::vector<std::string> set = spec.set_knobs();
  for (const std::string& k : set) {
    const bool drawn = (k == "model_mass" && spec.model_mass.given) || (k == "soil_stiffness" && spec.soil_stiffness.given) ||
                       (k == "position_noise" && spec.position_noise.given) || (k == "delay_cycles" && spec.delay_cycles.given);
    if (drawn) s.fail("perturbations", "'" + k + "' is drawn here and set by the grid or a variant: choose one");
    if (k == spec.search.knob) s.fail("search", "'" + k + "' is searched and set by the grid or a variant: choose one");
    if (!spec.grids.empty() && !spec.variants.empty())
      for (const SweepVariant& v : spec.variants)
        for (const SweepSetting& vs : v.values)
          for (const SweepGrid& g : spec.grids)
            for (const SweepAxis& a : g)
              if (a.knob == vs.first) s.fail("variants", "'" + vs.first + "' is set by the grid and by variant " + v.name);
  }
  if (spec.total_cases() > 10'000'000) s.fail_here("more than 10 million cases");
  s.finish();
  top.finish();
  spec.digest = content_digest(doc.text(), spec.scenes);
  return spec;
}

SweepCase sweep_case(const SweepSpec& spec, int id) {
  // One generator per case, seeded from (seed, id): independent of which shard runs the case.
  std::seed_seq seq{spec.seed, static_cast<unsigned>(id), 0x5eedu};
  std::mt19937_64 rng(seq);
  SweepCase c;
  c.id = id;
  // id = ((scene * variants + variant) * points + point) * cases + draw.
  int rest = id / spec.cases;
  const int points = spec.grid_points(), variants = std::max<int>(1, static_cast<int>(spec.variants.size()));
  int point = rest % points;
  rest /= points;
  c.variant = spec.variants.empty() ? -1 : rest % variants;
  c.scene = rest / variants;
  for (std::size_t g = 0; g < spec.grids.size(); ++g) {
    const int size = grid_size(spec.grids[g]);
    if (point >= size) {
      point -= size;
      continue;
    }
    c.grid = static_cast<int>(g);
    for (auto a = spec.grids[g].rbegin(); a != spec.grids[g].rend(); ++a) {  // the last axis fastest
      const int n = static_cast<int>(a->values.size());
      c.set.insert(c.set.begin(), {a->knob, a->values[static_cast<std::size_t>(point % n)]});
      point /= n;
    }
    break;
  }
  if (c.variant >= 0)
    for (const SweepSetting& v : spec.variants[static_cast<std::size_t>(c.variant)].values) c.set.push_back(v);
  c.model_mass = draw(rng, spec.model_mass, 0);
  c.soil_stiffness = draw(rng, spec.soil_stiffness, 1);
  c.position_noise = draw(rng, spec.position_noise, 0);
  c.delay_cycles = static_cast<int>(std::floor(draw(rng, spec.delay_cycles, 0) + (spec.delay_cycles.given ? 0.5 : 0)));
  if (!spec.faults.empty()) draw_fault(rng, spec.faults, c);
  return c;
}

}  // namespace exc::sim
