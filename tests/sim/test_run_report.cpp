// The report of a run as a user reads it: what plot-run makes of the telemetry before tracking starts.
#include <doctest/doctest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "sim_runs.hpp"

namespace fs = std::filesystem;

using exc::test::read_text_file;
using exc::test::Run;
using exc::test::run_sim;

namespace {

bool have_matplotlib() { return std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") == 0; }

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

TEST_CASE("tools/plot-run: before tracking starts the desired trajectory is a gap (NaN), not zero, in every row and in a bucketed view's envelope") {
  if (!have_matplotlib()) {
    MESSAGE("SKIPPED: matplotlib is missing (Debian package python3-matplotlib)");
    return;
  }
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
