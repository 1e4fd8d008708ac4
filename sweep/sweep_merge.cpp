// The merge of a sweep's shard files: the table (a row per case), the summary (missing cases and
// shard files, failures by region, the fault campaign's outcomes) and the charts the spec records.
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <fstream>
#include <map>
#include <regex>
#include <stdexcept>

#include "output_files/helper_program.hpp"
#include "output_files/output_file.hpp"
#include "report/run_report.hpp"
#include "fault_campaign.hpp"
#include "sweep.hpp"

namespace exc::sim {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const char* const kJoints[4] = {"swing", "boom", "arm", "bucket"};

// A number of a shard line as the table writes it: empty when absent or null (never "nan").
std::string cell(const json& j) {
  if (!j.is_number()) return "";
  std::ostringstream o;
  o.precision(17);
  o << j.get<double>();
  return o.str();
}

std::string quoted(const std::string& s) {
  std::string q = "\"";
  for (char ch : s) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return q + "\"";
}

// The kind of a failure without its numbers: which check of the plant, which fault of the firmware.
std::string failure_kind(const std::string& f) {
  auto head = [](const std::string& s) { return s.substr(0, s.find_first_of(":(;0123456789")); };
  if (f.rfind("plant stopped: ", 0) == 0) return "plant: " + head(f.substr(15));
  const auto last = f.find("the last for ");
  if (last != std::string::npos) return "firmware safe state: " + head(f.substr(last + 13));
  return head(f);
}

// The Monte-Carlo draws' regions: the perturbation that was largest relative to its range.
std::string draw_region(const json& j) {
  const double stiff = j["soil_stiffness"].get<double>(), mass = std::abs(j["model_mass"].get<double>());
  return stiff >= 2 ? "soil stiffness >= 2x" : mass >= 0.15 ? "model mass error >= 15 %"
         : j["delay_cycles"].get<int>() >= 2 ? "delay >= 2 cycles" : "elsewhere";
}

std::vector<std::string> run_columns(const SweepSpec& spec) {
  return spec.run == SweepRun::open_loop ? std::vector<std::string>{"plant"} : spec.controllers;
}

// Why a shard line is not a record of one of this spec's cases, "" when it is one: its spec digest,
// its case number, and the type of every field the table, the regions and the campaign read (a
// const json read where a field is missing is undefined behaviour, a wrong type an exception).
std::string record_problem(const SweepSpec& spec, const json& j) {
  if (!j.is_object()) return "not a JSON object";
  const auto digest = j.find("spec");
  if (digest == j.end() || !digest->is_string()) return "no spec digest (a shard of an older excavator-sim?)";
  if (*digest != spec.digest)
    return "of another spec, or of this one before it, its scenes or their machine files were edited (spec digest " +
           digest->get<std::string>() + ", this spec's " + spec.digest + ")";
  const auto id = j.find("case");
  if (id == j.end() || !id->is_number_integer() || id->get<long long>() < 0 || id->get<long long>() >= spec.total_cases())
    return "its case is not a whole number in [0, " + std::to_string(spec.total_cases()) + ")";
  const auto is = [&](const json& o, const char* key, bool (json::*type)() const noexcept) {
    return !o.contains(key) || (o[key].*type)();
  };
  for (const SweepDraw& d : spec.perturbations)
    if (!j.contains(d.knob) || !j[d.knob].is_number()) return "its " + d.knob + " is not a number";
  if (!is(j, "scene", &json::is_string) || (spec.scenes.size() > 1 && !j.contains("scene"))) return "no scene name";
  if (!is(j, "variant", &json::is_string)) return "its variant is not a name";
  if (j.contains("fault")) {
    const json& f = j["fault"];
    if (!f.is_object() || !(f.contains("kind") && f["kind"].is_string()) || !(f.contains("start") && f["start"].is_number()))
      return "its fault has no kind or start";
  }
  for (const std::string& name : run_columns(spec)) {
    if (!j.contains(name) || !j[name].is_object()) return "no result of run '" + name + "'";
    const json& r = j[name];
    if (!(r.contains("ok") && r["ok"].is_boolean())) return "run '" + name + "' has no ok (true or false)";
    // rms_error: one figure per joint, or null for a run that never tracked.
    const bool rms_ok = !r.contains("rms_error") || r["rms_error"].is_null() || r["rms_error"].is_object();
    if (!rms_ok || !is(r, "failure", &json::is_string) || !is(r, "outcome", &json::is_string) ||
        !is(r, "safe_state_time", &json::is_number) || !is(r, "fault_detected_time", &json::is_number))
      return "run '" + name + "' has a field of the wrong type";
  }
  return "";
}

// Reads the shard files' lines into `cases`; a file that is not there is named with its cases when
// its name tells its shard (shard-I.jsonl of the N given, or shard-I-of-N.jsonl). A line that is not
// a record of this spec's cases is named and left out (in `ignored`), and so is a second record of a
// case (in `conflicts` when it differs from the first).
json read_shards(const SweepSpec& spec, const std::vector<fs::path>& files, std::map<int, json>& cases,
                 json& ignored, json& conflicts) {
  json absent = json::array();
  const std::regex shard_name(R"(.*?(\d+)(?:-of-(\d+))?)");
  for (const fs::path& f : files) {
    std::ifstream in(f);
    if (!in) {
      json entry = {{"file", f.string()}};
      std::smatch m;
      const std::string stem = f.stem().string();
      int i = 0, n = 0;
      // The shard its name tells, when it does (a number too long for an int tells none).
      if (std::regex_match(stem, m, shard_name) &&
          parse_shard(m[1].str() + "/" + (m[2].matched ? m[2].str() : std::to_string(files.size())), i, n)) {
        json ids = json::array();
        for (int id = i; id < spec.total_cases(); id += n) ids.push_back(id);
        entry["shard"] = std::to_string(i) + "/" + std::to_string(n);
        entry["cases"] = ids;
      }
      std::fprintf(stderr, "sweep merge: shard file %s is not there%s\n", f.string().c_str(),
                   entry.contains("shard") ? (" (shard " + entry["shard"].get<std::string>() + ": its cases are missing)").c_str() : "");
      absent.push_back(entry);
      continue;
    }
    std::string line;
    int n = 0, ignored_here = 0, conflicts_here = 0;
    constexpr int kNamedPerFile = 3;
    while (std::getline(in, line)) {
      ++n;
      if (line.empty()) continue;
      const std::string at = f.string() + " line " + std::to_string(n);
      json j;
      std::string problem;
      try {
        j = json::parse(line);
        problem = record_problem(spec, j);
      } catch (const json::exception&) {
        problem = "not a complete record";  // a shard killed mid-write leaves a torn last line
      }
      if (!problem.empty()) {
        // The first few of a file on stderr (a stale 1000-case shard is 1000 lines), all in sweep.json.
        if (++ignored_here <= kNamedPerFile) std::fprintf(stderr, "sweep merge: %s: %s; ignored\n", at.c_str(), problem.c_str());
        ignored.push_back({{"file", f.string()}, {"line", n}, {"why", problem}});
        continue;
      }
      const int id = j["case"].get<int>();
      const auto [it, first] = cases.emplace(id, j);
      if (first) continue;
      if (it->second != j) {
        if (++conflicts_here <= kNamedPerFile)
          std::fprintf(stderr, "sweep merge: case %d: %s holds a record that differs from an earlier one; the first is kept\n",
                       id, at.c_str());
        conflicts.push_back({{"case", id}, {"file", f.string()}, {"line", n}});
      }
    }
    if (ignored_here > kNamedPerFile)
      std::fprintf(stderr, "sweep merge: %s: %d more lines ignored (all in sweep.json's ignored_lines)\n", f.string().c_str(),
                   ignored_here - kNamedPerFile);
    if (conflicts_here > kNamedPerFile)
      std::fprintf(stderr, "sweep merge: %s: %d more differing records (all in sweep.json's conflicting_records)\n",
                   f.string().c_str(), conflicts_here - kNamedPerFile);
  }
  return absent;
}

// robustness.json as `excavator-sim robustness` writes it (the variants' rows), for plot-run.
json robustness_rows(const SweepSpec& spec, const std::map<int, json>& cases) {
  json rows = json::array();
  for (const auto& [id, j] : cases) {
    json row = {{"variant", j.value("variant", std::to_string(id))}};
    if (j.contains("variant"))
      for (const SweepVariant& v : spec.variants)
        if (v.name == j["variant"]) row["description"] = v.description;
    for (const std::string& c : spec.controllers) row[c] = j[c];
    rows.push_back(row);
  }
  return {{"robustness", rows}};
}

}  // namespace

MergeOutcome merge_sweep(const SweepSpec& spec, const std::vector<fs::path>& shard_files, const fs::path& out_dir,
                         bool charts) {
  MergeOutcome outcome;
  std::map<int, json> cases;
  json ignored = json::array(), conflicts = json::array();
  const json absent_files = read_shards(spec, shard_files, cases, ignored, conflicts);
  fs::create_directories(out_dir);
  const std::vector<std::string> runs = run_columns(spec), knobs = spec.set_knobs();
  std::ofstream csv = output::open_file(out_dir / "sweep.csv");
  csv << "case";
  if (spec.scenes.size() > 1) csv << ",scene";
  if (!spec.variants.empty()) csv << ",variant";
  for (const SweepDraw& d : spec.perturbations) csv << ',' << d.knob;
  if (!spec.faults.empty()) csv << ",fault,fault_joint,fault_start,fault_duration,fault_magnitude";
  for (const std::string& k : knobs) csv << ',' << k;
  for (const std::string& c : runs) {
    csv << ',' << c << "_ok";
    for (const char* joint : kJoints) csv << ',' << c << "_rms_" << joint;
    if (!spec.search.knob.empty()) csv << ',' << c << "_search";
    csv << ',' << c << "_failure";
  }
  csv << "\n";
  std::vector<int> missing;
  std::map<std::string, std::map<std::string, int>> failures, kinds;  // controller -> region / kind -> count
  json by_value = json::object();                                      // controller -> knob -> value -> counts
  json campaign = json::object();                                      // controller -> fault kind -> outcomes
  json safety_functions = json::object();  // per controller, per stop's fault (count_safety_function)
  // The Monte-Carlo regions need the three draws they are made of.
  const bool all_draws = spec.draws("model_mass") && spec.draws("soil_stiffness") && spec.draws("delay_cycles");
  for (int id = 0; id < spec.total_cases(); ++id) {
    const auto it = cases.find(id);
    if (it == cases.end()) {
      missing.push_back(id);
      continue;
    }
    const json& j = it->second;
    csv << id;
    if (spec.scenes.size() > 1) csv << ',' << j.value("scene", "");
    if (!spec.variants.empty()) csv << ',' << j.value("variant", "");
    for (const SweepDraw& d : spec.perturbations) csv << ',' << cell(j[d.knob]);
    if (!spec.faults.empty()) {
      const json& f = j.contains("fault") ? j["fault"] : json::object();
      csv << ',' << f.value("kind", "none") << ',' << cell(f.value("joint", json())) << ',' << cell(f.value("start", json()))
          << ',' << cell(f.value("duration", json())) << ',' << cell(f.value("magnitude", json()));
    }
    const SweepCase c = sweep_case(spec, id);
    for (const std::string& k : knobs) csv << ',' << (c.value(k) ? c.value(k)->text() : "");
    for (const std::string& name : runs) {
      const json& r = j.at(name);
      const bool ok = r.at("ok").get<bool>();
      csv << ',' << (ok ? 1 : 0);
      for (const char* joint : kJoints) csv << ',' << cell(r.contains("rms_error") && r["rms_error"].is_object() ? r["rms_error"].value(joint, json()) : json());
      if (!spec.search.knob.empty()) {
        const json v = r.value("search_value", json());
        csv << ',' << (v.is_string() ? v.get<std::string>() : cell(v));
      }
      csv << ',' << quoted(r.value("failure", ""));
      if (j.contains("fault")) {
        count_campaign_run(campaign, j, name);
        count_safety_function(safety_functions, j, name);
      }
      for (const SweepSetting& s : c.set) {
        json& v = by_value[name][s.first][s.second.text()];
        if (v.is_null()) v = {{"runs", 0}, {"failed", 0}};
        v["runs"] = v["runs"].get<int>() + 1;
        if (!ok) v["failed"] = v["failed"].get<int>() + 1;
      }
      if (!ok) {
        ++kinds[name][failure_kind(r.value("failure", ""))];
        if (all_draws) ++failures[name][draw_region(j)];
      }
    }
    csv << "\n";
  }
  json summary = {{"spec", spec.file}, {"cases", spec.total_cases()}, {"merged", cases.size()}, {"missing", missing},
                  {"missing_shard_files", absent_files}, {"ignored_lines", ignored}, {"conflicting_records", conflicts},
                  {"campaign", campaign}, {"safety_functions", safety_functions}};
  if (spec.records("failures")) {
    summary["failures"] = failures;
    summary["failure_kinds"] = kinds;
    summary["failures_by_value"] = by_value;
  }
  // What the charts read: the runs' columns and the grids' axes.
  json grids = json::array();
  for (const SweepGrid& g : spec.grids) {
    json axes = json::array();
    for (const SweepAxis& a : g) axes.push_back(a.knob);
    grids.push_back(axes);
  }
  summary["chart"] = {{"runs", runs}, {"grids", grids}, {"search", spec.search.knob}, {"variants", !spec.variants.empty()}};
  output::write_file(out_dir / "sweep.json", summary.dump(2) + "\n");
  output::finish_file(csv, out_dir / "sweep.csv");
  if (charts && spec.records("robustness") && !spec.variants.empty()) {
    output::write_file(out_dir / "robustness.json", robustness_rows(spec, cases).dump(2) + "\n");
    if (plot_robustness(out_dir / "robustness.json", out_dir) != 0) {
      std::fprintf(stderr, "sweep merge: the robustness chart failed (%s)\n", (out_dir / "robustness.png").c_str());
      outcome.charts_ok = false;
    }
  }
  const bool stability = spec.records("stability"), spread = spec.records("robustness") && spec.variants.empty();
  if (charts && (stability || spread) && !cases.empty()) {
    std::vector<std::string> cmd = {"/usr/bin/python3", EXC_SWEEP_PLOT};
    if (stability) cmd.push_back("--stability");
    if (spread) cmd.push_back("--robustness");
    cmd.push_back(out_dir.string());
    if (output::run_helper(cmd) != 0) {
      std::fprintf(stderr, "sweep merge: the charts failed (%s)\n", output::command_text(cmd).c_str());
      outcome.charts_ok = false;
    }
  }
  if (!conflicts.empty()) {
    std::fprintf(stderr, "sweep merge: %zu records differ from an earlier record of their case: the runs are not reproducible as merged\n",
                 conflicts.size());
    outcome.consistent = false;
  }
  if (!missing.empty()) {
    std::fprintf(stderr, "sweep merge: %zu of %d cases missing (first: %d); rerun their shards\n", missing.size(),
                 spec.total_cases(), missing.front());
    outcome.complete = false;
  }
  return outcome;
}

}  // namespace exc::sim
