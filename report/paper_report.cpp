#include "paper_report.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

namespace exc::sim {
namespace {

namespace fs = std::filesystem;

const char* const kJoint[4] = {"swing", "boom", "arm", "bucket"};
const char* const kPaperName[4] = {"Swing motor", "Boom cylinder", "Arm cylinder", "Bucket cylinder"};

const RunRecord* find(const Summary& s, const char* controller) {
  for (const RunRecord& r : s.runs)
    if (r.controller == controller) return &r;
  return nullptr;
}

// "1.53 mm" for a cylinder, "0.42 mrad" for the swing; "n/a" without the run.
std::string amount(const RunRecord* r, const double (RunRecord::*field)[4], int joint) {
  if (r == nullptr || r->tracking_samples == 0) return "n/a";
  char b[48];
  std::snprintf(b, sizeof b, "%.3g %s", (r->*field)[joint] * 1e3, joint == 0 ? "mrad" : "mm");
  return b;
}

std::string figures_of(const RunRecord* pid, const RunRecord* adaptive, int j) {
  return "RMS error PID " + amount(pid, &RunRecord::rms_error, j) + ", adaptive " +
         amount(adaptive, &RunRecord::rms_error, j) + "; worst PID " + amount(pid, &RunRecord::max_error, j) +
         ", adaptive " + amount(adaptive, &RunRecord::max_error, j);
}

std::string image(const fs::path& out, const SceneJobResult& scene, const std::string& png) {
  return fs::relative(scene.out_dir / "report" / png, out).generic_string();
}

std::string verdict(const Summary& s) {
  std::string v;
  for (const RunRecord& r : s.runs) v += r.controller + (r.ok ? " ok" : " FAILED (" + r.failure + ")") + "; ";
  return v.empty() ? "no runs" : v.substr(0, v.size() - 2);
}

}  // namespace

// The dig through the valves: the three controllers' figures and the circuit's, in a table.
void write_hydraulic_section(std::ostream& md, const fs::path& out, const SceneJobResult& h, const SceneJobResult& force) {
  md << "## Beyond the paper: the same dig through a hydraulic machine's valves\n\n"
     << h.summary.scene << ": " << h.summary.setup << ". Runs: " << verdict(h.summary) << ". The firmware commands "
     << "pilot pressures; the paper's laws produce the efforts and the valve stage (a force loop on the measured "
     << "chamber pressures, the inverse orifice map, dead-zone compensation) turns them into spool openings; "
        "flow-based position control, the industry's baseline, commands the valves' flow from the desired "
        "velocity and the position error, with no model ([report](" << image(out, h, "report.md") << ")).\n\n"
     << "| controller | RMS error swing / boom / arm / bucket | worst | pressures | pumps short of flow |\n"
     << "|---|---|---|---|---|\n";
  for (const RunRecord& r : h.summary.runs) {
    char row[400];
    std::snprintf(row, sizeof row,
                  "| %s | %.3g mrad / %.3g / %.3g / %.3g mm | %.3g mrad / %.3g / %.3g / %.3g mm | %.2f .. %.1f MPa | "
                  "%.2f s |\n",
                  r.controller.c_str(), r.rms_error[0] * 1e3, r.rms_error[1] * 1e3, r.rms_error[2] * 1e3,
                  r.rms_error[3] * 1e3, r.max_error[0] * 1e3, r.max_error[1] * 1e3, r.max_error[2] * 1e3,
                  r.max_error[3] * 1e3, r.min_pressure * 1e-6, r.peak_pressure * 1e-6, r.flow_saturated_seconds);
    md << row;
  }
  const RunRecord* pid = find(h.summary, "pid");
  const RunRecord* ad = find(h.summary, "adaptive");
  const RunRecord* fpid = find(force.summary, "pid");
  const RunRecord* fad = find(force.summary, "adaptive");
  if (pid && ad && fpid && fad && ad->rms_error[2] > 0 && ad->rms_error[3] > 0 && fad->rms_error[2] > 0 &&
      fad->rms_error[3] > 0) {
    char b[320];
    std::snprintf(b, sizeof b,
                  "\nThrough the valves PID's RMS error is %.1fx the adaptive law's on the arm and %.1fx on the bucket; "
                  "with the paper's force actuators (Figs. 11-12) it was %.1fx and %.1fx. The adaptive law keeps its "
                  "lead where the paper puts it, smaller: the force loop's lag sits between the law and the soil.\n",
                  pid->rms_error[2] / ad->rms_error[2], pid->rms_error[3] / ad->rms_error[3],
                  fpid->rms_error[2] / fad->rms_error[2], fpid->rms_error[3] / fad->rms_error[3]);
    md << b;
  }
  md << "\n![bucket](" << image(out, h, "tracking_bucket.png") << ") ![errors](" << image(out, h, "tracking_error.png")
     << ")\n";
}

bool write_paper_report(const fs::path& out, const SceneJobResult& free_motion, const SceneJobResult& dig,
                        const SceneJobResult& hydraulic_dig) {
  std::ofstream md(out / "report.md");
  const RunRecord* fm_pid = find(free_motion.summary, "pid");
  const RunRecord* fm_ad = find(free_motion.summary, "adaptive");
  const RunRecord* d_pid = find(dig.summary, "pid");
  const RunRecord* d_ad = find(dig.summary, "adaptive");
  md << "# The paper's figures: free motion (Figs. 4-7) and digging (Figs. 8-12)\n\n"
     << "Kim, Yoo and Lee, \"Geometric Modeling and Trajectory Control Design for an Excavator Mechanism\": "
        "the firmware against the simulated machine over the in-memory CAN bus, each scene with the paper's "
        "inverse dynamics + PID and its adaptive computed torque. The paper gives no numbers; these are this "
        "run's. Each scene's own report has every other figure: ["
     << free_motion.summary.scene << "](" << image(out, free_motion, "report.md") << "), [" << dig.summary.scene
     << "](" << image(out, dig, "report.md") << ").\n\n"
     << "- " << free_motion.summary.scene << ": " << free_motion.summary.setup << ". Runs: " << verdict(free_motion.summary)
     << ".\n"
     << "- " << dig.summary.scene << ": " << dig.summary.setup << ". Runs: " << verdict(dig.summary) << ".\n\n";

  md << "## Free motion (paper 5.1)\n\nThe paper drives the four active joints along arbitrary joint "
        "trajectories with the bucket clear of the ground; with no external force, inverse dynamics + PID "
        "tracks each of them. Desired against actual, PID left, adaptive right (the adaptive law has no "
        "soil to adapt to here).\n\n";
  for (int j = 0; j < 4; ++j) {
    md << "### Fig. " << 4 + j << " " << kPaperName[j] << "\n\n![Fig. " << 4 + j << "]("
       << image(out, free_motion, std::string("tracking_") + kJoint[j] + ".png") << ")\n\n"
       << "Paper: the " << kJoint[j] << " follows its desired trajectory under PID. This run: "
       << figures_of(fm_pid, fm_ad, j) << ".\n\n";
  }

  md << "## Digging (paper 5.2)\n\n";
  char force[160] = "n/a";
  if (d_pid && d_ad)
    std::snprintf(force, sizeof force, "peak |F| %.1f kN (PID) and %.1f kN (adaptive), %d and %d shear re-anchorings",
                  d_pid->peak_soil_force * 1e-3, d_ad->peak_soil_force * 1e-3, d_pid->reanchor_count,
                  d_ad->reanchor_count);
  md << "### Fig. 8 Reaction force at the bucket tip\n\n![Fig. 8](" << image(out, dig, "soil_force.png") << ")\n\n"
     << "Paper: the soil's reaction zig-zags as the soil shears and the anchor moves (eqs. 9-11). This run: "
     << force << ".\n\n";
  for (int j = 0; j < 2; ++j) {
    md << "### Fig. " << 9 + j << " " << kPaperName[j] << "\n\n![Fig. " << 9 + j << "]("
       << image(out, dig, std::string("tracking_") + kJoint[j] + ".png") << ")\n\n"
       << "Paper: swing and boom track well under both controllers (shown once). This run: "
       << figures_of(d_pid, d_ad, j) << ".\n\n";
  }
  for (int j = 2; j < 4; ++j) {
    std::string ratio;
    if (d_pid && d_ad && d_ad->rms_error[j] > 0) {
      char b[64];
      std::snprintf(b, sizeof b, "; PID's RMS error is %.1fx the adaptive law's", d_pid->rms_error[j] / d_ad->rms_error[j]);
      ratio = b;
    }
    md << "### Fig. " << 9 + j << " " << kPaperName[j] << " - PID control (left), adaptive control (right)\n\n![Fig. "
       << 9 + j << "](" << image(out, dig, std::string("tracking_") + kJoint[j] + ".png") << ")\n\n"
       << "Paper: the arm and bucket, most loaded by the soil, drift from the desired position under PID and "
          "track under the adaptive law. This run: "
       << figures_of(d_pid, d_ad, j) << ratio << ".\n\n";
  }
  md << "Beyond the paper: the soil estimates against the true values (![estimates]("
     << image(out, dig, "soil_estimates.png") << ")) and the tracking errors of both scenes (![free motion]("
     << image(out, free_motion, "tracking_error.png") << ") ![digging](" << image(out, dig, "tracking_error.png")
     << ")).\n\n";
  write_hydraulic_section(md, out, hydraulic_dig, dig);
  md.flush();  // a write that fails at the end (disk full) is a failure too
  return static_cast<bool>(md);
}

}  // namespace exc::sim
