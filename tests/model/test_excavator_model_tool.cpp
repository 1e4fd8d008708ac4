// The excavator-model program driven through standard input, as a user would.
#include <doctest/doctest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

#include "model_fixture.hpp"
#include "scratch_files.hpp"

namespace {

struct Run {
  int status = -1;
  std::string out, err;
};

// Runs the tool with 'input' on stdin (files under the build tree for stdout and stderr).
Run run_tool(const std::string& args, const std::string& input) {
  // ctest runs test cases in parallel processes: one file set per process and call.
  static int call = 0;
  const std::string base = std::string(EXC_BINARY_DIR) + "/tests/model/tool_run_" + std::to_string(getpid()) + "_" +
                           std::to_string(call++);
  for (const char* ext : {".in", ".out", ".err"}) exc::test::scratch_file(base + ext);
  { std::ofstream(base + ".in") << input; }
  const std::string cmd = std::string(EXC_MODEL_TOOL) + " " + args + " < " + base + ".in > " + base + ".out 2> " + base + ".err";
  const int raw = std::system(cmd.c_str());
  Run r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  auto slurp = [](const std::string& p) {
    std::ifstream in(p);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  };
  r.out = slurp(base + ".out");
  r.err = slurp(base + ".err");
  for (const char* ext : {".in", ".out", ".err"}) std::remove((base + ext).c_str());
  return r;
}

std::vector<std::vector<double>> numbers(const std::string& text) {
  std::vector<std::vector<double>> rows;
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream in(line);
    std::vector<double> row;
    double x;
    while (in >> x) row.push_back(x);
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

TEST_CASE("tools/excavator-model fk reproduces the reference poses") {
  const exc::Machine& mach = exc::test::reference_model().machine;
  std::string input;
  for (const auto& p : mach.reference_poses) {
    std::ostringstream s;
    s.precision(17);
    s << p.q_a[0] << " " << p.q_a[1] << " " << p.q_a[2] << " " << p.q_a[3] << "\n";
    input += s.str();
  }
  const Run r = run_tool("fk", input);
  REQUIRE(r.status == 0);
  const auto rows = numbers(r.out);
  REQUIRE(rows.size() == mach.reference_poses.size());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const auto& pose = mach.reference_poses[k];
    REQUIRE(rows[k].size() == 6);
    const exc::Vec3 tip = pose.pins_world.back().second;  // T
    CHECK(pose.pins_world.back().first == "T");
    CHECK(std::abs(rows[k][0] - tip.x()) < 0.5e-3);
    CHECK(std::abs(rows[k][1] - tip.y()) < 0.5e-3);
    CHECK(std::abs(rows[k][2] - tip.z()) < 0.5e-3);
    CHECK(std::abs(rows[k][3] - pose.boom_angle_deg) < 0.01);
    CHECK(std::abs(rows[k][4] - pose.arm_angle_deg) < 0.01);
    CHECK(std::abs(rows[k][5] - pose.bucket_angle_deg) < 0.01);
  }
  // Full precision: 17 significant digits on every number.
  CHECK(r.out.find("8.66435") != std::string::npos);
  CHECK(r.out.substr(0, r.out.find(' ')).size() >= 17);
}

TEST_CASE("tools/excavator-model id then fd round trip through the program") {
  const Run id = run_tool("id", "0.3 2.2 2.8 1.9 0.2 0.1 -0.1 0.2 0.5 -0.3 0.4 0.6\n0 2.46 2.32 2.14 0 0 0 0 0 0 0 0\n");
  REQUIRE(id.status == 0);
  const auto tau = numbers(id.out);
  REQUIRE(tau.size() == 2);
  REQUIRE(tau[0].size() == 4);
  // Holding the machine still takes a push on the boom cylinder (it carries the front's weight).
  CHECK(tau[1][1] > 1e5);
  CHECK(std::abs(tau[1][0]) < 1e-6);
  char line[512];
  std::snprintf(line, sizeof line, "0.3 2.2 2.8 1.9 0.2 0.1 -0.1 0.2 %.17g %.17g %.17g %.17g\n", tau[0][0], tau[0][1],
                tau[0][2], tau[0][3]);
  const Run fd = run_tool("fd", line);
  REQUIRE(fd.status == 0);
  const auto qdd = numbers(fd.out);
  REQUIRE(qdd.size() == 1);
  REQUIRE(qdd[0].size() == 4);
  const double expected[4] = {0.5, -0.3, 0.4, 0.6};
  for (int k = 0; k < 4; ++k) CHECK(qdd[0][k] == doctest::Approx(expected[k]).epsilon(1e-8));
}

TEST_CASE("tools/excavator-model stops at a bad line with its number and reason, exit 2") {
  const Run few = run_tool("id", "0 2.4 2.6 2.0 0 0 0 0 0 0 0 0\n0 2.4 2.6\n0 2.4 2.6 2.0 0 0 0 0 0 0 0 0\n");
  CHECK(few.status == 2);
  CHECK(numbers(few.out).size() == 1);  // the good line before it was answered
  CHECK(few.err.find("line 2") != std::string::npos);
  CHECK(few.err.find("expected 12 numbers, got 3") != std::string::npos);

  const Run word = run_tool("fk", "0 2.4 abc 2.0\n");
  CHECK(word.status == 2);
  CHECK(word.err.find("line 1") != std::string::npos);
  CHECK(word.err.find("'abc' is not a number") != std::string::npos);

  const Run nan = run_tool("fk", "0 2.4 nan 2.0\n");
  CHECK(nan.status == 2);
  CHECK(nan.err.find("not finite") != std::string::npos);

  const Run no_assembly = run_tool("fk", "\n0 2.4 2.6 1.5\n");
  CHECK(no_assembly.status == 2);
  CHECK(no_assembly.err.find("line 2") != std::string::npos);
  CHECK(no_assembly.err.find("no assembly") != std::string::npos);
  CHECK(no_assembly.err.find("loop 3") != std::string::npos);

  const Run toggle = run_tool("fd", "0 2.4 2.6 1.5825 0 0 0 0 0 0 0 0\n");
  CHECK(toggle.status == 2);
  CHECK(toggle.err.find("toggle") != std::string::npos);
  CHECK(toggle.err.find("conditioning") != std::string::npos);
}

TEST_CASE("tools/excavator-model --help and --machine") {
  const Run help = run_tool("--help", "");
  CHECK(help.status == 0);
  CHECK(help.out.find("fk") != std::string::npos);
  CHECK(help.out.find("--machine") != std::string::npos);

  const Run same = run_tool(std::string("--machine ") + EXC_MACHINE_FILE + " fk", "0.5 1.9 3.0 1.8\n");
  const Run builtin = run_tool("fk", "0.5 1.9 3.0 1.8\n");
  CHECK(same.status == 0);
  CHECK(same.out == builtin.out);

  const std::string bad =
      exc::test::scratch_file(std::string(EXC_BINARY_DIR) + "/tests/model/bad_machine_" + std::to_string(getpid()) + ".yaml");
  { std::ofstream(bad) << "name: x\ngravity: -3\n"; }
  const Run bad_run = run_tool("--machine " + bad + " fk", "0 2 2 2\n");
  CHECK(bad_run.status == 2);
  CHECK(bad_run.err.find(bad) != std::string::npos);
  CHECK(bad_run.err.find("gravity") != std::string::npos);

  const Run no_mode = run_tool("", "");
  CHECK(no_mode.status == 2);
}
