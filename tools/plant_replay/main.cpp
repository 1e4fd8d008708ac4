// excavator-plant-replay: run a scene open-loop from a CSV of efforts, without the firmware, and
// write the plant's state at every cycle. Exit 0: ran to the end; 1: the plant stopped (its message
// on stderr); 2: bad input (file, line and reason on stderr).
#include <cmath>
#include <cstdlib>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "model/scene_common.hpp"
#include "option_checks.hpp"

#include "app/float_environment.hpp"
#include "output_files/output_file.hpp"
#include "sim_plant/plant.hpp"

namespace {

struct Row {
  double t = 0;
  exc::Vec4 value = exc::Vec4::Zero();
};

// The cells of one CSV line, a trailing empty cell included ("1,2," is three cells).
std::vector<std::string> split_cells(const std::string& line) {
  std::vector<std::string> cells(1);
  for (const char ch : line) {
    if (ch == ',')
      cells.emplace_back();
    else
      cells.back() += ch;
  }
  return cells;
}

// The whole cell as a number (blanks and a CR around it allowed), or false. strtod, not stod: a
// subnormal value is a number, and one beyond the double range reads as infinite (refused as such).
bool parse_number(const std::string& cell, double& value) {
  const char* begin = cell.c_str();
  char* end = nullptr;
  value = std::strtod(begin, &end);
  if (end == begin) return false;
  return cell.find_first_not_of(" \t\r", static_cast<std::size_t>(end - begin)) == std::string::npos;
}

std::string shortest(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

// CSV: an optional header line (the first line whose first cell is not a number: a data line such
// as "0,1e3,..." is data, not a header), then t,swing,boom,arm,bucket with t increasing, every value
// finite; valve openings (a hydraulic scene) within -1..1. A bad cell is named by its line and
// column here, not by the plant when it reaches it.
std::vector<Row> read_efforts(const std::string& path, bool valve_openings) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the file");
  std::vector<Row> rows;
  std::string line;
  int number = 0;
  bool first_content_line = true;
  const char* const columns[5] = {"t", "swing", "boom", "arm", "bucket"};
  while (std::getline(in, line)) {
    ++number;
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
    const std::vector<std::string> cells = split_cells(line);
    double v[5];
    if (first_content_line) {
      first_content_line = false;
      if (!parse_number(cells[0], v[0])) continue;  // the header
    }
    const std::string at = path + ":" + std::to_string(number);
    if (cells.size() != 5)
      throw std::runtime_error(at + ": expected 5 columns t,swing,boom,arm,bucket, found " +
                               std::to_string(cells.size()));
    for (int c = 0; c < 5; ++c) {
      const std::string place = at + ": column " + std::to_string(c + 1) + " (" + columns[c] + ")";
      if (!parse_number(cells[c], v[c])) throw std::runtime_error(place + " is not a number: '" + cells[c] + "'");
      if (!std::isfinite(v[c])) throw std::runtime_error(place + " is " + shortest(v[c]) + ": a finite number is required");
      if (valve_openings && c > 0 && std::abs(v[c]) > 1)
        throw std::runtime_error(place + " is " + shortest(v[c]) +
                                 ": the scene's actuators are hydraulic, so the columns are valve openings, allowed range [-1, 1]");
    }
    Row r;
    r.t = v[0];
    r.value = exc::Vec4(v[1], v[2], v[3], v[4]);
    if (!rows.empty() && !(r.t > rows.back().t))
      throw std::runtime_error(at + ": column 1 (t) is " + shortest(r.t) + ": t must increase (the line before has " +
                               shortest(rows.back().t) + ")");
    rows.push_back(r);
  }
  if (rows.empty()) throw std::runtime_error(path + ": no rows of efforts");
  return rows;
}

}  // namespace

int main(int argc, char** argv) {
  exc::output::check_stdout_at_exit("excavator-plant-replay");  // stdout lost to a full disk is not exit 0
  exc::app::set_loop_float_mode();  // the plant steps as in the loop (docs/floating-point.md)
  CLI::App app{
      "Runs a scene open-loop from a CSV of efforts (zero-order hold) and writes the plant's state at every "
      "cycle.\nCSV columns: t,swing,boom,arm,bucket: swing torque (N m) and cylinder forces (N, positive pushes "
      "longer); for an actuators.fidelity that takes valve commands (hydraulic), valve openings -1..1 instead. An optional header line (its first "
      "cell not a number), blank lines and lines starting with # are skipped.",
      "excavator-plant-replay"};
  std::string scene_path, efforts_path, out_path;
  double duration = 0;
  app.add_option("--scene", scene_path, "scene file (YAML, docs/scene-schema.md)")->required();
  app.add_option("--efforts", efforts_path, "CSV of efforts t,swing,boom,arm,bucket")->required();
  app.add_option("--out", out_path, "output CSV (default: standard output)");
  app.add_option("--duration", duration, "simulated seconds (default: the scene's duration)")
      ->check(exc::cli::number_in(exc::kRunDurationBounds, "s"));
  if (const auto status = exc::cli::parse_command_line(app, argc, argv)) return *status;

  std::vector<Row> rows;
  exc::plant::Scene scene;
  try {
    scene = exc::plant::load_scene(scene_path);
    rows = read_efforts(efforts_path, exc::plant::fidelity_of(scene.actuators).takes_valves());
  } catch (const std::exception& e) {
    std::cerr << "excavator-plant-replay: " << e.what() << "\n";
    return 2;
  }
  if (duration <= 0) duration = scene.duration;
  std::FILE* out = stdout;
  if (!out_path.empty()) {
    out = std::fopen(out_path.c_str(), "w");
    if (!out) {
      std::cerr << "excavator-plant-replay: " << out_path << ": cannot write (" << std::strerror(errno) << ")\n";
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
  cmd.mode = plant.fidelity().takes_valves() ? exc::plant::ActuatorCommand::valve : exc::plant::ActuatorCommand::effort;
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
    errno = 0;
    if (std::fclose(out) != 0 || failed) {
      // fclose's errno when it failed (the last flush); a write that failed earlier left none.
      std::cerr << "excavator-plant-replay: " << out_path << ": cannot write"
                << (errno != 0 ? std::string(" (") + std::strerror(errno) + ")" : std::string()) << "\n";
      return 2;
    }
  }
  return rc;
}
