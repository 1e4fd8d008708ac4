// excavator-model: the closed-chain model of the machine, one case per line on standard input.
//   excavator-model fk   q_a (4)               -> tip x y z (world, m), boom arm bucket angles (deg)
//   excavator-model id   q_a qd_a qdd_a (12)   -> tau_a (4): swing N m, cylinder forces N
//   excavator-model fd   q_a qd_a tau_a (12)   -> qdd_a (4)
// Gravity included; no soil, no friction. Output at full precision (%.17g). A bad line stops the run
// with its line number and the reason, exit status 2.
#include <CLI/CLI.hpp>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "model/closed_chain.hpp"
#include "model/forward_dynamics.hpp"
#include "output_files/output_file.hpp"
#include "option_checks.hpp"
#include "model/machine_reader.hpp"

namespace {

constexpr int kBadInput = 2;

// Splits a line into numbers; returns false with a reason if it is not exactly 'expected' of them.
bool parse_numbers(const std::string& line, int expected, std::vector<double>& out, std::string& reason) {
  out.clear();
  const char* p = line.c_str();
  while (true) {
    while (*p == ' ' || *p == '\t' || *p == '\r') ++p;
    if (*p == '\0') break;
    char* end = nullptr;
    errno = 0;
    const double x = std::strtod(p, &end);
    const char* token_end = p;
    while (*token_end && *token_end != ' ' && *token_end != '\t' && *token_end != '\r') ++token_end;
    if (end == p || end != token_end) {
      reason = "'" + std::string(p, token_end) + "' is not a number";
      return false;
    }
    if (!std::isfinite(x)) {
      reason = "'" + std::string(p, token_end) + "' is not finite";
      return false;
    }
    out.push_back(x);
    p = end;
  }
  if (static_cast<int>(out.size()) != expected) {
    reason = "expected " + std::to_string(expected) + " numbers, got " + std::to_string(out.size());
    return false;
  }
  return true;
}

std::string describe(const exc::ModelReport& r) {
  std::string s = exc::to_string(r.status);
  if (r.loop >= 0) s += " in loop " + std::to_string(r.loop) + " (Table 2)";
  if (r.status == exc::ModelStatus::near_toggle) s += ", conditioning " + std::to_string(r.conditioning);
  return s;
}

void print_row(const double* values, int n) {
  for (int i = 0; i < n; ++i) std::printf(i ? " %.17g" : "%.17g", values[i]);
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  exc::output::check_stdout_at_exit("excavator-model");  // stdout lost to a full disk is not exit 0
  CLI::App app{
      "excavator-model: the excavator's closed-chain model (paper Tables 1-2, eqs. 1, 14-17).\n"
      "Reads one case per line from standard input (whitespace-separated numbers) and writes one line\n"
      "per case, every number at full precision (%.17g). q_a = [swing rad, L_boom m, L_arm m,\n"
      "L_bucket m]; tau_a = [swing torque N m, boom, arm, bucket cylinder forces N, positive pushing];\n"
      "gravity included, no soil, no friction. A bad line stops the run: line number and reason on\n"
      "standard error, exit status 2."};
  app.require_subcommand(1);
  app.fallthrough();
  std::string machine_file;
  app.add_option("--machine", machine_file,
                 "Machine file (YAML, as machines/reference-20t.yaml); default: the built-in reference machine");
  app.add_subcommand("fk", "q_a (4 numbers) -> tip x y z in the world (m), boom, arm, bucket angles (deg)");
  app.add_subcommand("id", "q_a qd_a qdd_a (12 numbers) -> tau_a (4): inverse dynamics");
  app.add_subcommand("fd", "q_a qd_a tau_a (12 numbers) -> qdd_a (4): forward dynamics");
  if (const auto status = exc::cli::parse_command_line(app, argc, argv)) return *status;
  const std::string mode = app.get_subcommands().front()->get_name();

  exc::Machine machine;
  try {
    machine = machine_file.empty() ? exc::reference_machine() : exc::load_machine(machine_file);
  } catch (const exc::SettingsError& e) {
    std::fprintf(stderr, "excavator-model: %s\n", e.what());
    return kBadInput;
  }
  const exc::Model model = exc::build_model(machine);
  exc::Workspace ws(model);

  const int expected = mode == "fk" ? 4 : 12;
  std::vector<double> v;
  std::string line, reason;
  long line_number = 0;
  while (std::getline(std::cin, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;  // blank lines separate nothing
    auto bad = [&](const std::string& why) {
      std::fflush(stdout);
      std::fprintf(stderr, "excavator-model %s: line %ld: %s\n", mode.c_str(), line_number, why.c_str());
      return kBadInput;
    };
    if (!parse_numbers(line, expected, v, reason)) return bad(reason);
    const exc::Vec4 q_a(v[0], v[1], v[2], v[3]);
    const exc::Vec4 qd_a = expected == 12 ? exc::Vec4(v[4], v[5], v[6], v[7]) : exc::Vec4::Zero();
    const exc::Vec4 third = expected == 12 ? exc::Vec4(v[8], v[9], v[10], v[11]) : exc::Vec4::Zero();
    if (mode == "fd") {
      exc::Vec4 qdd_a;
      const exc::ModelReport r = exc::forward_dynamics(model, ws, q_a, qd_a, third, exc::TipLoad{}, qdd_a);
      if (!r.ok()) return bad(describe(r));
      print_row(qdd_a.data(), 4);
      continue;
    }
    const exc::ModelReport r = exc::update_closed_chain(model, ws, q_a, qd_a);
    if (!r.ok()) return bad(describe(r));
    if (mode == "fk") {
      const double out[6] = {ws.tip_world.x(), ws.tip_world.y(), ws.tip_world.z(),
                             ws.q[exc::kBoom] * 180.0 / M_PI, ws.q[exc::kArm] * 180.0 / M_PI,
                             ws.q[exc::kBucket] * 180.0 / M_PI};
      print_row(out, 6);
    } else {
      exc::Vec4 tau_a;
      exc::inverse_dynamics(model, ws, third, exc::Vec2::Zero(), tau_a);
      print_row(tau_a.data(), 4);
    }
  }
  return 0;
}
