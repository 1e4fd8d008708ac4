// The merge of a sweep's shard files: the table (a row per case), the summary (missing cases and
// shard files, failures by region, the fault campaign's outcomes) and the charts the spec records.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <fstream>
#include <map>
#include <regex>
#include <stdexcept>

#include "output_file.hpp"
#include "run_report.hpp"
#include "fault_campaign.hpp"
#include "sweep.hpp"
#include "sweep_tables.hpp"

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

// Reads the shard files' lines into `cases`; a file that is not there is named with its cases when
// its name tells its shard (shard-I.jsonl of the N given, or shard-I-of-N.jsonl).
json read_shards(const SweepSpec& spec, const std::vector<fs::path>& files, std::map<int, json>& cases) {
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
    int n = 0;
    while (std::getline(in, line)) {
      ++n;
      if (line.empty()) continue;
      try {
        const json j = json::parse(line);
        cases[j.at("case").get<int>()] = j;
      } catch (const json::exception&) {
        // A shard killed mid-write leaves a torn last line: that case counts as missing.
        std::fprintf(stderr, "sweep merge: %s line %d: not a complete record, ignored\n", f.string().c_str(), n);
      }
    }
  }
  return absent;
}

std::vector<std::string> run_columns(const SweepSpec& spec) {
  return spec.run == SweepRun::open_loop ? std::vector<std::string>{"plant"} : spec.controllers;
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
  const json absent_files = read_shards(spec, shard_files, cases);
  fs::create_directories(out_dir);
  const std::vector<std::string> runs = run_columns(spec), knobs = spec.set_knobs();
  const std::pair<const char*, const SweepRange*> draws[] = {{"model_mass", &spec.model_mass},
                                                             {"soil_stiffness", &spec.soil_stiffness},
                                                             {"position_noise", &spec.position_noise},
                                                             {"delay_cycles", &spec.delay_cycles}};
  std::ofstream csv = output::open_file(out_dir / "sweep.csv");
  csv << "case";
  if (spec.scenes.size() > 1) csv << ",scene";
  if (!spec.variants.empty()) csv << ",variant";
  for (const auto& [name, range] : draws)
    if (range->given) csv << ',' << name;
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
  const bool all_draws = spec.model_mass.given && spec.soil_stiffness.given && spec.delay_cycles.given;
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
    for (const auto& [name, range] : draws)
      if (range->given) csv << ',' << cell(j[name]);
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
      if (j.contains("fault")) count_campaign_run(campaign, j, name);
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
                  {"missing_shard_files", absent_files}, {"campaign", campaign}};
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
    const std::string what = std::string(stability ? " --stability" : "") + (spread ? " --robustness" : "");
    const std::string cmd = "/usr/bin/python3 '" EXC_SWEEP_PLOT "'" + what + " '" + out_dir.string() + "'";
    if (std::system(cmd.c_str()) != 0) {
      std::fprintf(stderr, "sweep merge: the charts failed (%s)\n", cmd.c_str());
      outcome.charts_ok = false;
    }
  }
  if (!missing.empty()) {
    std::fprintf(stderr, "sweep merge: %zu of %d cases missing (first: %d); rerun their shards\n", missing.size(),
                 spec.total_cases(), missing.front());
    outcome.complete = false;
  }
  return outcome;
}

}  // namespace exc::sim
