#pragma once
// Sweeps: many runs of one or more scenes, numbered deterministically, run in shards that any engine
// can schedule (GNU parallel, Slurm job arrays, a plain loop) and merged afterwards (docs/sweeps.md).
//
//   sweep:
//     scenes: [../scenes/dig.yaml]    # relative to the spec file (or scene: one file)
//     controllers: [pid, adaptive]    # each case runs with each
//     run: closed_loop                # or open_loop: excavator-bench's effort profile, plant alone
//     cases: 1000                     # seeded random draws per grid point and variant
//     seed: 1
//     duration: 10                    # s per run (default: the scene's)
//     perturbations:                  # drawn uniformly in [min, max] per case, in this order
//       model_mass: [-0.2, 0.2]
//     grid:                           # lists of values, crossed (first key slowest); a list of such
//       gain_scale: [0.5, 1, 2]       #   mappings runs each one after the other
//     variants:                       # named cases, each a set of values
//       - {name: nominal}
//       - {name: delay2, delay_cycles: 2, description: "sensor frames 2 cycles late"}
//     search: {integrator.step: [1e-2, 1e-3]}   # per case: the first value whose run passes
//     faults: [bus_burst, ...]        # the fault campaign (fault_campaign.hpp): one fault per case
//     record: [failures, robustness, stability]   # the merge's outputs besides the table (default: failures)
//
// A knob names a setting of the scene or its machine by its path, or is one of the named knobs
// (sweep_knobs.hpp); a value is read by the scene's own readers when the spec loads and when the case
// runs (its type, unit and range are the setting's).
//
// Case id = ((scene * variants + variant) * grid points + point) * cases + draw; a case's draws depend
// on (seed, id) only, so a shard computes exactly the cases a single process would, and any set of
// shard files merges into the same table.
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "harness/lockstep_run.hpp"
#include "harness/scene_source.hpp"

namespace exc::sim {

// A knob drawn uniformly in [min, max] per case (a whole-number setting's draw rounded).
struct SweepDraw {
  std::string knob;
  double min = 0, max = 0;
  bool whole = false;
};

// One value of a knob: a number, a list of numbers (a setting that takes one per joint, ...) or a name.
struct SweepValue {
  enum class Type { number, list, name } type = Type::number;
  double number = 0;
  std::vector<double> list;
  std::string name;
  std::string text() const;  // as the table writes it
  nlohmann::json to_json() const;
};
using SweepSetting = std::pair<std::string, SweepValue>;  // knob, value

struct SweepAxis {
  std::string knob;
  std::vector<SweepValue> values;
};
using SweepGrid = std::vector<SweepAxis>;  // crossed, the first axis slowest

struct SweepVariant {
  std::string name, description;
  std::vector<SweepSetting> values;
};

enum class SweepRun : std::uint8_t { closed_loop, open_loop };

struct SweepSpec {
  std::string file;
  std::vector<std::string> scenes;  // absolute paths
  std::vector<std::shared_ptr<const SceneSource>> sources;  // each scene as read once, in the same order
  SweepRun run = SweepRun::closed_loop;
  std::vector<std::string> controllers{"pid", "adaptive"};
  int cases = 1;  // random draws per grid point and variant
  unsigned seed = 1;
  // true: every grid point and variant of a scene runs the same draws (case i's from (seed, scene,
  // i mod cases)), so they compare pair by pair; false: each case its own (from (seed, i)).
  bool paired_draws = false;
  double duration = 0;
  bool stop_at_safe_state = false;  // end a run at the firmware's first safe stop (maps)
  double window_start = 0, window_horizon = 1;  // open loop: s of the task, s simulated
  std::vector<SweepDraw> perturbations;  // drawn in this order
  std::vector<std::string> faults;  // fault kinds to draw from (empty: no fault)
  std::vector<SweepGrid> grids;     // run one after the other
  std::vector<SweepVariant> variants;
  SweepAxis search;                 // knob empty: none
  std::vector<std::string> record{"failures"};
  // The spec file's and its scenes' contents as 16 hex digits: every shard line carries it, and the
  // merge takes only lines that carry this spec's.
  std::string digest;

  int grid_points() const;  // over all grids (1 without a grid)
  int total_cases() const;
  bool records(const std::string& what) const;
  bool draws(const std::string& knob) const;
  // The knobs a case sets (grid axes, then variants' keys, in first-seen order): the table's columns.
  std::vector<std::string> set_knobs() const;
};

// Reads a sweep spec (opened and parsed once; errors name file, line, column and field) and its scenes
// (each file once), and reads every value it sets with the scenes' readers. `scenes`, when given,
// chooses the scenes instead of the spec's list (excavator-sim robustness SCENE, the bench's --scenes).
using SceneChoice = std::function<std::vector<std::string>(const std::vector<std::string>& spec_scenes)>;
SweepSpec load_sweep_spec(const std::string& path, const SceneChoice& scenes = nullptr);

// "I/N" with 0 <= I < N, two whole decimal numbers and nothing else (no sign, blank or overflow).
bool parse_shard(const std::string& text, int& shard, int& shards);

struct SweepCase {
  int id = 0;
  int scene = 0, variant = -1, grid = -1;  // indices into the spec (-1: none)
  std::vector<SweepSetting> set;           // the grid point's and the variant's values
  std::vector<SweepSetting> drawn;         // the perturbations' draws
  std::string fault = "none";
  double fault_start = 0, fault_duration = 0, fault_magnitude = 0;
  int fault_joint = 0;
  const SweepValue* value(const std::string& knob) const;  // null when the case does not set it
};
SweepCase sweep_case(const SweepSpec& spec, int id);
// The case's scene with its draws and set values (and the searched value, when given), read by the
// scene's readers.
SceneBundle case_bundle(const SweepSpec& spec, const SweepCase& c, const SweepSetting* searched = nullptr);

// One case's runs as its shard line: {"case", the draws, "set", and per controller (open loop: "plant")
// {"ok", "failure", "rms_error", "max_error", "outcome", "search_value", ...}}.
using SweepRunner = std::function<nlohmann::json(const SweepSpec&, const SweepCase&)>;
// The closed loop: each controller through run_lockstep on the case's scene and settings.
nlohmann::json run_closed_loop_case(const SweepSpec& spec, const SweepCase& c);
// The same run, its whole record (the robustness table keeps every figure).
RunRecord run_sweep_case(const SweepSpec& spec, const SweepCase& c, const std::string& controller);
nlohmann::json record_json(const RunRecord& r, const app::FirmwareSettings& firmware);

// The progress line of a shard on a terminal: "sweep shard 0/4: 12 of 250 cases, 1 min 04 s elapsed,
// ~21 min 10 s left" (the time left from the mean time per case so far).
std::string sweep_progress_text(int shard, int shards, int done, int count, double elapsed_s);
// Runs the cases id = shard, shard + shards, ... and writes one JSON line per case to `out` (flushed
// as each finishes); with `progress`, on a terminal only, the progress line above, redrawn. Returns
// the number of cases run.
int run_sweep_shard(const SweepSpec& spec, int shard, int shards, const std::filesystem::path& out, bool progress,
                    const SweepRunner& runner = run_closed_loop_case);

// What a merge could not do: cases missing (named in the JSON and on stderr), a chart that failed
// (named on stderr; the table and summary are written either way).
struct MergeOutcome {
  bool complete = true;
  bool charts_ok = true;
  bool consistent = true;  // no case with two different records (runs are deterministic)
  bool ok() const { return complete && charts_ok && consistent; }
};

// Merges shard files (absent ones reported with their cases) into out_dir: sweep.csv, sweep.json
// (missing cases, failures by region) and the charts the spec records.
MergeOutcome merge_sweep(const SweepSpec& spec, const std::vector<std::filesystem::path>& shard_files,
                         const std::filesystem::path& out_dir, bool charts = true);

}  // namespace exc::sim
