// excavator-bench --quick end to end: the program runs in CI time, writes its JSON with the keys the
// README promises (finite numbers; the peer's null and "skipped" when MuJoCo is absent) and every CSV.
#include <doctest/doctest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>
#include <algorithm>

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

namespace {
// The work-precision chart against the textbook: in free motion (smooth, the same efforts for every
// method), the tip error of semi-implicit Euler falls 10x per 10x smaller step (order 1), of the
// implicit midpoint rule 100x (order 2); RK4 falls at least 200x from 10 ms to 1 ms before it meets
// the reference's own floor.
void check_convergence_orders(const fs::path& csv) {
  std::ifstream f(csv);
  std::string line;
  std::getline(f, line);
  std::map<std::string, std::map<double, double>> err;  // method -> step -> tip RMS
  while (std::getline(f, line)) {
    std::vector<std::string> c;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) c.push_back(cell);
    if (c.size() < 6 || c[0] != "free_motion" || c[3] != "1") continue;
    err[c[1]][std::stod(c[2])] = std::stod(c[5]);
  }
  const auto order = [&](const char* method, double coarse, double fine) {
    INFO(method);
    REQUIRE(err[method].count(coarse) == 1);
    REQUIRE(err[method].count(fine) == 1);
    return std::log10(err[method][coarse] / err[method][fine]) / std::log10(coarse / fine);
  };
  CHECK(order("semi_implicit_euler/independent", 1e-2, 1e-3) == doctest::Approx(1.0).epsilon(0.1));
  CHECK(order("semi_implicit_euler/independent", 1e-3, 1e-4) == doctest::Approx(1.0).epsilon(0.1));
  CHECK(order("implicit_midpoint/independent", 1e-2, 1e-3) == doctest::Approx(2.0).epsilon(0.1));
  CHECK(order("rk4/independent", 1e-2, 1e-3) > 2.3);
}

// The pressure-integration chart: both inputs, both methods, every listed substep; backward Euler runs
// every one, forward Euler's 10 ms run of the four-function profile is stopped by the plant's pressure
// check naming the method (never a NaN), and the JSON names each input's boundary.
void check_pressure_integration(const fs::path& csv, const nlohmann::json& j) {
  std::ifstream f(csv);
  std::string line;
  std::getline(f, line);
  int rows = 0, backward_ok = 0, backward = 0;
  bool stopped = false;
  while (std::getline(f, line)) {
    if (line.empty()) continue;
    ++rows;
    std::vector<std::string> c;  // input, method, step_s, ok (the names hold no comma)
    std::stringstream ss(line);
    for (std::string cell; c.size() < 4 && std::getline(ss, cell, ',');) c.push_back(cell);
    REQUIRE(c.size() == 4);
    if (c[1] == "backward_euler") {
      ++backward;
      backward_ok += c[3] == "1";
    }
    if (c[0] == "four functions" && c[1] == "forward_euler" && c[2] == "0.01" && c[3] == "0")
      stopped = line.find("pressure_method forward_euler at step 0.01 s") != std::string::npos;
  }
  CHECK(rows >= 2 * 2 * 3);
  CHECK(backward == 2 * 3);
  CHECK(backward_ok == backward);
  CHECK(stopped);
  REQUIRE(j.contains("pressure_integration"));
  CHECK(j["pressure_integration"].size() == 2);
}

// One recommended fidelity per scene: within tolerance, the cheapest up to the timing noise (15 %), and
// no simpler model (a later row) within tolerance at an equal cost.
void check_recommendations(const fs::path& csv) {
  REQUIRE(fs::exists(csv));
  std::ifstream f(csv);
  std::string header, line;
  std::getline(f, header);
  auto column = [&](const std::string& name) {
    int index = 0;
    std::size_t start = 0;
    for (std::size_t end; (end = header.find(',', start)) != std::string::npos; start = end + 1, ++index)
      if (header.substr(start, end - start) == name) return index;
    return header.substr(start) == name ? index : -1;
  };
  const int c_scene = column("scene"), c_within = column("within_tolerance"), c_rec = column("recommended"),
            c_cpu = column("cpu_s_per_sim_s");
  REQUIRE(c_scene >= 0);
  REQUIRE(c_within >= 0);
  REQUIRE(c_rec >= 0);
  REQUIRE(c_cpu >= 0);
  struct Row {
    std::string scene;
    bool within, recommended;
    double cpu;
  };
  std::vector<Row> rows;
  while (std::getline(f, line)) {
    if (line.empty()) continue;
    std::vector<std::string> cells;
    std::size_t start = 0;
    for (std::size_t end; (end = line.find(',', start)) != std::string::npos && line[start] != '"'; start = end + 1)
      cells.push_back(line.substr(start, end - start));
    cells.push_back(line.substr(start));
    REQUIRE(static_cast<int>(cells.size()) > std::max({c_scene, c_within, c_rec, c_cpu}));
    rows.push_back({cells[c_scene], cells[c_within] == "1", cells[c_rec] == "1",
                    cells[c_cpu].empty() ? NAN : std::atof(cells[c_cpu].c_str())});
  }
  for (const char* scene : {"free_motion", "dig"}) {
    INFO(scene);
    int recommended = -1, count = 0;
    double cheapest = INFINITY;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      if (rows[i].scene != scene) continue;
      if (rows[i].recommended) recommended = static_cast<int>(i), ++count;
      if (rows[i].within) cheapest = std::min(cheapest, rows[i].cpu);
    }
    REQUIRE(count == 1);
    CHECK(rows[recommended].within);
    CHECK(rows[recommended].cpu <= 1.15 * cheapest + 1e-12);
    // No simpler model (a later row) within tolerance at an equal cost.
    for (std::size_t i = recommended + 1; i < rows.size(); ++i)
      if (rows[i].scene == scene) CHECK_FALSE((rows[i].within && rows[i].cpu <= 1.15 * cheapest));
  }
}
}  // namespace

TEST_CASE("tools/excavator-bench --quick writes its json and csvs and recommends one fidelity per scene") {
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
  // Independent coordinates close the loops in closed form: the constraint error is round-off.
  CHECK(j["constraint_error"].get<double>() < 1e-9);
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
  // One row per point of each grid: 2 scenes x 9 integrators x 3 steps; 9 integrators x (2 soil
  // stiffnesses + 2 joint speeds); 2 scenes x 2 engines.
  CHECK(data_lines(out / "work_precision.csv") == 2 * 9 * 3);
  CHECK(data_lines(out / "stability_step.csv") == 9 * (2 + 2));
  CHECK(data_lines(out / "peer.csv") == 2 * 2);
  for (const char* csv : {"peer_tip.csv", "fidelity.csv", "stability_control.csv"}) {
    INFO(csv);
    CHECK(data_lines(out / csv) > 0);
  }
  check_pressure_integration(out / "pressure_integration.csv", j);
  check_convergence_orders(out / "work_precision.csv");
  check_recommendations(out / "fidelity.csv");
}