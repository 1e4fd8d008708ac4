// The README's front-page result tables against the program: each scene the tables name is run in
// full (as the main command runs it, no report), and every figure of its row must agree with the
// run's summary within the tolerance the README states. A row that does not is printed as the
// current program output would write it, ready to replace the README's.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "sim_runs.hpp"

namespace fs = std::filesystem;

using exc::test::read_text_file;
using exc::test::Run;
using exc::test::run_sim;

namespace {

const char* const kLaws[3] = {"pid", "adaptive", "flow"};
const char* const kCylinders[3] = {"boom", "arm", "bucket"};

// A figure as the README writes it: its value and half a unit of its last digit (what rounding to
// that digit may have moved it).
struct Figure {
  double value = 0, half_digit = 0;
};

std::vector<Figure> figures_in(const std::string& cell) {
  std::vector<Figure> out;
  static const std::regex number("[0-9]+(\\.([0-9]+))?");
  for (auto it = std::sregex_iterator(cell.begin(), cell.end(), number); it != std::sregex_iterator(); ++it)
    out.push_back({std::stod(it->str()), 0.5 * std::pow(10.0, -static_cast<double>((*it)[2].length()))});
  return out;
}

// The tolerance the README states: 5 % of the figure or 0.02 mm, beyond the rounding of its last digit.
bool agrees(const Figure& readme, double measured_mm) {
  return std::abs(readme.value - measured_mm) <= std::max(0.05 * std::abs(measured_mm), 0.02) + readme.half_digit;
}

std::vector<std::string> cells_of(const std::string& row) {
  std::vector<std::string> cells;
  std::stringstream in(row);
  for (std::string cell; std::getline(in, cell, '|');) {
    const auto a = cell.find_first_not_of(' '), b = cell.find_last_not_of(' ');
    cells.push_back(a == std::string::npos ? "" : cell.substr(a, b - a + 1));
  }
  return cells;  // cells[0] is before the first '|'
}

// The README's rows of the table after `heading`: those whose first cell starts with a backquoted scene.
std::vector<std::vector<std::string>> table_after(const std::string& readme, const std::string& heading) {
  std::vector<std::vector<std::string>> rows;
  auto at = readme.find(heading);
  REQUIRE_MESSAGE(at != std::string::npos, "the README has no '" << heading << "'");
  at = readme.find("\n|", at);
  std::stringstream lines(readme.substr(at + 1));
  for (std::string line; std::getline(lines, line) && line.rfind("|", 0) == 0;)
    if (line.rfind("| `", 0) == 0) rows.push_back(cells_of(line));
  return rows;
}

std::string scene_of(const std::string& cell) { return cell.substr(1, cell.find('`', 1) - 1); }

// The summary of a full run of the scene (every law it runs by default), no report.
nlohmann::json summary_of(const std::string& scene) {
  const Run r = run_sim("run " + std::string(EXC_SOURCE_DIR) + "/scenes/" + scene + ".yaml --quiet --no-report --out out --json s.json");
  INFO(r.err);
  REQUIRE(r.status == 0);
  return nlohmann::json::parse(read_text_file(r.dir / "s.json"));
}

double mm(const nlohmann::json& run, const char* what, const char* cylinder) { return run[what][cylinder].get<double>() * 1e3; }

double worst_mm(const nlohmann::json& run) {
  double w = 0;
  for (const char* c : kCylinders) w = std::max(w, mm(run, "max_error", c));
  return w;
}

// As the README writes a figure: 2 decimals below 10 mm, 1 below 100, none above.
std::string figure(double v) {
  char text[32];
  std::snprintf(text, sizeof text, v < 10 ? "%.2f" : v < 100 ? "%.1f" : "%.0f", v);
  return text;
}
// A worst error: in the main job's table 1 decimal below 10 mm, none above; in the other, 1 decimal.
std::string worst_figure(double v, bool main_table = true) {
  char text[32];
  std::snprintf(text, sizeof text, v < 10 || !main_table ? "%.1f" : "%.0f", v);
  return text;
}

}  // namespace

TEST_CASE("tools/README: the main job's result table (paper dig, hydraulic dig, free motion) is what the main command measures, within 5 % or 0.02 mm") {
  const std::string readme = read_text_file(fs::path(EXC_SOURCE_DIR) / "README.md");
  std::string flat = readme;
  std::replace(flat.begin(), flat.end(), '\n', ' ');
  CHECK(flat.find("every figure within 5 % or 0.02 mm beyond the rounding of its last digit") != std::string::npos);  // stated
  const auto rows = table_after(readme, "## Results at a glance");
  std::vector<std::string> scenes;
  for (const auto& cells : rows) {
    REQUIRE(cells.size() >= 6);
    const std::string scene = scene_of(cells[1]);
    scenes.push_back(scene);
    const nlohmann::json s = summary_of(scene);
    std::string expected = "| " + cells[1] + " | " + cells[2] + " |";
    bool row_ok = true;
    for (int law = 0; law < 3; ++law) {
      const std::string& cell = cells[static_cast<std::size_t>(3 + law)];
      INFO(scene << " " << kLaws[law] << ": '" << cell << "'");
      if (!s.contains(kLaws[law])) {
        CHECK(cell == "-");  // a law the scene does not run
        expected += " - |";
        continue;
      }
      const nlohmann::json& run = s[kLaws[law]];
      const std::vector<Figure> readme_mm = figures_in(cell);
      const std::size_t n = readme_mm.size();
      REQUIRE((n == 3 || n == 4));
      const bool has_worst = n == 4 && cell.find("worst") != std::string::npos;
      std::string text = figure(mm(run, "rms_error", "boom")) + " / " + figure(mm(run, "rms_error", "arm")) + " / " +
                         figure(mm(run, "rms_error", "bucket"));
      if (has_worst) text += " (worst " + worst_figure(worst_mm(run)) + ")";
      expected += " " + text + " |";
      for (int c = 0; c < 3; ++c) row_ok = row_ok && agrees(readme_mm[c], mm(run, "rms_error", kCylinders[c]));
      if (has_worst) row_ok = row_ok && agrees(readme_mm[3], worst_mm(run));
    }
    CHECK_MESSAGE(row_ok, "the README's row of " << scene << " differs from the program's; it now reads:\n" << expected);
  }
  CHECK(scenes == std::vector<std::string>{"paper_dig", "dig", "paper_free_motion"});  // the main command's three scenes
}

TEST_CASE("tools/README: the table of ground no law was tuned for is what those shipped scenes measure, within 5 % or 0.02 mm") {
  const std::string readme = read_text_file(fs::path(EXC_SOURCE_DIR) / "README.md");
  const auto rows = table_after(readme, "On ground it was not tuned for");
  REQUIRE(rows.size() == 4);
  for (const auto& cells : rows) {
    REQUIRE(cells.size() >= 5);
    const std::string scene = scene_of(cells[1]);
    const nlohmann::json s = summary_of(scene);
    std::string expected = "| " + cells[1] + " |";
    bool row_ok = true;
    for (int law = 0; law < 3; ++law) {
      const std::string& cell = cells[static_cast<std::size_t>(2 + law)];
      INFO(scene << " " << kLaws[law] << ": '" << cell << "'");
      if (!s.contains(kLaws[law])) {
        CHECK(cell.rfind("left out", 0) == 0);  // the README says why
        expected += " " + cell + " |";
        continue;
      }
      const nlohmann::json& run = s[kLaws[law]];
      const std::vector<Figure> f = figures_in(cell);  // rms/worst per cylinder
      REQUIRE(f.size() == 6);
      std::string text;
      for (std::size_t c = 0; c < 3; ++c) {
        text += (c ? ", " : "") + figure(mm(run, "rms_error", kCylinders[c])) + "/" + worst_figure(mm(run, "max_error", kCylinders[c]), false);
        row_ok = row_ok && agrees(f[2 * c], mm(run, "rms_error", kCylinders[c])) && agrees(f[2 * c + 1], mm(run, "max_error", kCylinders[c]));
      }
      expected += " " + text + " |";
    }
    CHECK_MESSAGE(row_ok, "the README's row of " << scene << " differs from the program's; it now reads:\n" << expected);
  }
}
