#include "sweep.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <set>
#include <stdexcept>

#include "settings/section_reader.hpp"
#include "control/controller_registry.hpp"
#include "fault_campaign.hpp"
#include "sweep_knobs.hpp"
#include "sweep_tables.hpp"

namespace exc::sim {
namespace {

using settings::Declaration;
using settings::format_number;
using settings::Need;
using settings::SectionReader;

[[noreturn]] void fail_at(const SectionReader& r, const std::string& key, long index, const std::string& why) {
  if (index >= 0) r.fail(key, static_cast<std::size_t>(index), why);
  r.fail(key, why);
}

// "a whole number in [0, 63]", "a number in [0, 0.1]" (element's bounds), with the unit.
std::string allowed(const Declaration& d, int element) {
  const settings::Bounds& b = d.bounds_of(element);
  return std::string(d.type == Declaration::Type::whole ? "a whole number" : "a number") + " in [" + format_number(b.lo) +
         ", " + format_number(b.hi) + "]" + (d.unit.empty() ? "" : " " + d.unit);
}

// One value of a knob from its node, as its declaration takes it: a name for an enumeration (its
// readers check it), a number (a whole one where the setting is whole), for a setting that takes a
// list of numbers either that many or one for every element; each number within its range. Errors at
// the key (index >= 0: at the list's element), naming the range and the setting.
SweepValue read_value(const SectionReader& r, const std::string& key, long index, const YAML::Node& n, const Declaration& d) {
  const std::string about = " (" + d.field + (d.what.empty() ? "" : ": " + d.what) + ")";
  SweepValue v;
  if (d.type == Declaration::Type::choice) {
    if (!n.IsScalar()) fail_at(r, key, index, "must be a name" + about);
    v.type = SweepValue::Type::name;
    v.name = n.Scalar();
    return v;
  }
  const auto number = [&](const YAML::Node& x, int first, int last) {
    double value = 0;
    if (!settings::finite_number(x, value))
      fail_at(r, key, index, "is '" + (x.IsScalar() ? x.Scalar() : std::string("not a scalar")) + "'; must be " +
                                 allowed(d, first) + about);
    for (int e = first; e <= last; ++e) {
      const settings::Bounds& b = d.bounds_of(e);
      if (value < b.lo || value > b.hi || (d.type == Declaration::Type::whole && value != std::floor(value)))
        fail_at(r, key, index, "is " + format_number(value) + "; allowed: " + allowed(d, e) + about);
    }
    return value;
  };
  const bool list = d.type == Declaration::Type::numbers;
  if (n.IsSequence() && list) {
    if (static_cast<int>(n.size()) != d.count)
      fail_at(r, key, index, "must be one number or " + std::to_string(d.count) + " of them" + about);
    v.type = SweepValue::Type::list;
    for (int e = 0; e < d.count; ++e) v.list.push_back(number(n[static_cast<std::size_t>(e)], e, e));
    return v;
  }
  if (!n.IsScalar())
    fail_at(r, key, index, "must be " + (list ? "one number or " + std::to_string(d.count) : std::string("a number")) + about);
  v.number = number(n, 0, list ? d.count - 1 : 0);
  return v;
}

// Reads a spec's knobs and values, each value read by the scenes' readers once.
class KnobReader {
 public:
  explicit KnobReader(const SweepSpec& spec) : spec_(spec) {}

  // What the knob at `key` takes, the same in every scene (an error at the key otherwise).
  Declaration values(SectionReader& r, const std::string& key) {
    r.given(key.c_str());  // declared (and refused when it has no value)
    Declaration first;
    for (std::size_t i = 0; i < spec_.sources.size(); ++i) {
      try {
        const Declaration d = knob_values(spec_.run, key, *spec_.sources[i]);
        if (i == 0) first = d;
      } catch (const std::invalid_argument& e) {
        r.fail(key, e.what());
      }
    }
    return first;
  }

  // A value, read as the scenes' readers read it with the value set. One they refuse alone is held
  // for check_refused: the grid's other values or a variant's may make it valid (a faster path with
  // the timing fitted), which only the whole spec shows.
  SweepValue value(const SectionReader& r, const std::string& key, long index, const YAML::Node& n, const Declaration& d) {
    const SweepValue v = read_value(r, key, index, n, d);
    if (!checked_.insert(key + "=" + v.text()).second) return v;
    for (const std::shared_ptr<const SceneSource>& scene : spec_.sources) {
      try {
        SceneChanges changes(*scene);
        set_knob(spec_.run, key, v, changes);
        (void)changes.read();
      } catch (const std::exception& e) {
        refused_.push_back(Refused{r, key, index, v, e.what()});
        break;
      }
    }
    return v;
  }

  // Each value refused alone, read again in every case it runs in: with each grid point and variant
  // of each scene (the point's or variant's own value of the knob where it sets it; a drawn or
  // searched value beside their settings, as case_bundle sets them). Refused in any: an error at the
  // value naming the settings it was read with.
  void check_refused() const {
    if (refused_.empty()) return;
    const int points = spec_.grid_points(), variants = std::max<int>(1, static_cast<int>(spec_.variants.size()));
    const long combinations = static_cast<long>(spec_.sources.size()) * points * variants;
    SweepSpec one = spec_;  // a case per combination: its id is the combination's index
    one.cases = 1;
    // The grid's and the variants' values first: they are read without the draws, so a value refused
    // for itself (a name no reader takes) is named, not a draw read beside it.
    std::vector<const Refused*> order;
    const std::vector<std::string> set = spec_.set_knobs();
    for (int pass = 0; pass < 2; ++pass)
      for (const Refused& x : refused_)
        if ((std::find(set.begin(), set.end(), x.key) != set.end()) == (pass == 0)) order.push_back(&x);
    for (const Refused* p : order) {
      const Refused& x = *p;
      if (combinations > kMostJointReads)
        fail_at(x.reader, x.key, x.index, "is " + x.value.text() + ", refused by the scene: " + x.why);
      const bool searched = x.key == spec_.search.knob;
      for (long i = 0; i < combinations; ++i) {
        const SweepCase c = sweep_case(one, static_cast<int>(i));
        const auto own = std::find_if(c.set.begin(), c.set.end(), [&](const SweepSetting& s) { return s.first == x.key; });
        if (own != c.set.end() && own->second.text() != x.value.text()) continue;  // a case without this value
        try {
          SceneChanges changes(*spec_.sources[static_cast<std::size_t>(c.scene)]);
          if (own == c.set.end() && !searched) set_knob(spec_.run, x.key, x.value, changes);
          for (const SweepSetting& s : c.set) set_knob(spec_.run, s.first, s.second, changes);
          if (searched) set_knob(spec_.run, x.key, x.value, changes);
          (void)changes.read();
        } catch (const std::exception& e) {
          std::string with;
          for (const SweepSetting& s : c.set)
            if (s.first != x.key) with += (with.empty() ? " with " : ", ") + s.first + " = " + s.second.text();
          fail_at(x.reader, x.key, x.index, "is " + x.value.text() + ", refused by the scene" + with + ": " + e.what());
        }
      }
    }
  }

  // The knobs given in a mapping (a grid, the search), each a list of values, in the mapping's order.
  std::vector<SweepAxis> axes(SectionReader& r, const YAML::Node& node) {
    std::vector<SweepAxis> axes;
    for (const auto& kv : node) {
      const std::string knob = kv.first.Scalar();
      const Declaration d = values(r, knob);
      const YAML::Node list = kv.second;
      if (!list.IsSequence() || list.size() == 0) r.fail(knob, "must be a list of values (" + d.field + ")");
      SweepAxis a{knob, {}};
      for (std::size_t i = 0; i < list.size(); ++i) a.values.push_back(value(r, knob, static_cast<long>(i), list[i], d));
      axes.push_back(a);
    }
    r.finish();
    return axes;
  }

  // Perturbations: each knob drawn in [min, max].
  void draws(SectionReader& p, const YAML::Node& node, std::vector<SweepDraw>& out) {
    for (const auto& kv : node) {
      const std::string knob = kv.first.Scalar();
      const Declaration d = values(p, knob);
      if (d.type == Declaration::Type::choice) p.fail(knob, "takes a name: it cannot be drawn");
      const YAML::Node range = kv.second;
      if (!range.IsSequence() || range.size() != 2 || !range[0].IsScalar() || !range[1].IsScalar())
        p.fail(knob, "must be [min, max], each " + allowed(d, 0) + " (" + d.field + ")");
      const double min = value(p, knob, 0, range[0], d).number, max = value(p, knob, 1, range[1], d).number;
      if (max < min) p.fail(knob, "max " + format_number(max) + " is below min " + format_number(min));
      out.push_back(SweepDraw{knob, min, max, d.type == Declaration::Type::whole});
    }
  }

 private:
  struct Refused {
    SectionReader reader;  // where the value was given (errors name its line)
    std::string key;
    long index;
    SweepValue value;
    std::string why;  // the first scene's reason
  };
  // A joint read is a scene read (its path's effort check included: some 10 ms): beyond this many
  // combinations a value refused alone is refused, as it was before the joint check.
  static constexpr long kMostJointReads = 1000;
  const SweepSpec& spec_;
  std::set<std::string> checked_;  // knob=value pairs already read by the scenes
  std::vector<Refused> refused_;
};

}  // namespace

std::string SweepValue::text() const {
  if (type == Type::name) return name;
  if (type == Type::number) return format_number(number);
  std::string s;
  for (double x : list) s += (s.empty() ? "" : " ") + format_number(x);
  return s;
}

nlohmann::json SweepValue::to_json() const {
  if (type == Type::name) return name;
  if (type == Type::number) return number;
  return list;
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

bool SweepSpec::draws(const std::string& knob) const {
  return std::any_of(perturbations.begin(), perturbations.end(), [&knob](const SweepDraw& d) { return d.knob == knob; });
}

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
// FNV-1a (64 bit) of the spec's text, then each scene's text and its machine's (the file it names, or
// the built-in machine's text), each as read once, as 16 hex digits: what a shard line carries so that
// the merge can tell a line of this spec from one of another or an edited one.
std::string content_digest(const std::string& spec_text, const std::vector<std::shared_ptr<const SceneSource>>& scenes) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  const auto add = [&h](const std::string& text) {
    for (const char c : text) h = (h ^ static_cast<unsigned char>(c)) * 0x100000001b3ULL;
    h = (h ^ 0xFF) * 0x100000001b3ULL;  // the end of a file: so that bytes moved between files count
  };
  add(spec_text);
  for (const std::shared_ptr<const SceneSource>& scene : scenes) {
    add(scene->scene.text());
    add(scene->machine.document.text());
  }
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}
}  // namespace

SweepSpec load_sweep_spec(const std::string& path, const SceneChoice& scenes) {
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
  if (scenes) spec.scenes = scenes(spec.scenes);
  // Each scene and its machine file read once, here: the knobs' values are read by their readers.
  for (const std::string& scene_path : spec.scenes)
    spec.sources.push_back(std::make_shared<const SceneSource>(load_scene_source(scene_path)));
  s.choice("run", spec.run, kSweepRuns, "what one run of a case is");
  s.choices("controllers", spec.controllers, control::controller_registry(), 1, "the controllers each case runs");
  s.whole("cases", spec.cases, 1, 1e6, "", "seeded random draws per grid point and variant, case i from (seed, i)");
  s.whole("seed", spec.seed, 0, 4e9, "", "the draws' seed");
  s.flag("paired_draws", spec.paired_draws,
         "every grid point and variant of a scene runs the same draws (and faults), to compare them pair by pair");
  if (s.given("duration")) s.number("duration", spec.duration, {1e-3, 3600}, "s", "per run (absent: the scene's)");
  s.flag("stop_at_safe_state", spec.stop_at_safe_state, "end each run at the firmware's first safe stop");
  SectionReader w = s.section("window", "open loop: the task's window the effort profile covers");
  w.number("start", spec.window_start, {0, 3600}, "s", "of the task where the window starts");
  w.number("horizon", spec.window_horizon, {0.01, 3600}, "s", "simulated");
  w.finish();
  KnobReader knobs(spec);
  SectionReader p = s.section("perturbations", "each knob drawn uniformly in [min, max] per case");
  if (p.present()) knobs.draws(p, raw["perturbations"], spec.perturbations);
  p.finish();
  s.choices("faults", spec.faults, kFaultKinds, 0, "one fault per case, its kind drawn from the list");
  if (s.given("grid")) {
    if (raw["grid"].IsSequence()) {
      s.sections("grid", 1, 1000, "grids run one after the other", [&](SectionReader& g, std::size_t i) {
        spec.grids.push_back(knobs.axes(g, raw["grid"][i]));
      });
    } else {
      SectionReader g = s.section("grid", "lists of values, crossed");
      spec.grids.push_back(knobs.axes(g, raw["grid"]));
    }
    for (const SweepGrid& g : spec.grids)
      if (g.empty()) s.fail("grid", "a grid names no knob");
  }
  s.sections("variants", 0, 10000, "named cases", [&](SectionReader& v, std::size_t i) {
    SweepVariant variant;
    v.text("name", variant.name, "the variant's short name", Need::required);
    v.text("description", variant.description, "what is changed, in words");
    for (const auto& kv : raw["variants"][i]) {
      const std::string knob = kv.first.Scalar();
      if (knob == "name" || knob == "description") continue;
      variant.values.push_back({knob, knobs.value(v, knob, -1, kv.second, knobs.values(v, knob))});
    }
    spec.variants.push_back(variant);
  });
  if (s.given("search")) {
    SectionReader q = s.section("search", "one knob: per case, the first of its values whose run passes");
    const std::vector<SweepAxis> axes = knobs.axes(q, raw["search"]);
    if (axes.size() != 1) s.fail("search", "must name exactly one knob");
    spec.search = axes.front();
  }
  s.choices("record", spec.record, kSweepRecords, 1, "what the merge writes");
  // A knob is either drawn or set, and set by one of grid, variants and search.
  const std::vector<std::string> set = spec.set_knobs();
  if (!spec.search.knob.empty() && spec.draws(spec.search.knob))
    s.fail("perturbations", "'" + spec.search.knob + "' is drawn here and searched: choose one");
  for (const std::string& k : set) {
    if (spec.draws(k)) s.fail("perturbations", "'" + k + "' is drawn here and set by the grid or a variant: choose one");
    if (k == spec.search.knob) s.fail("search", "'" + k + "' is searched and set by the grid or a variant: choose one");
    if (!spec.grids.empty() && !spec.variants.empty())
      for (const SweepVariant& v : spec.variants)
        for (const SweepSetting& vs : v.values)
          for (const SweepGrid& g : spec.grids)
            for (const SweepAxis& a : g)
              if (a.knob == vs.first) s.fail("variants", "'" + vs.first + "' is set by the grid and by variant " + v.name);
  }
  // Two knobs writing one setting (or one inside the other) whole: the later would undo the earlier.
  std::vector<std::string> all = set;
  for (const SweepDraw& d : spec.perturbations) all.push_back(d.knob);
  if (!spec.search.knob.empty()) all.push_back(spec.search.knob);
  const auto inside = [](const std::string& a, const std::string& b) {  // a is b or a setting within b
    return a.compare(0, b.size(), b) == 0 && (a.size() == b.size() || a[b.size()] == '.');
  };
  for (std::size_t i = 0; i < all.size(); ++i)
    for (std::size_t j = i + 1; j < all.size(); ++j)
      for (const std::string& a : knob_writes(spec.run, all[i]))
        for (const std::string& b : knob_writes(spec.run, all[j]))
          if (inside(a, b) || inside(b, a))
            s.fail_here("'" + all[i] + "' and '" + all[j] + "' both write " + (a.size() < b.size() ? a : b) +
                        " (the later one would undo the other): choose one");
  knobs.check_refused();
  if (spec.total_cases() > 10'000'000) s.fail_here("more than 10 million cases");
  s.finish();
  top.finish();
  spec.digest = content_digest(doc.text(), spec.sources);
  return spec;
}

SweepCase sweep_case(const SweepSpec& spec, int id) {
  // id = ((scene * variants + variant) * points + point) * cases + draw.
  SweepCase c;
  c.id = id;
  int rest = id / spec.cases;
  const int points = spec.grid_points(), variants = std::max<int>(1, static_cast<int>(spec.variants.size()));
  int point = rest % points;
  rest /= points;
  c.variant = spec.variants.empty() ? -1 : rest % variants;
  c.scene = rest / variants;
  // One generator per case, seeded from (seed, id): independent of which shard runs the case. Paired,
  // from (seed, scene, draw): the same for every grid point and variant of the scene.
  std::seed_seq unpaired{spec.seed, static_cast<unsigned>(id), 0x5eedu};
  std::seed_seq paired{spec.seed, static_cast<unsigned>(c.scene), static_cast<unsigned>(id % spec.cases), 0xda12u};
  std::mt19937_64 rng(spec.paired_draws ? paired : unpaired);
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
  for (const SweepDraw& d : spec.perturbations) {
    double x = d.min + (d.max - d.min) * std::uniform_real_distribution<double>(0.0, 1.0)(rng);
    if (d.whole) x = std::floor(x + 0.5);
    c.drawn.push_back({d.knob, SweepValue{SweepValue::Type::number, x, {}, ""}});
  }
  if (!spec.faults.empty()) draw_fault(rng, spec.faults, c);
  return c;
}

SceneBundle case_bundle(const SweepSpec& spec, const SweepCase& c, const SweepSetting* searched) {
  SceneChanges changes(*spec.sources[static_cast<std::size_t>(c.scene)]);
  for (const std::vector<SweepSetting>* values : {&c.drawn, &c.set})
    for (const SweepSetting& v : *values) set_knob(spec.run, v.first, v.second, changes);
  if (searched != nullptr) set_knob(spec.run, searched->first, searched->second, changes);
  return changes.read();
}

}  // namespace exc::sim
