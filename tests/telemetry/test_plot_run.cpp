// plot-run end to end: a small two-controller log written by the publisher, exported and drawn by
// `excavator-log report` (export to CSV, then plot-run). Checks the files, not the pixels: every figure exists, is a
// PNG of the documented size (1200 x 700) and not trivially small, and the report embeds them.
#include <doctest/doctest.h>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "exlcm/controller_state_t.hpp"
#include "exlcm/machine_state_t.hpp"
#include "exlcm/timing_t.hpp"
#include "matplotlib_probe.hpp"
#include "png_size.hpp"
#include "telemetry/telemetry_publisher.hpp"

namespace fs = std::filesystem;
using exc::test::png_size;
using exc::telemetry::Channel;
using exc::telemetry::LcmOutput;
using exc::telemetry::TelemetryConfig;
using exc::telemetry::TelemetryPublisher;

namespace {

// A made-up run: sinusoidal references, an error that is larger for "pid", a saw-tooth soil force
// (with_soil) and estimates converging on the truth (with_soil; the PID baseline publishes zeros).
void publish_synthetic_run(TelemetryPublisher& publisher, double error_scale, bool with_soil = true) {
  const double pi = std::acos(-1.0);
  for (std::int64_t k = 0; k < 2000; ++k) {
    const double t = k * 1e-3;
    exlcm::machine_state_t state{};
    exlcm::controller_state_t ctrl{};
    state.utime = ctrl.utime = k * 1000;
    for (int j = 0; j < 4; ++j) {
      ctrl.q_desired[j] = (j == 0 ? 0.0 : 2.0) + 0.3 * std::sin(2 * pi * 0.5 * t + j);
      ctrl.error[j] = error_scale * 0.01 * std::sin(2 * pi * 2 * t + j);
      state.q_active[j] = ctrl.q_desired[j] + ctrl.error[j];
    }
    if (with_soil) {
      state.soil_force[0] = 4e4 * std::fmod(t, 0.25) / 0.25;
      state.soil_force[1] = -2e4 * std::fmod(t, 0.25) / 0.25;
    }
    for (int i = 0; i < 6; ++i) {
      ctrl.theta_true[i] = with_soil ? 1000.0 * (i + 1) : std::nan("");
      ctrl.theta_hat[i] = with_soil ? ctrl.theta_true[i] * (1 - std::exp(-t)) : 0.0;
    }
    publisher.publish(Channel::state, state);
    publisher.publish(Channel::controller, ctrl);
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  exlcm::timing_t timing{};
  timing.utime = 2000 * 1000;
  timing.stage = 0;
  timing.count = 2000;
  timing.bin_width_us = 10;
  for (int b = 0; b < 64; ++b) timing.bins[b] = b < 20 ? 100 * std::exp(-0.3 * (b - 8) * (b - 8)) : 0;
  timing.p99_us = 150;
  timing.max_us = 190;
  publisher.publish(Channel::timing, timing);
}

// An empty scratch directory of this test process's own.
fs::path fresh_dir(const std::string& prefix) {
  const fs::path dir = fs::temp_directory_path() / (prefix + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

}  // namespace

TEST_CASE("tools/plot-run draws every figure and the report from a small recorded log") {
  REQUIRE_MESSAGE(exc::test::matplotlib_available(), exc::test::kMatplotlibMissing);
  const fs::path dir = fresh_dir("exc-plot-run-");
  const fs::path log_path = dir / "run.lcm";
  {
    std::string error;
    auto output = LcmOutput::open("file://" + log_path.string() + "?mode=w", &error);
    REQUIRE_MESSAGE(output, error);
    for (const auto& [suffix, scale] : {std::pair<const char*, double>{"/pid", 5.0},
                                        std::pair<const char*, double>{"/adaptive", 1.0}}) {
      TelemetryConfig config;
      config.shared_output = output;
      config.channel_suffix = suffix;
      TelemetryPublisher publisher(config);
      REQUIRE(publisher.start(&error));
      publish_synthetic_run(publisher, scale);
      publisher.stop();
      CHECK(publisher.counters().dropped_overflow == 0);
    }
  }
  {
    std::ofstream summary(dir / "summary.json");
    summary << R"({"pid": {"rms_error_arm_m": 0.05, "p99_us": 150},)"
            << R"( "adaptive": {"rms_error_arm_m": 0.01, "p99_us": 160}})";
  }
  // excavator-log report = excavator-log export into out/csv, then plot-run on it.
  const std::string out_dir = (dir / "report").string();
  const std::string csv_dir = (dir / "report" / "csv").string();
  const std::string command = std::string(EXC_EXCAVATOR_LOG) + " report " + log_path.string() +
                              " --out " + out_dir + " --summary " +
                              (dir / "summary.json").string() + " >/dev/null";
  REQUIRE(std::system(command.c_str()) == 0);
  CHECK(fs::exists(fs::path(csv_dir) / "EXC_STATE__pid.csv"));
  CHECK(fs::exists(fs::path(csv_dir) / "EXC_CONTROLLER__adaptive.csv"));

  std::ifstream report_file(fs::path(out_dir) / "report.md");
  REQUIRE(report_file.good());
  std::stringstream report;
  report << report_file.rdbuf();
  CHECK(report.str().find("rms_error_arm_m") != std::string::npos);
  CHECK(report.str().find("| quantity | pid | adaptive |") != std::string::npos);
  // The RMS of a sine over whole periods is its amplitude / sqrt(2): 0.05 and 0.01 here.
  CHECK(report.str().find("| arm (m) | 0.03536 | 0.007071 |") != std::string::npos);
  // excavator-sim's summary shape: figures per controller, the baseline first, in mm.
  {
    std::ofstream summary(dir / "sim_summary.json");
    const char* run = R"({"rms_error": {"swing": 0, "boom": 0.0015, "arm": 0.0073, "bucket": 0.052},
      "max_error": {"swing": 0, "boom": 0.004, "arm": 0.02, "bucket": 0.11}, "peak_soil_force": 13100,
      "reanchor_count": 25, "control_step_us": {"median": 7, "p99": 10.5, "max": 200},
      "heap_allocations_in_loop": 0, "simulated_seconds": 10, "ok": true,
      "theta_hat": {"M_x": 1, "B_x": 2, "K_x": 3, "M_z": 4, "B_z": 5, "K_z": 6},
      "theta_true": {"M_x": 1, "B_x": 2, "K_x": 3, "M_z": 4, "B_z": 5, "K_z": 6}})";
    summary << "{\"adaptive\": " << run << ", \"pid\": " << run << ", \"scene\": \"dig\"}";
  }
  const std::string sim_out = (dir / "sim_report").string();
  REQUIRE(std::system((std::string(EXC_EXCAVATOR_LOG) + " report " + log_path.string() + " --out " + sim_out +
                       " --summary " + (dir / "sim_summary.json").string() + " >/dev/null")
                          .c_str()) == 0);
  std::ifstream sim_file(fs::path(sim_out) / "report.md");
  std::stringstream sim_report;
  sim_report << sim_file.rdbuf();
  CHECK(sim_report.str().find("| quantity | pid | adaptive |") != std::string::npos);
  CHECK(sim_report.str().find("| tracking: RMS error arm (mm) | 7.3 | 7.3 |") != std::string::npos);
  CHECK(sim_report.str().find("| peak soil force (kN) | 13.1 | 13.1 |") != std::string::npos);
  for (const char* name :
       {"tracking_swing.png", "tracking_boom.png", "tracking_arm.png", "tracking_bucket.png",
        "tracking_error.png", "soil_force.png", "soil_estimates.png", "loop_timing.png"}) {
    CAPTURE(std::string(name));
    const fs::path png = fs::path(out_dir) / name;
    REQUIRE(fs::exists(png));
    // A 1200 x 700 figure with axes, lines and text is tens of kilobytes; an empty canvas is ~5.
    CHECK(fs::file_size(png) > 15000);
    std::uint32_t width = 0;
    std::uint32_t height = 0;
    REQUIRE(png_size(png, &width, &height));
    CHECK(width == 1200);
    CHECK(height == 700);
    CHECK(report.str().find(std::string("(") + name + ")") != std::string::npos);
  }
  if (std::getenv("EXC_KEEP_PLOTS") == nullptr) fs::remove_all(dir);
}

// The report's table gives every phase of excavator-sim's summary (its "phases") and the hold's
// verdict, and says which phase each figure covers; the old table had the tracking figures alone.
TEST_CASE("tools/plot-run: the report's summary table gives the errors per phase and the hold's verdict against the tolerance") {
  REQUIRE_MESSAGE(exc::test::matplotlib_available(), exc::test::kMatplotlibMissing);
  const fs::path dir = fresh_dir("exc-plot-run-phases-");
  const fs::path log_path = dir / "run.lcm";
  {
    std::string error;
    auto output = LcmOutput::open("file://" + log_path.string() + "?mode=w", &error);
    REQUIRE_MESSAGE(output, error);
    for (const char* suffix : {"/pid", "/adaptive"}) {
      TelemetryConfig config;
      config.shared_output = output;
      config.channel_suffix = suffix;
      TelemetryPublisher publisher(config);
      REQUIRE(publisher.start(&error));
      publish_synthetic_run(publisher, 1.0);
      publisher.stop();
    }
  }
  // Two runs: the PID's hold past the tolerance on the arm (3.1 mm), the adaptive law's within it.
  auto run = [](double hold_arm, bool hold_ok) {
    std::ostringstream r;
    r << R"({"rms_error": {"swing": 0, "boom": 0.0015, "arm": 0.0073, "bucket": 0.002},
      "max_error": {"swing": 0, "boom": 0.004, "arm": 0.02, "bucket": 0.011}, "peak_soil_force": 13100,
      "reanchor_count": 25, "control_step_us": {"median": 7, "p99": 10.5, "max": 200},
      "heap_allocations_in_loop": 0, "simulated_seconds": 600, "ok": )" << (hold_ok ? "true" : "false") << R"(,
      "theta_hat": {"M_x": 1, "B_x": 2, "K_x": 3, "M_z": 4, "B_z": 5, "K_z": 6},
      "theta_true": {"M_x": 1, "B_x": 2, "K_x": 3, "M_z": 4, "B_z": 5, "K_z": 6},
      "holding_tolerance": {"swing": 0.0025, "boom": 0.0025, "arm": 0.0025, "bucket": 0.0025},
      "hold_ok": )" << (hold_ok ? "true" : "false") << R"(,
      "phases": {"tracking": {"samples": 10000, "seconds": 10, "rms_error": {"swing": 0, "boom": 0.0015, "arm": 0.0073, "bucket": 0.002},
                              "max_error": {"swing": 0, "boom": 0.004, "arm": 0.02, "bucket": 0.011}},
                 "settle": {"samples": 2000, "seconds": 2.0, "rms_error": {"swing": 0, "boom": 0.001, "arm": 0.001, "bucket": 0.001},
                            "max_error": {"swing": 0, "boom": 0.0031, "arm": 0.0042, "bucket": 0.0011}},
                 "hold": {"samples": 588000, "seconds": 588.0, "rms_error": {"swing": 0, "boom": 0.0008, "arm": 0.0009, "bucket": 0.0007},
                          "max_error": {"swing": 0, "boom": 0.0015, "arm": )" << hold_arm << R"(, "bucket": 0.0016},
                          "excursions": {"swing": 0, "boom": 0, "arm": )" << (hold_ok ? 0 : 2) << R"(, "bucket": 0}},
                 "stop": null}})";
    return r.str();
  };
  {
    std::ofstream summary(dir / "sim_summary.json");
    summary << "{\"adaptive\": " << run(0.0018, true) << ", \"pid\": " << run(0.0031, false) << ", \"scene\": \"hold\"}";
  }
  const std::string out = (dir / "report").string();
  REQUIRE(std::system((std::string(EXC_EXCAVATOR_LOG) + " report " + log_path.string() + " --out " + out + " --summary " +
                       (dir / "sim_summary.json").string() + " >/dev/null")
                          .c_str()) == 0);
  std::ifstream file(fs::path(out) / "report.md");
  std::stringstream report;
  report << file.rdbuf();
  const std::string text = report.str();
  CAPTURE(text);
  CHECK(text.find("| tracking: max error arm (mm) | 20 | 20 |") != std::string::npos);
  CHECK(text.find("| settle: max error arm (mm) | 4.2 | 4.2 |") != std::string::npos);
  CHECK(text.find("| hold: max error arm (mm) | 3.1 | 1.8 |") != std::string::npos);
  CHECK(text.find("| hold: time in it (s) | 588.0 | 588.0 |") != std::string::npos);
  CHECK(text.find("| hold: excursions past the tolerance (boom / arm / bucket) | 0 / 2 / 0 | 0 / 0 / 0 |") != std::string::npos);
  CHECK(text.find("| hold: verdict (holding tolerance) | NOT met: worst arm 3.1 mm against 2.5 mm | met: worst arm 1.8 mm against 2.5 mm |") !=
        std::string::npos);
  // A phase no run was in has no rows; the note says which phase each figure covers.
  CHECK(text.find("| stop:") == std::string::npos);
  CHECK(text.find("Which phase each figure covers") != std::string::npos);
  if (std::getenv("EXC_KEEP_PLOTS") == nullptr) fs::remove_all(dir);
}

TEST_CASE("tools/plot-run draws a run with empty panels (PID alone, no soil) without a plotting library's warning") {
  REQUIRE_MESSAGE(exc::test::matplotlib_available(), exc::test::kMatplotlibMissing);
  const fs::path dir = fresh_dir("exc-plot-run-empty-");
  const fs::path log_path = dir / "run.lcm";
  {
    std::string error;
    TelemetryConfig config;
    config.lcm_url = "file://" + log_path.string() + "?mode=w";
    config.channel_suffix = "/pid";
    TelemetryPublisher publisher(config);
    REQUIRE_MESSAGE(publisher.start(&error), error);
    publish_synthetic_run(publisher, 1.0, false);
    publisher.stop();
  }
  const fs::path err = dir / "stderr.txt";
  const std::string command = std::string(EXC_EXCAVATOR_LOG) + " report " + log_path.string() + " --out " +
                              (dir / "report").string() + " >/dev/null 2>" + err.string();
  REQUIRE(std::system(command.c_str()) == 0);
  std::ifstream in(err);
  std::stringstream text;
  text << in.rdbuf();
  INFO("stderr: " << text.str());
  // matplotlib warns "No artists with labels found to put in legend" for a legend over an empty panel.
  CHECK(text.str().find("No artists") == std::string::npos);
  CHECK(text.str().find("Warning") == std::string::npos);
  for (const char* name : {"soil_force.png", "soil_estimates.png", "tracking_error.png"}) {
    CAPTURE(std::string(name));
    CHECK(fs::exists(dir / "report" / name));
  }
  if (std::getenv("EXC_KEEP_PLOTS") == nullptr) fs::remove_all(dir);
}
