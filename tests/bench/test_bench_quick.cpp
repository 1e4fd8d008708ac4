// excavator-bench --quick end to end: the program runs in CI time, writes its JSON with the keys the
// README promises (finite numbers; the peer's null and "skipped" when MuJoCo is absent) and every CSV.
#include <doctest/doctest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

namespace fs = std::filesystem;

namespace {
int data_lines(const fs::path& p) {
  std::ifstream f(p);
  std::string line;
  int n = -1;  // the header
  while (std::getline(f, line))
    if (!line.empty()) ++n;
  return n;
}
}  // namespace

TEST_CASE("tools/excavator-bench --quick writes its json and csvs") {
  const fs::path out = fs::path(EXC_BINARY_DIR) / "tests/bench/quick";
  fs::remove_all(out);
  const fs::path json_path = out / "summary.json";
  const std::string cmd = std::string("'") + EXC_BENCH_EXE + "' --quick --out '" + out.string() + "' --json '" +
                          json_path.string() + "' > '" + (fs::path(EXC_BINARY_DIR) / "tests/bench/quick.log").string() +
                          "' 2>&1";
  const auto t0 = std::chrono::steady_clock::now();
  REQUIRE(std::system(cmd.c_str()) == 0);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  CHECK(wall < 120.0);  // generous: the target is 1 min on an idle 2-core machine

  REQUIRE(fs::exists(json_path));
  nlohmann::json j;
  std::ifstream(json_path) >> j;
  for (const char* key : {"plant_step_us", "constraint_error", "control_step_us"}) {
    INFO(key);
    REQUIRE(j.contains(key));
    REQUIRE(j[key].is_number());
    CHECK(std::isfinite(j[key].get<double>()));
  }
  CHECK(j["plant_step_us"].get<double>() > 0);
  CHECK(j["control_step_us"].get<double>() > 0);
  CHECK(j["constraint_error"].get<double>() >= 0);
  REQUIRE(j.contains("pareto"));
  REQUIRE(j["pareto"].is_array());
  CHECK(j["pareto"].size() >= 2);  // at least one point per scene
  for (const auto& p : j["pareto"]) CHECK(std::isfinite(p["tip_rms_m"].get<double>()));
  for (const char* key : {"mujoco_step_us", "mujoco_constraint_error", "mujoco_inverse_us"}) {
    INFO(key);
    REQUIRE(j.contains(key));
#ifdef EXC_HAVE_MUJOCO
    REQUIRE(j[key].is_number());
    CHECK(std::isfinite(j[key].get<double>()));
    CHECK(j[key].get<double>() > 0);
#else
    CHECK(j[key].is_null());
#endif
  }
#ifndef EXC_HAVE_MUJOCO
  CHECK(j["mujoco"].get<std::string>().find("skipped") != std::string::npos);
#endif
  for (const char* csv : {"work_precision.csv", "peer.csv", "peer_tip.csv", "fidelity.csv", "stability_step.csv",
                          "stability_control.csv"}) {
    INFO(csv);
    CHECK(data_lines(out / csv) > 0);
  }
}
