// Seeded mutations of every shipped scene, of the machine file and of the sweep specs, loaded as
// excavator-sim loads them and, when accepted, run (a scene for 3 s, past the start-up and into the
// task; a sweep's first and last case for 0.3 s): each is refused with an error naming its file, or
// it runs and ends ok with finite figures or says why it failed. Never a crash, an exception that is
// not a std::exception, a message without the file, or a NaN in an accepted run's figures.
#include <doctest/doctest.h>
#include <unistd.h>

#include <cmath>
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <random>
#include <regex>
#include <string>
#include <vector>

#include "harness/lockstep_run.hpp"
#include "scratch_files.hpp"
#include "sweep.hpp"
#include "text_file.hpp"

namespace fs = std::filesystem;

namespace {

// Values a typing slip, a copy from another unit or a hostile file puts where a number belongs.
const char* const kValues[] = {"0",     "-1",    "-0.001", "1e308", "-1e308", "1e-320", ".nan", ".inf",
                               "-.inf", "1e400", "abc",    "[]",    "{}",     "~",      "\"1\"", "2.5e3",
                               "[1, 2]", "0x10", "1_000",  "true",  "-7",     "1e6",    "3",     "-3"};

struct Mutant {
  std::string text;
  std::string what;  // the mutation, for the failure message
};

// One mutation of `text`: a number replaced by one of kValues, a line deleted or repeated, a key
// misspelt, or the file cut short.
Mutant mutate(const std::string& text, std::mt19937_64& rng) {
  std::vector<std::string> lines;
  {
    std::size_t start = 0;
    while (start <= text.size()) {
      const std::size_t end = text.find('\n', start);
      lines.push_back(text.substr(start, end == std::string::npos ? std::string::npos : end - start));
      if (end == std::string::npos) break;
      start = end + 1;
    }
  }
  auto join = [&]() {
    std::string out;
    for (const std::string& l : lines) out += l + "\n";
    return out;
  };
  auto pick = [&](std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng); };
  const int kind = static_cast<int>(pick(10));
  if (kind < 6) {
    // A number (outside comments) replaced.
    static const std::regex number(R"([-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?)");
    std::vector<std::pair<std::size_t, std::smatch>> found;
    for (std::size_t i = 0; i < lines.size(); ++i) {
      const std::string code = lines[i].substr(0, lines[i].find('#'));
      for (std::sregex_iterator it(code.begin(), code.end(), number), end; it != end; ++it) found.push_back({i, *it});
    }
    if (!found.empty()) {
      const auto& [line, m] = found[pick(found.size())];
      const std::string value = kValues[pick(std::size(kValues))];
      const std::string before = lines[line];
      lines[line] = before.substr(0, static_cast<std::size_t>(m.position())) + value +
                    before.substr(static_cast<std::size_t>(m.position() + m.length()));
      return {join(), "line " + std::to_string(line + 1) + ": '" + before + "' -> '" + lines[line] + "'"};
    }
  }
  const std::size_t line = pick(lines.size());
  if (kind == 6) {
    const std::string gone = lines[line];
    lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(line));
    return {join(), "line " + std::to_string(line + 1) + " deleted: '" + gone + "'"};
  }
  if (kind == 7) {
    lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(line), lines[line]);
    return {join(), "line " + std::to_string(line + 1) + " repeated: '" + lines[line] + "'"};
  }
  if (kind == 8) {
    const std::size_t colon = lines[line].find(':');
    if (colon != std::string::npos && colon > 0) {
      const std::string before = lines[line];
      lines[line].insert(colon, "x");
      return {join(), "line " + std::to_string(line + 1) + ": key misspelt: '" + lines[line] + "'"};
    }
  }
  const std::size_t cut = pick(text.size());
  return {text.substr(0, cut), "cut after byte " + std::to_string(cut)};
}

// The message of what `load` throws, none when it does not. (Anything but a std::exception reaches
// doctest, which fails the case.)
template <class Load>
std::optional<std::string> error_of(Load&& load) {
  try {
    load();
  } catch (const std::exception& e) {
    return std::string(e.what());
  }
  return std::nullopt;
}

bool run_figures_finite(const exc::sim::RunRecord& r) {
  for (int j = 0; j < 4; ++j)
    if (!std::isfinite(r.rms_error[j]) || !std::isfinite(r.max_error[j])) return false;
  for (double t : r.theta_hat)
    if (!std::isfinite(t)) return false;
  return std::isfinite(r.peak_soil_force) && std::isfinite(r.simulated_seconds);
}

struct Tally {
  int refused = 0, ran_ok = 0, ran_failed = 0;
};

// Whether `load` refused its file; a refusal must name one of `files`, and is counted.
template <class Load>
bool refused_naming(Load&& load, const std::vector<fs::path>& files, Tally& tally) {
  const std::optional<std::string> error = error_of(load);
  if (!error) return false;
  INFO("error: " << *error);
  bool named = false;
  for (const fs::path& f : files) named = named || error->find(f.string()) != std::string::npos;
  CHECK(named);
  ++tally.refused;
  return true;
}

// Loads `path` and runs it for 3 s if accepted. An error must name one of `files`: the
// mutated file, or the scene when the mutated machine file is valid and the scene's task no longer
// fits it.
void check_mutant(const fs::path& path, const std::vector<fs::path>& files, const std::string& what, Tally& tally) {
  INFO(files.front().filename().string() << ": " << what);
  exc::sim::SceneBundle bundle;
  if (refused_naming([&] { bundle = exc::sim::load_scene_bundle(path.string()); }, files, tally)) return;
  exc::sim::LockstepOptions options;
  options.controller = bundle.firmware.controller.law;
  options.duration = std::min(3.0, bundle.scene.duration);  // past the start-up, into the task
  options.stop_at_safe_state = true;
  try {
    const exc::sim::RunRecord r = exc::sim::run_lockstep(bundle.scene, bundle.firmware, options);
    INFO("run failure: " << r.failure);
    if (r.ok) {
      CHECK(run_figures_finite(r));
      if (std::getenv("EXC_MUTANTS_ACCEPTED") != nullptr) MESSAGE("accepted: " << what);
      ++tally.ran_ok;
    } else {
      CHECK_FALSE(r.failure.empty());
      if (std::getenv("EXC_MUTANTS") != nullptr) MESSAGE("failed as it should say: " << what << ": " << r.failure);
      ++tally.ran_failed;
    }
  } catch (const std::exception& e) {
    // A run may refuse what only its start can check (the initial state's assembly): said, not silent.
    const std::string message = e.what();  // (doctest would print a char pointer's address)
    INFO("run refused: " << message);
    CHECK_FALSE(message.empty());
    if (std::getenv("EXC_MUTANTS") != nullptr) MESSAGE("run refused: " << what << ": " << message);
    ++tally.ran_failed;
  }
}

// Per scene (the machine file gets twice as many). EXC_MUTANTS overrides it for a longer search.
// Under the address or thread sanitizer (2-15x slower) the sweep specs' mutants are a quarter of
// them, so that the case stays within its time: the mutations are seeded, the same first ones.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr int kInstrumentedShare = 4;
#else
constexpr int kInstrumentedShare = 1;
#endif

int mutants_per_file() {
  const char* env = std::getenv("EXC_MUTANTS");
  return env != nullptr ? std::max(1, std::atoi(env)) : 60;
}

}  // namespace

TEST_CASE("tools/settings: seeded mutations of every shipped scene are refused naming the scene, or run 3 s with finite figures or a stated failure") {
  const fs::path dir = exc::test::scratch_dir(fs::path(EXC_BINARY_DIR) / "tests" / "sim" /
                                              ("mutations_" + std::to_string(getpid())));
  Tally tally;
  std::uint64_t seed = 1;
  for (const char* scene : {"dig.yaml", "free_motion.yaml", "truck_loading.yaml", "paper_dig.yaml", "paper_free_motion.yaml"}) {
    const std::string text = exc::test::read_text_file(fs::path(EXC_SOURCE_DIR) / "scenes" / scene);
    REQUIRE(!text.empty());
    std::mt19937_64 rng(seed++);
    for (int k = 0; k < mutants_per_file(); ++k) {
      const Mutant m = mutate(text, rng);
      const fs::path path = dir / ("mutant_" + std::to_string(k) + "_" + scene);
      std::ofstream(path) << m.text;
      check_mutant(path, {path}, m.what, tally);
    }
  }
  MESSAGE("scenes: " << tally.refused << " refused, " << tally.ran_ok << " ran ok, " << tally.ran_failed << " ran and failed");
  // The mutations reach both paths: most are refused, some are harmless edits that run.
  CHECK(tally.refused > 0);
  CHECK(tally.ran_ok + tally.ran_failed > 0);
}

TEST_CASE("tools/settings: seeded mutations of the machine file are refused naming it or the scene, or run 3 s with finite figures or a stated failure") {
  const fs::path dir = exc::test::scratch_dir(fs::path(EXC_BINARY_DIR) / "tests" / "sim" /
                                              ("machine_mutations_" + std::to_string(getpid())));
  const std::string machine = exc::test::read_text_file(fs::path(EXC_SOURCE_DIR) / "machines" / "reference-20t.yaml");
  const std::string dig = exc::test::read_text_file(fs::path(EXC_SOURCE_DIR) / "scenes" / "dig.yaml");
  REQUIRE(!machine.empty());
  REQUIRE(dig.find("\nmachine:") == std::string::npos);
  Tally tally;
  std::mt19937_64 rng(101);
  for (int k = 0; k < 2 * mutants_per_file(); ++k) {
    const Mutant m = mutate(machine, rng);
    const fs::path machine_path = dir / ("machine_" + std::to_string(k) + ".yaml");
    const fs::path scene_path = dir / ("scene_" + std::to_string(k) + ".yaml");
    std::ofstream(machine_path) << m.text;
    std::ofstream(scene_path) << "machine: " << machine_path.filename().string() << "\n" << dig;
    check_mutant(scene_path, {machine_path, scene_path}, m.what, tally);
  }
  MESSAGE("machine file: " << tally.refused << " refused, " << tally.ran_ok << " ran ok, " << tally.ran_failed
                           << " ran and failed");
  CHECK(tally.refused > 0);
  CHECK(tally.ran_ok + tally.ran_failed > 0);
}

// Found by the mutations above: a check on a generated field (the truck cycle's knots, task.cycle)
// was placed by looking the field up in the file, and the lookup of a key the file does not have
// threw yaml-cpp's "invalid node" with no file, line or field.
TEST_CASE("tools/settings: a truck cycle whose dump leaves the bucket's stroke is refused at the task's line, naming the generated cycle") {
  const fs::path dir = exc::test::scratch_dir(fs::path(EXC_BINARY_DIR) / "tests" / "sim" /
                                              ("truck_cycle_" + std::to_string(getpid())));
  std::string text = exc::test::read_text_file(fs::path(EXC_SOURCE_DIR) / "scenes" / "truck_loading.yaml");
  const std::string from = "open_pitch_deg: 50";
  const auto at = text.find(from);
  REQUIRE(at != std::string::npos);
  text.replace(at, from.size(), "open_pitch_deg: 1");
  const fs::path path = dir / "truck_loading.yaml";
  std::ofstream(path) << text;
  const std::string message = error_of([&] { (void)exc::sim::load_scene_bundle(path.string()); }).value_or("");
  INFO(message);
  CHECK(message.rfind(path.string() + ":", 0) == 0);  // file:line:column first
  CHECK(message.find("task.cycle[") != std::string::npos);
  CHECK(message.find("bucket cylinder length") != std::string::npos);
  CHECK(message.find("invalid node") == std::string::npos);
}

namespace {
// A sweep case's line: each controller's run ok with finite (or no) figures, or failed saying why.
bool case_line_sound(const nlohmann::json& line, const std::vector<std::string>& controllers, std::string& why) {
  for (const std::string& name : controllers) {
    if (!line.contains(name)) return why = "no entry for " + name, false;
    const nlohmann::json& run = line[name];
    if (run.value("ok", false)) {
      for (const char* key : {"rms_error", "max_error"})
        if (run.contains(key))
          for (const auto& v : run[key])
            if (!v.is_null() && !(v.is_number() && std::isfinite(v.get<double>())))
              return why = name + "." + key + " holds " + v.dump(), false;
    } else if (run.value("failure", std::string()).empty()) {
      return why = name + " failed without a reason: " + run.dump(), false;
    }
  }
  return true;
}
}  // namespace

TEST_CASE("tools/sweep: seeded mutations of every shipped sweep spec are refused naming the spec, or number their cases and run the first and last with finite figures or a stated failure") {
  const fs::path dir = exc::test::scratch_dir(fs::path(EXC_BINARY_DIR) / "tests" / "sim" /
                                              ("sweep_mutations_" + std::to_string(getpid())));
  const std::string scenes = (fs::path(EXC_SOURCE_DIR) / "scenes").string() + "/";
  Tally tally;
  std::uint64_t seed = 1001;
  for (const auto& entry : fs::directory_iterator(fs::path(EXC_SOURCE_DIR) / "sweeps")) {
    if (entry.path().extension() != ".yaml") continue;
    std::string text = exc::test::read_text_file(entry.path());
    // The specs name their scenes relative to sweeps/: the mutants live elsewhere.
    for (std::size_t at = text.find("../scenes/"); at != std::string::npos; at = text.find("../scenes/", at))
      text.replace(at, 10, scenes);
    std::mt19937_64 rng(seed++);
    const int mutants = std::max(1, mutants_per_file() / 3 / kInstrumentedShare);
    for (int k = 0; k < mutants; ++k) {
      const Mutant m = mutate(text, rng);
      const fs::path path = dir / ("mutant_" + std::to_string(k) + "_" + entry.path().filename().string());
      std::ofstream(path) << m.text;
      INFO(entry.path().filename().string() << ": " << m.what);
      exc::sim::SweepSpec spec;
      if (refused_naming([&] { spec = exc::sim::load_sweep_spec(path.string()); }, {path}, tally)) continue;
      const int total = spec.total_cases();
      REQUIRE(total > 0);
      if (spec.run != exc::sim::SweepRun::closed_loop) {
        (void)exc::sim::sweep_case(spec, total - 1);
        ++tally.ran_ok;
        continue;
      }
      spec.duration = 0.3;
      for (const int id : {0, total - 1}) {
        try {
          const nlohmann::json line = exc::sim::run_closed_loop_case(spec, exc::sim::sweep_case(spec, id));
          std::string why;
          INFO("case " << id << ": " << line.dump());
          CHECK_MESSAGE(case_line_sound(line, spec.controllers, why), why);
          ++tally.ran_ok;
        } catch (const std::exception& e) {
          const std::string message = e.what();  // (doctest would print a char pointer's address)
          INFO("case " << id << " refused: " << message);
          CHECK_FALSE(message.empty());
          if (std::getenv("EXC_MUTANTS") != nullptr) MESSAGE("case refused: " << m.what << ": " << message);
          ++tally.ran_failed;
        }
      }
    }
  }
  // Directed: a scene that is not a file is refused at the spec's line (found by the mutations: it
  // was accepted, and the first case's run named the scene alone).
  for (const auto& [line, problem] : {std::pair<std::string, std::string>{"scene: " + scenes + "dig.y", "no such file"},
                                      {"scenes: [" + scenes + "dig.yaml, " + scenes + "]", "is a directory"}}) {
    const fs::path path = dir / "bad_scene.yaml";
    std::ofstream(path) << "sweep:\n  " << line << "\n  controllers: [pid]\n";
    const std::string message = error_of([&] { (void)exc::sim::load_sweep_spec(path.string()); }).value_or("");
    INFO(message);
    CHECK(message.rfind(path.string() + ":2:", 0) == 0);
    CHECK(message.find(problem) != std::string::npos);
  }
  MESSAGE("sweep specs: " << tally.refused << " refused, " << tally.ran_ok << " cases ran, " << tally.ran_failed
                          << " cases refused at their run");
  CHECK(tally.refused > 0);
  CHECK(tally.ran_ok > 0);
}

// Found by the mutations above: `seed: ~` ran with the default seed, as if the key were absent.
TEST_CASE("tools/settings: a key left without a value (empty, ~ or null) is refused at its line in a scene, the machine file and a sweep spec, and an empty section still takes its defaults") {
  const fs::path dir = exc::test::scratch_dir(fs::path(EXC_BINARY_DIR) / "tests" / "sim" /
                                              ("no_value_" + std::to_string(getpid())));
  const std::string dig = exc::test::read_text_file(fs::path(EXC_SOURCE_DIR) / "scenes" / "dig.yaml");
  const std::string from = "  seed: 1\n";
  REQUIRE(dig.find(from) != std::string::npos);
  const auto line_of = [](const std::string& text, const std::string& what) {
    return 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(text.find(what)), '\n');
  };
  for (const char* none : {"", " ~", " null"}) {
    std::string text = dig;
    text.replace(text.find(from), from.size(), std::string("  seed:") + none + "\n");
    const fs::path path = dir / "scene.yaml";
    std::ofstream(path) << text;
    const std::string message = error_of([&] { (void)exc::sim::load_scene_bundle(path.string()); }).value_or("");
    INFO("seed:" << std::string(none) << " -> " << message);
    CHECK(message.rfind(path.string() + ":" + std::to_string(line_of(dig, from)) + ":", 0) == 0);
    CHECK(message.find("sensors.seed: has no value") != std::string::npos);
  }
  // The machine file: a link's mass.
  const std::string machine = exc::test::read_text_file(fs::path(EXC_SOURCE_DIR) / "machines" / "reference-20t.yaml");
  const std::string mass = "mass: 70,";
  REQUIRE(machine.find(mass) != std::string::npos);
  std::string empty_mass = machine;
  empty_mass.replace(empty_mass.find(mass), mass.size(), "mass: ~,");
  std::ofstream(dir / "machine.yaml") << empty_mass;
  std::ofstream(dir / "with_machine.yaml") << "machine: machine.yaml\n" << dig;
  const std::string machine_error = error_of([&] { (void)exc::sim::load_scene_bundle((dir / "with_machine.yaml").string()); }).value_or("");
  INFO(machine_error);
  CHECK(machine_error.find((dir / "machine.yaml").string() + ":" + std::to_string(line_of(machine, mass)) + ":") !=
        std::string::npos);
  CHECK(machine_error.find(".mass: has no value") != std::string::npos);
  // A sweep spec: its case count.
  const fs::path spec = dir / "spec.yaml";
  std::ofstream(spec) << "sweep:\n  scene: " << (fs::path(EXC_SOURCE_DIR) / "scenes" / "dig.yaml").string()
                      << "\n  cases:\n  controllers: [pid]\n";
  const std::string spec_error = error_of([&] { (void)exc::sim::load_sweep_spec(spec.string()); }).value_or("");
  INFO(spec_error);
  CHECK(spec_error.rfind(spec.string() + ":3:", 0) == 0);
  CHECK(spec_error.find("sweep.cases: has no value") != std::string::npos);
  // The controls: an empty section takes its defaults; the scene as shipped loads.
  std::string empty_section = dig;
  const std::string terrain = "terrain: {height: 0.0}\n";
  REQUIRE(empty_section.find(terrain) != std::string::npos);
  empty_section.replace(empty_section.find(terrain), terrain.size(), "terrain:\n");
  std::ofstream(dir / "empty_section.yaml") << empty_section;
  CHECK_FALSE(error_of([&] { (void)exc::sim::load_scene_bundle((dir / "empty_section.yaml").string()); }).has_value());
  CHECK_FALSE(error_of([&] { (void)exc::sim::load_scene_bundle((fs::path(EXC_SOURCE_DIR) / "scenes" / "dig.yaml").string()); }).has_value());
}
