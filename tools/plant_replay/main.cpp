// excavator-plant-replay: run a scene open-loop from a CSV of efforts, without the firmware, and
// write the plant's state at every cycle. Exit 0: ran to the end; 1: the plant stopped (its message
// on stderr); 2: bad input (file, line and reason on stderr).
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "model/scene_common.hpp"
#include "option_checks.hpp"

#include "output_file.hpp"
#include "sim_plant/plant.hpp"

namespace {

struct Row {
  double t = 0;
  exc::Vec4 value = exc::Vec4::Zero();
};

// CSV: a header line, then t,swing,boom,arm,bucket with t increasing, every value finite; valve
// openings (a hydraulic scene) within -1..1. A bad cell is named by its line and column here, not by
// the plant when it reaches it.
std::vector<Row> read_efforts(const std::string& path, bool valve_openings) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the file");
  std::vector<Row> rows;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    if (number == 1 && line.find_first_of("abcdefghijklmnopqrstuvwxyz") != std::string::npos) continue;  // header
    std::stringstream ss(line);
    Row r;
    std::string cell;
    double v[5];
    int n = 0;
    while (std::getline(ss, cell, ',') && n < 6) {
      try {
        std::size_t used = 0;
        v[n < 5 ? n : 4] = std::stod(cell, &used);
        if (cell.find_first_not_of(" \t\r", used) != std::string::npos) throw std::invalid_argument("");
      } catch (const std::exception&) {
        throw std::runtime_error(path + ":" + std::to_string(number) + ": column " + std::to_string(n + 1) +
                                 " is not a number: '" + cell + "'");
      }
      ++n;
    }
    if (n != 5)
      throw std::runtime_error(path + ":" + std::to_string(number) +
                               ": expected 5 columns t,swing,boom,arm,bucket, found " + std::to_string(n));
    const char* const columns[5] = {"t", "swing", "boom", "arm", "bucket"};
    for (int c = 0; c < 5; ++c) {
      const std::string place = path + ":" + std::to_string(number) + ": column " + std::to_string(c + 1) + " (" + columns[c] + ")";
      std::ostringstream value;
      value << v[c];
      if (!std::isfinite(v[c])) throw std::runtime_error(place + " is " + value.str() + ": a finite number is required");
      if (valve_openings && c > 0 && std::abs(v[c]) > 1)
        throw std::runtime_error(place + " is " + value.str() +
                                 ": the scene's actuators are hydraulic, so the columns are valve openings, allowed range [-1, 1]");
    }
    r.t = v[0];
    r.value = exc::Vec4(v[1], v[2], v[3], v[4]);
    if (!rows.empty() && !(r.t > rows.back().t))
      throw std::runtime_error(path + ":" + std::to_string(number) + ": t must increase (" + std::to_string(r.t) + ")");
    rows.push_back(r);
  }
  if (rows.empty()) throw std::runtime_error(path + ": no rows of efforts");
  return rows;
}

}  // namespace

int main(int argc, char** argv) {
  exc::output::check_stdout_at_exit("excavator-plant-replay");  // stdout lost to a full disk is not exit 0
  CLI::App app{
      "Runs a scene open-loop from a CSV of efforts (zero-order hold) and writes the plant's state at every "
      "cycle.\nCSV columns: t,swing,boom,arm,bucket: swing torque (N m) and cylinder forces (N, positive pushes "
      "longer); for actuators.fidelity hydraulic, valve openings -1..1 instead.",
      "excavator-plant-replay"};
  std::string scene_path, efforts_path, out_path;
  double duration = 0;
  app.add_option("--scene", scene_path, "scene file (YAML, docs/scene-schema.md)")->required();
  app.add_option("--efforts", efforts_path, "CSV of efforts t,swing,boom,arm,bucket")->required();
  app.add_option("--out", out_path, "output CSV (default: standard output)");
  app.add_option("--duration", duration, "simulated seconds (default: the scene's duration)")
      ->check(exc::cli::number_in(exc::kRunDurationBounds, "s"));
  CLI11_PARSE(app, argc, argv);

  std::vector<Row> rows;
  exc::plant::Scene scene;
  try {
    scene = exc::plant::load_scene(scene_path);
    rows = read_efforts(efforts_path, scene.actuators.fidelity == exc::plant::ActuatorFidelity::hydraulic);
  } catch (const std::exception& e) {
    std::cerr << "excavator-plant-replay: " << e.what() << "\n";
    return 2;
  }
  if (duration <= 0) duration = scene.duration;
  std::FILE* out = stdout;
  if (!out_path.empty()) {
    out = std::fopen(out_path.c_str(), "w");
    if (!out) {
      std::cerr << "excavator-plant-replay: " << out_path << ": cannot write\n";
      return 2;
    }
  }
  exc::plant::Plant plant(scene);
  if (!plant.status().ok()) {
    std::cerr << "excavator-plant-replay: " << plant.status().text() << "\n";
    return 1;
  }
  std::fprintf(out,
               "t,q_swing,q_boom,q_arm,q_bucket,qd_swing,qd_boom,qd_arm,qd_bucket,effort_swing,effort_boom,"
               "effort_arm,effort_bucket,tip_x,tip_z,soil_fx,soil_fz,anchor_x,anchor_z,in_soil,depth,reanchors,"
               "kinetic_energy,potential_energy,energy_error,constraint_residual,p_a_boom,p_a_arm,p_a_bucket,"
               "p_b_boom,p_b_arm,p_b_bucket\n");
  exc::plant::ActuatorCommand cmd;
  cmd.mode = scene.actuators.fidelity == exc::plant::ActuatorFidelity::hydraulic ? exc::plant::ActuatorCommand::valve
                                                                                 : exc::plant::ActuatorCommand::effort;
  const long cycles = std::lround(duration / scene.cycle);
  std::size_t row = 0;
  int rc = 0;
  for (long k = 0; k < cycles; ++k) {
    const double t_start = k * scene.cycle;
    while (row + 1 < rows.size() && rows[row + 1].t <= t_start + 1e-9) ++row;
    cmd.value = rows[row].t <= t_start + 1e-9 ? rows[row].value : exc::Vec4::Zero();
    const exc::plant::PlantStatus st = plant.step(cmd);
    if (!st.ok()) {
      std::cerr << "excavator-plant-replay: " << st.text() << "\n";
      rc = 1;
      break;
    }
    const exc::plant::PlantState& s = plant.state();
    std::fprintf(out, "%.6f", s.time);
    for (int i = 0; i < 4; ++i) std::fprintf(out, ",%.17g", s.q_a[i]);
    for (int i = 0; i < 4; ++i) std::fprintf(out, ",%.17g", s.qd_a[i]);
    for (int i = 0; i < 4; ++i) std::fprintf(out, ",%.10g", s.effort[i]);
    std::fprintf(out, ",%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%d,%.10g,%d,%.10g,%.10g,%.6g,%.6g", s.rho.x(), s.rho.y(),
                 s.soil_force.x(), s.soil_force.y(), s.soil_anchor.x(), s.soil_anchor.y(), s.in_soil ? 1 : 0, s.depth,
                 s.reanchor_count, s.kinetic_energy, s.potential_energy, s.energy_error, s.constraint_residual);
    for (int i = 1; i < 4; ++i) std::fprintf(out, ",%.8g", s.pressure_a[i]);
    for (int i = 1; i < 4; ++i) std::fprintf(out, ",%.8g", s.pressure_b[i]);
    std::fprintf(out, "\n");
  }
  // A write to --out that failed (disk full) is an error, not a short file with exit 0; standard
  // output is checked at exit (check_stdout_at_exit).
  if (out != stdout) {
    const bool failed = std::ferror(out) != 0;
    if (std::fclose(out) != 0 || failed) {
      std::cerr << "excavator-plant-replay: " << out_path << ": cannot write\n";
      return 2;
    }
  }
  return rc;
}
