// The report of a run as a user reads it (excavator-sim run: the summary on stdout, report.md and its
// figures) for a task that repeats, and what plot-run makes of the telemetry before tracking starts.
#include <doctest/doctest.h>

#include <algorithm>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "matplotlib_probe.hpp"
#include "png_size.hpp"
#include "sim_runs.hpp"

namespace fs = std::filesystem;

using exc::test::edited_dig;
using exc::test::read_text_file;
using exc::test::Run;
using exc::test::run_sim;

namespace {


// The dig pass at twice the speed (5 s), twice, with a 2 s return move between: two short cycles.
fs::path repeated_dig() {
  return edited_dig({{"duration: 10.1", "duration: 12.5"},
                     {"  swing: 0.0                   # rad, held", "  swing: 0.0\n  repeat: 2\n  return_time: 2.0"},
                     {"{t: 2.0,", "{t: 1.0,"},
                     {"{t: 3.5,", "{t: 1.75,"},
                     {"{t: 6.0,", "{t: 3.0,"},
                     {"{t: 8.0,", "{t: 4.0,"},
                     {"{t: 10.0,", "{t: 5.0,"}},
                    "repeated_dig");
}

std::string format(const char* fmt, double a, double b = 0, double c = 0, double d = 0) {
  char text[160];
  std::snprintf(text, sizeof text, fmt, a, b, c, d);
  return text;
}

// The four joints' errors of one cycle as report.md writes them: "a / b / c / d" in mm (swing mrad).
std::string per_joint(const nlohmann::json& errors) {
  return format("%.3g / %.3g / %.3g / %.3g", 1e3 * errors["swing"].get<double>(), 1e3 * errors["boom"].get<double>(),
                1e3 * errors["arm"].get<double>(), 1e3 * errors["bucket"].get<double>());
}

// key=value pairs printed by a Python snippet run in `dir` with plot-run's modules on its path.
std::map<std::string, double> run_python(const fs::path& dir, const std::string& code) {
  const fs::path script = dir / "check.py";
  std::ofstream(script) << "import sys\nsys.path.insert(0, '" << EXC_PLOT_RUN_DIR << "')\n" << code;
  const fs::path out = dir / "check.txt";
  REQUIRE(std::system(("cd '" + dir.string() + "' && /usr/bin/python3 check.py > check.txt").c_str()) == 0);
  std::map<std::string, double> values;
  std::istringstream lines(read_text_file(out));
  std::string line;
  while (std::getline(lines, line)) {
    const auto eq = line.find('=');
    if (eq != std::string::npos) values[line.substr(0, eq)] = std::stod(line.substr(eq + 1));
  }
  return values;
}

}  // namespace

TEST_CASE("tools/excavator-sim report of a repeated dig: each controller's per-cycle table (time, RMS and worst error of all four joints, soil force, estimates) and chart, what they show in words, and the task's end time") {
  REQUIRE_MESSAGE(exc::test::matplotlib_available(), exc::test::kMatplotlibMissing);
  const fs::path scene = repeated_dig();
  const Run r = run_sim("run " + scene.string() + " --controller pid,adaptive --quiet --out out");
  INFO(r.err);
  REQUIRE(r.status == 0);
  const nlohmann::json j = nlohmann::json::parse(read_text_file(r.dir / "out" / "summary.json"));
  const std::string report = read_text_file(r.dir / "out" / "report" / "report.md");
  INFO(report);
  for (const char* c : {"pid", "adaptive"}) {
    CAPTURE(c);
    REQUIRE(j[c]["cycles"].size() == 2);
    REQUIRE(j[c]["task_finished"].get<bool>());
    const double finish = j[c]["task_finish_time"].get<double>();
    CHECK(finish == doctest::Approx(12.05).epsilon(1e-3));
    // The task's end in the printed summary and in the report's table.
    CHECK(r.out.find(std::string(c) + std::string(10 - std::string(c).size(), ' ') + " task finished at " +
                     format("%.3f s;", finish)) != std::string::npos);
    // One table row per cycle with the JSON's own figures.
    for (std::size_t k = 0; k < 2; ++k) {
      const nlohmann::json& cycle = j[c]["cycles"][k];
      const std::string row = "| " + std::to_string(k + 1) + " | " + c + " | " +
                              format("%.2f", cycle["end"].get<double>() - cycle["start"].get<double>()) + " | " +
                              per_joint(cycle["rms_error"]) + " | " + per_joint(cycle["max_error"]) + " | " +
                              format("%.1f", 1e-3 * cycle["peak_soil_force"].get<double>()) + " | ";
      CAPTURE(row);
      CHECK(report.find(row) != std::string::npos);
    }
  }
  CHECK(report.find(format("| task finished at (s) | %.3f | %.3f |", j["pid"]["task_finish_time"].get<double>(),
                           j["adaptive"]["task_finish_time"].get<double>())) != std::string::npos);
  // The adaptive law's estimates at the cycle's end; PID has none.
  CHECK(report.find(format(" | %.3g ", j["adaptive"]["cycles"][1]["theta_hat"]["M_x"].get<double>())) != std::string::npos);
  CHECK(report.find("| (no estimator) |") != std::string::npos);
  // In words, from the numbers: who is better on each joint in which cycles, whether a law learns.
  CHECK(report.find("What the numbers show:") != std::string::npos);
  // The bucket's verdict, rebuilt from summary.json's per-cycle figures: who is lower in which cycle.
  auto lower = [&](const char* figure) {
    std::vector<std::string> who;
    for (std::size_t k = 0; k < j["pid"]["cycles"].size(); ++k)
      who.push_back(j["adaptive"]["cycles"][k][figure]["bucket"].get<double>() < j["pid"]["cycles"][k][figure]["bucket"].get<double>()
                        ? "adaptive" : "pid");
    if (std::all_of(who.begin(), who.end(), [&](const std::string& w) { return w == who[0]; })) return who[0] + " in every cycle";
    std::string text;
    for (std::size_t k = 0; k < who.size(); ++k) text += (k ? ", " : "") + who[k] + " in cycle " + std::to_string(k + 1);
    return text;
  };
  const std::string bucket = "- bucket: the lower RMS error: " + lower("rms_error") + "; the lower worst error: " +
                             lower("max_error") + " (mean RMS pid ";
  CAPTURE(bucket);
  CHECK(report.find(bucket) != std::string::npos);
  CHECK(report.find("- adaptive, RMS error after its first cycle: boom ") != std::string::npos);
  CHECK(report.find(" after its first cycle on boom") != std::string::npos);  // the verdict, whichever it is
  CHECK(report.find("- adaptive carries its soil estimates from one cycle to the next") != std::string::npos);
  for (const char* name : {"work_cycles.png", "cycle_errors.png"}) {
    CAPTURE(name);
    const fs::path png = r.dir / "out" / "report" / name;
    std::uint32_t width = 0, height = 0;
    REQUIRE(exc::test::png_size(png, &width, &height));
    CHECK(width == 1200);
    CHECK(height == 700);
    CHECK(fs::file_size(png) > 30000);
    CHECK(report.find(std::string("(") + name + ")") != std::string::npos);
  }
  // A short run: the report's CSVs have one row per cycle (12.5 s at 1 kHz), no bucketed view.
  CHECK(exc::test::csv_data_rows(r.dir / "out" / "report" / "csv" / "EXC_CONTROLLER__adaptive.csv") == 12500);
  CHECK_FALSE(fs::exists(r.dir / "out" / "report" / "csv" / "detail"));
  fs::remove(scene);
}

TEST_CASE("tools/plot-run: before tracking starts the desired trajectory is a gap (NaN), not zero, in every row and in a bucketed view's envelope") {
  REQUIRE_MESSAGE(exc::test::matplotlib_available(), exc::test::kMatplotlibMissing);
  const Run r = run_sim("run " + exc::test::kDig + " --duration 3 --quiet --no-report --out out");
  REQUIRE(r.status == 0);
  const std::string log = (r.dir / "out" / "run.lcm").string();
  for (const auto& [dir, options] : {std::pair<std::string, std::string>{"rows", ""}, {"buckets", " --bucket-rows 500 --buckets 60"}}) {
    const std::string command = std::string(EXC_LOG_TOOL) + " export '" + log + "' --csv '" + (r.dir / dir).string() +
                                "'" + options + " > /dev/null";
    REQUIRE(std::system(command.c_str()) == 0);
  }
  const std::map<std::string, double> v = run_python(r.dir, R"(
import math
import numpy as np
import run_data as d
ctrl = d.read_channel("rows", "EXC_CONTROLLER__adaptive.csv")
print("rows_bucketed=%d" % (ctrl.buckets is not None))
desired = d.commanded(ctrl, "q_desired_1")
before = [k for k, m in enumerate(ctrl["mode"]) if m < 2]
print("before_rows=%d" % len(before))
print("before_raw_zero=%d" % sum(ctrl["q_desired_1"][k] == 0.0 for k in before))
print("before_nan=%d" % sum(math.isnan(desired[k]) for k in before))
print("after_nan=%d" % sum(math.isnan(x) for k, x in enumerate(desired) if k not in set(before)))
ctrl = d.read_channel("buckets", "EXC_CONTROLLER__adaptive.csv")
print("view_bucketed=%d" % (ctrl.buckets is not None))
t, lo, hi = d.envelope(ctrl, "q_desired_1", only_commanded=True)
print("view_buckets=%d" % len(t))
print("view_first_bucket_nan=%d" % (math.isnan(lo[0]) and math.isnan(hi[0])))
print("view_nan_buckets=%d" % np.count_nonzero(np.isnan(lo)))
print("view_zero_in_envelope=%d" % (np.count_nonzero(lo == 0) + np.count_nonzero(hi == 0)))
)");
  // The firmware publishes q_desired = 0 while it starts up (init, wait for sensors): every such row
  // is a gap, every later one a value.
  CHECK(v.at("rows_bucketed") == 0);
  CHECK(v.at("before_rows") > 0);
  CHECK(v.at("before_raw_zero") == v.at("before_rows"));
  CHECK(v.at("before_nan") == v.at("before_rows"));
  CHECK(v.at("after_nan") == 0);
  // The bucketed view: the bucket holding the start-up is a gap, the later ones values, none 0.
  CHECK(v.at("view_bucketed") == 1);
  CHECK(v.at("view_buckets") == 60);
  CHECK(v.at("view_first_bucket_nan") == 1);
  CHECK(v.at("view_nan_buckets") == 1);
  CHECK(v.at("view_zero_in_envelope") == 0);
}

TEST_CASE("tools/excavator-sim: a helper's output (plot-run's line) follows the table it ran after, never inside it, with stdout a file") {
  // stdout to a file is block-buffered: plot-run, started while part of the table was still in
  // excavator-sim's buffer, printed its line above or inside the table.
  const std::string scenes = std::string(EXC_SOURCE_DIR) + "/scenes/";
  const std::string paper = "paper --free-motion " + scenes + "paper_free_motion.yaml --dig " + scenes + "paper_dig.yaml --hydraulic-dig " +
                            exc::test::kDig + " --duration 0.2 --out paper";
  for (const std::string& job : {"run " + exc::test::kDig + " --duration 0.2 --out run", paper}) {
    CAPTURE(job);
    const Run r = run_sim(job + " --quiet");
    REQUIRE_MESSAGE(r.status == 0, r.err);
    std::istringstream out(r.out);
    std::vector<std::string> lines;
    for (std::string line; std::getline(out, line);) lines.push_back(line);
    int helpers = 0, tables = 0;
    for (std::size_t i = 0; i < lines.size(); ++i) {
      if (lines[i].rfind("scene ", 0) == 0) ++tables;
      if (lines[i].rfind("plot-run: ", 0) != 0) continue;
      ++helpers;
      INFO(r.out);
      // After every line of its scene's table (the runs' lines, then the hydraulics'), before "report: ".
      REQUIRE(i > 0);
      REQUIRE(i + 1 < lines.size());
      CHECK(lines[i + 1].rfind("report: ", 0) == 0);
      CHECK((lines[i - 1].find("heap allocations in loop") != std::string::npos ||
             lines[i - 1].find("hydraulics: chamber pressures") != std::string::npos));
    }
    CHECK(helpers == tables);  // one report per scene
    CHECK(tables >= 1);
  }
}
