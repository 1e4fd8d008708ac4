// excavator-loop-bench --split end to end: the program profiles itself under valgrind's callgrind and
// prints one cycle's instructions by stage. The table must be consistent with its own nesting: no
// stage above the stage that calls it, the parts of a node within the node, and the two nodes with
// the SYNC stage accounting for most of the loop (the rest is the lockstep's own glue), the model
// evaluations within the two stages that call them. A parse that matched the wrong function, a double
// count or a count from outside the loop breaks one of these.
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "scratch_files.hpp"
#include "text_file.hpp"

namespace fs = std::filesystem;

namespace {
struct Row {
  int depth = 0;
  std::string stage;
  double count = -1;  // instructions per cycle; -1 when inlined
};
}  // namespace

TEST_CASE("tools/excavator-loop-bench --split: each stage within its caller, the nodes account for the loop") {
  const fs::path dir =
      exc::test::scratch_dir(fs::path(EXC_BINARY_DIR) / "tests" / "bench" / ("loop_split_" + std::to_string(getpid())));
  const std::string cmd = std::string(EXC_LOOP_BENCH_EXE) +
                          " --split --split-duration 0.5 --duration 0.2 --repeats 1 --no-pin --history 0 > '" +
                          (dir / "out.txt").string() + "' 2> '" + (dir / "err.txt").string() + "'";
  const int raw = std::system(cmd.c_str());
  const std::string out = exc::test::read_text_file(dir / "out.txt");
  INFO(out);
  INFO(exc::test::read_text_file(dir / "err.txt"));
  REQUIRE(WIFEXITED(raw));
  REQUIRE(WEXITSTATUS(raw) == 0);  // valgrind is an install step (tools/install-deps test)
  const std::size_t at = out.find("# Instructions per cycle by stage");
  REQUIRE(at != std::string::npos);

  std::vector<Row> rows;
  const std::size_t model_at = out.find("# One evaluation of the closed-chain model", at);
  REQUIRE(model_at != std::string::npos);
  std::istringstream lines(out.substr(at, model_at - at));  // the stage table only
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind("| ", 0) != 0 || line.rfind("| stage", 0) == 0) continue;
    const std::size_t a = 2, b = line.find(" | ", a);
    REQUIRE(b != std::string::npos);
    std::string stage = line.substr(a, b - a);
    Row r;
    while (stage.rfind("  ", 0) == 0) {
      stage.erase(0, 2);
      ++r.depth;
    }
    r.stage = stage;
    const std::string cell = line.substr(b + 3, line.find(" | ", b + 3) - (b + 3));
    if (cell != "(inlined)") {
      REQUIRE(cell.back() == 'k');
      r.count = std::stod(cell.substr(0, cell.size() - 1)) * 1e3;
    }
    rows.push_back(r);
  }
  REQUIRE(rows.size() == 21);  // the stages the README's table names
  REQUIRE(rows[0].stage.rfind("the loop", 0) == 0);
  const double loop = rows[0].count;
  REQUIRE(loop > 1e3);

  // Nesting: each row's caller is the nearest row above it one level up; a stage costs no more than
  // its caller (0.1k of rounding), and the parts of a caller add up to no more than it.
  double node_sum = 0;
  int nodes = 0;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    if (rows[i].stage.rfind("across the nodes", 0) == 0 || rows[i].stage.rfind("telemetry thread", 0) == 0) {
      if (rows[i].count >= 0 && rows[i].stage.rfind("across", 0) == 0) CHECK(rows[i].count <= loop);
      continue;  // cross-cutting figures, not parts of one caller
    }
    if (rows[i].depth == 1 && rows[i].count >= 0) {
      node_sum += rows[i].count;
      ++nodes;
    }
    std::size_t parent = i;
    while (parent > 0 && rows[--parent].depth != rows[i].depth - 1) {}
    if (rows[i].count < 0 || rows[parent].count < 0) continue;
    INFO(rows[i].stage << " under " << rows[parent].stage);
    CHECK(rows[i].count <= rows[parent].count + 100);
    double parts = 0;
    for (std::size_t j = parent + 1; j < rows.size() && rows[j].depth > rows[parent].depth; ++j)
      if (rows[j].depth == rows[parent].depth + 1 && rows[j].count > 0) parts += rows[j].count;
    CHECK(parts <= rows[parent].count + 300);
  }
  // The model evaluations run inside the plant's step and the control law only: counted outside the
  // loop (the scene's load runs them thousands of times) they would exceed both together.
  auto count_of = [&](const char* prefix) {
    for (const Row& r : rows)
      if (r.stage.rfind(prefix, 0) == 0) return r.count;
    return -1.0;
  };
  const double models = count_of("across the nodes: the model evaluations");
  const double step = count_of("Plant::step"), law = count_of("control law");
  REQUIRE(models > 0);
  if (step > 0 && law > 0) CHECK(models <= step + law + 200);
  CHECK(out.find("the loop without them would run at about") != std::string::npos);
  if (nodes == 3) {  // all three calls of the loop kept as functions by the compiler
    CHECK(node_sum <= loop + 300);
    CHECK(node_sum >= 0.85 * loop);
  }

  // One evaluation per node and path, counted in a child run of its own on random states: each
  // node's planar count below its general one (the same states), and the two nodes' together near
  // what the loop's own two evaluations per cycle counted above (other states: atan2 and the loop
  // closure's branches cost a little more or less).
  std::istringstream model_lines(out.substr(model_at));
  std::vector<std::pair<double, double>> evaluations;  // (planar, general) per node
  while (std::getline(model_lines, line)) {
    if (line.rfind("| the ", 0) != 0) continue;
    std::vector<std::string> cells;
    for (std::size_t a = 2, b; (b = line.find(" | ", a)) != std::string::npos; a = b + 3) cells.push_back(line.substr(a, b - a));
    REQUIRE(cells.size() == 3);
    REQUIRE(cells[1].back() == 'k');
    REQUIRE(cells[2].back() == 'k');
    evaluations.emplace_back(std::stod(cells[1]) * 1e3, std::stod(cells[2]) * 1e3);
  }
  REQUIRE(evaluations.size() == 2);  // the firmware's, the plant's
  for (const auto& [planar, general] : evaluations) {
    CHECK(planar > 1e3);
    CHECK(planar < general);
  }
  CHECK(std::abs(evaluations[0].first + evaluations[1].first - models) <= 0.15 * models);
  CHECK(out.find("Goal: one evaluation in at most 7.1k instructions: ") != std::string::npos);
  fs::remove_all(dir);
}
