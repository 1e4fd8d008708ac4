// The Plant API: zero heap allocations over 10000 steps (every integrator, formulation and
// fidelity), end stops (ideal: reported; limited: held), step time, and the replay tool.
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <iterator>

#include "app/allocation_counter.hpp"
#include "scratch_files.hpp"
#include "plant_scenes.hpp"

using namespace exc;
using namespace exc::plant;

TEST_CASE("plant/step allocates nothing over 10000 steps (every integrator, formulation, fidelity, pressure method)") {
  REQUIRE(exc::app::allocation_counting_works());
  struct Config {
    std::string method, formulation, actuators, integrator;
  };
  std::vector<Config> configs;
  for (const std::string& m : exc::plant::test::methods())
    for (const char* f : exc::plant::test::kFormulations) configs.push_back({m, f, "fidelity: ideal", ""});
  for (const ActuatorFidelityEntry& a : actuator_fidelities().entries()) {
    configs.push_back({"semi_implicit_euler", "independent", "fidelity: " + a.name, ""});
    if (a.has(kHydraulicCircuit))
      configs.push_back({"semi_implicit_euler", "independent", "fidelity: " + a.name, "pressure_method: forward_euler"});
  }
  for (const Config& c : configs) {
    CAPTURE(c.method);
    CAPTURE(c.formulation);
    CAPTURE(c.actuators);
    CAPTURE(c.integrator);
    exc::plant::test::SceneText t;
    t.extra_integrator = c.integrator;
    t.method = c.method;
    t.formulation = c.formulation;
    t.actuators = c.actuators;
    t.terrain = "height: 1.9";  // the tip starts in the soil: the soil path runs too
    t.soil = "preset: loam";
    t.sensors = "position_noise: [1e-4, 1e-4, 1e-4, 1e-4], velocity_noise: [1e-3, 1e-3, 1e-3, 1e-3], seed: 7, "
                "latency_cycles: 2, position_quantum: [1e-4, 1e-4, 1e-4, 1e-4], pressure_noise: 5e3, pressure_quantum: 1e3";
    Plant p(t.scene());
    ActuatorCommand cmd;
    const bool valves = p.fidelity().takes_valves();
    cmd.mode = valves ? ActuatorCommand::valve : ActuatorCommand::effort;
    cmd.value = valves ? Vec4::Zero() : Vec4(p.hold_effort());
    p.step(cmd);  // first step outside the counter: nothing lazily allocated may hide
    std::size_t allocations = 0;
    int steps = 0;
    {
      exc::app::AllocationCounter counter;
      exc::app::EigenNoMallocScope no_eigen_malloc;
      for (int i = 0; i < 10000; ++i) {
        if (!p.step(cmd).ok()) break;
        ++steps;
      }
      allocations = counter.count();
    }
    CHECK(steps == 10000);
    CHECK(allocations == 0);
  }
}

TEST_CASE("plant/a failure report allocates nothing either") {
  exc::plant::test::SceneText t;
  Plant p(t.scene());
  ActuatorCommand cmd;
  cmd.value = Vec4(0, 4e6, 0, 0);  // slam the boom out
  std::size_t allocations = 0;
  PlantStatus st;
  {
    exc::app::AllocationCounter counter;
    for (int i = 0; i < 3000 && st.ok(); ++i) st = p.step(cmd);
    allocations = counter.count();
  }
  CHECK_FALSE(st.ok());
  CHECK(allocations == 0);
}

TEST_CASE("plant/end stop: ideal actuators report a cylinder driven through it, limited ones hold it") {
  exc::plant::test::SceneText t;
  Plant ideal(t.scene());
  ActuatorCommand cmd;
  cmd.value = ideal.hold_effort();
  cmd.value[1] += 2e5;  // the boom pushes out to its stop
  PlantStatus st;
  for (int i = 0; i < 5000 && st.ok(); ++i) st = ideal.step(cmd);
  REQUIRE(st.failure == PlantFailure::end_stop);
  const std::string msg = st.text();
  MESSAGE(msg);
  CHECK(msg.find("boom") != std::string::npos);
  CHECK(msg.find("fidelity limited") != std::string::npos);
  CHECK(st.time > 0);
  // Once stopped, the plant stays stopped with the same report.
  CHECK(ideal.step(cmd).failure == PlantFailure::end_stop);

  t.actuators = "fidelity: limited, lag: 0.01";
  Plant limited(t.scene());
  for (int i = 0; i < 5000; ++i) REQUIRE(limited.step(cmd).ok());
  const Machine& m = limited.scene().machine;
  CHECK(limited.state().q_a[1] == doctest::Approx(m.boom.max_length));
  CHECK(limited.state().end_stop_events > 0);
  // Speed limit: the boom never moved faster than its pump flow allows.
  CHECK(std::abs(limited.state().qd_a[1]) <= m.boom.max_speed + 1e-12);
}

TEST_CASE("plant/step time per integrator: the median keeps pace with the 1 kHz cycle four times over (printed)") {
  for (const std::string& m : exc::plant::test::methods()) {
    for (const char* f : exc::plant::test::kFormulations) {
      exc::plant::test::SceneText t;
      t.method = m;
      t.formulation = f;
      Plant p(t.scene());
      ActuatorCommand cmd;
      cmd.value = p.hold_effort();
      std::vector<double> us;
      for (int i = 0; i < 2000; ++i) {
        const auto a = std::chrono::steady_clock::now();
        p.step(cmd);
        us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - a).count());
      }
      std::nth_element(us.begin(), us.begin() + us.size() / 2, us.end());
      const double median = us[us.size() / 2];
      MESSAGE(std::string(m) << " / " << std::string(f) << ": median step " << median << " us (test build)");
      // A quarter of the 1 ms cycle: the plant must outrun the firmware's cycle with room for the
      // firmware, the bus and telemetry in the same lockstep process. Medians hold on a loaded machine;
      // the steps take 2-60 us (excavator-plant-bench has the real figures).
      CHECK(median < 250.0);
    }
  }
}

#ifdef EXC_PLANT_REPLAY
TEST_CASE("tools/excavator-plant-replay runs a scene from a CSV of efforts and writes the states") {
  const std::string dir = std::string(EXC_BINARY_DIR) + "/tests/plant";
  const std::string efforts = dir + "/replay_efforts.csv", out = dir + "/replay_out.csv";
  // Efforts: a force-commanded scene (the hydraulic ones take valve commands).
  Plant p(load_scene(std::string(EXC_SOURCE_DIR) + "/scenes/paper_free_motion.yaml"));
  const Vec4 hold = p.hold_effort();
  {
    std::ofstream f(efforts);
    f << "t,swing,boom,arm,bucket\n";
    f.precision(17);
    f << 0.0 << "," << hold[0] << "," << hold[1] << "," << hold[2] << "," << hold[3] << "\n";
    f << 0.05 << "," << hold[0] + 2000 << "," << hold[1] << "," << hold[2] << "," << hold[3] << "\n";
  }
  const std::string cmd = std::string(EXC_PLANT_REPLAY) + " --scene " + EXC_SOURCE_DIR +
                          "/scenes/paper_free_motion.yaml --efforts " + efforts + " --out " + out + " --duration 0.1";
  REQUIRE(std::system(cmd.c_str()) == 0);
  // The same run through the library: the tool's last line must match it.
  ActuatorCommand c;
  for (int k = 1; k <= 100; ++k) {
    c.value = hold;
    if ((k - 1) * 1e-3 >= 0.05 - 1e-12) c.value[0] += 2000;
    REQUIRE(p.step(c).ok());
  }
  std::ifstream in(out);
  std::string header, line, last;
  std::getline(in, header);
  CHECK(header.rfind("t,q_swing,q_boom,q_arm,q_bucket", 0) == 0);
  int rows = 0;
  while (std::getline(in, line)) {
    last = line;
    ++rows;
  }
  CHECK(rows == 100);
  double t = 0, q0 = 0;
  REQUIRE(std::sscanf(last.c_str(), "%lf,%lf", &t, &q0) == 2);
  CHECK(t == doctest::Approx(0.1));
  CHECK(q0 == doctest::Approx(p.state().q_a[0]).epsilon(1e-12));
  CHECK(std::abs(q0) > 1e-6);  // the swing torque step moved it
  // --help works; a bad file is refused with its name.
  CHECK(std::system((std::string(EXC_PLANT_REPLAY) + " --help > /dev/null").c_str()) == 0);
  CHECK(std::system((std::string(EXC_PLANT_REPLAY) + " --scene /no/such.yaml --efforts " + efforts +
                     " > /dev/null 2>&1").c_str()) != 0);
}

TEST_CASE("tools/excavator-plant-replay refuses a non-finite cell, a wrong column count, and on a hydraulic scene an opening beyond 1, at its line and column, and a failed write is exit 2") {
  const std::filesystem::path dir = exc::test::scratch_dir(std::filesystem::path(EXC_BINARY_DIR) / "tests" / "plant" /
                                                           ("replay_refusals_" + std::to_string(getpid())));
  // Exit status and stderr of a replay of `csv` on `scene` into `out`.
  auto replay = [&](const std::string& scene, const std::string& csv, const std::string& out, std::string& err,
                    const std::string& header = "t,swing,boom,arm,bucket\n") {
    const auto efforts = dir / "efforts.csv";
    std::ofstream(efforts) << header << csv;
    const std::string cmd = std::string(EXC_PLANT_REPLAY) + " --scene " + EXC_SOURCE_DIR + "/scenes/" + scene +
                            " --efforts " + efforts.string() + " --out " + out + " --duration 0.05 2> " +
                            (dir / "err.txt").string();
    const int raw = std::system(cmd.c_str());
    std::ifstream in(dir / "err.txt");
    err.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  };
  const std::string out = (dir / "out.csv").string();
  std::string err;
  // The controls: finite efforts on a force-commanded scene, openings within 1 on a hydraulic one.
  CHECK(replay("paper_dig.yaml", "0,0,1,2,3\n0.01,1,2,3,4\n", out, err) == 0);
  CHECK(err.empty());
  CHECK(replay("dig.yaml", "0,0,0.5,-0.2,1\n", out, err) == 0);
  CHECK(err.empty());
  for (const char* bad : {"nan", "inf", "-inf"}) {
    CHECK(replay("paper_dig.yaml", std::string("0,0,1,2,3\n0.01,") + bad + ",2,3,4\n", out, err) == 2);
    INFO(err);
    CHECK(err.find("efforts.csv:3: column 2 (swing)") != std::string::npos);
    CHECK(err.find("a finite number is required") != std::string::npos);
  }
  CHECK(replay("dig.yaml", "0,0,0.5,-0.2,1.5\n", out, err) == 2);
  INFO(err);
  CHECK(err.find("efforts.csv:2: column 5 (bucket) is 1.5") != std::string::npos);
  CHECK(err.find("allowed range [-1, 1]") != std::string::npos);
  // A value beyond the double range is infinite, and refused as such; a subnormal one is a number.
  CHECK(replay("paper_dig.yaml", "0,0,1e999,2,3\n", out, err) == 2);
  CHECK(err.find("efforts.csv:2: column 3 (boom) is inf: a finite number is required") != std::string::npos);
  CHECK(replay("paper_dig.yaml", "0,0,1e-320,2,3\n", out, err) == 0);
  // Column counts are counted whole: seven cells, and a trailing comma's empty sixth.
  CHECK(replay("paper_dig.yaml", "0,0,1,2,3,4,5\n", out, err) == 2);
  CHECK(err.find("efforts.csv:2: expected 5 columns t,swing,boom,arm,bucket, found 7") != std::string::npos);
  CHECK(replay("paper_dig.yaml", "0,0,1,2,3,\n", out, err) == 2);
  CHECK(err.find("efforts.csv:2: expected 5 columns t,swing,boom,arm,bucket, found 6") != std::string::npos);
  CHECK(replay("paper_dig.yaml", "0,0,1,2,3\n0.02,0,1,2,3\n0.01,0,1,2,3\n", out, err) == 2);
  CHECK(err.find("efforts.csv:4: column 1 (t) is 0.01: t must increase (the line before has 0.02)") !=
        std::string::npos);
  // Without a header the first line is data, also when its cells hold an exponent's letter: the
  // replay equals the one of the same rows under a header, byte for byte.
  auto text_of = [](const std::string& path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  CHECK(replay("paper_dig.yaml", "0,1e3,2,3,4\n0.02,0,2e3,3,4\n", out, err) == 0);
  const std::string with_header = text_of(out);
  CHECK(replay("paper_dig.yaml", "0,1e3,2,3,4\n0.02,0,2e3,3,4\n", out, err, "") == 0);
  CHECK(err.empty());
  CHECK(with_header.size() > 1000);
  CHECK(text_of(out) == with_header);
  // A first line whose first cell is a word is the header, whatever its other cells hold.
  CHECK(replay("paper_dig.yaml", "0,0,1,2,3\n", out, err, "time,tau\n") == 0);
  // A write that fails (a full disk: /dev/full) is an error naming the output, not a short file.
  REQUIRE(std::filesystem::exists("/dev/full"));
  CHECK(replay("paper_dig.yaml", "0,0,1,2,3\n", "/dev/full", err) == 2);
  CHECK(err.find("/dev/full: cannot write (No space left on device)") != std::string::npos);
  CHECK(replay("paper_dig.yaml", "0,0,1,2,3\n", "/no/such/dir/out.csv", err) == 2);
  CHECK(err.find("/no/such/dir/out.csv: cannot write (No such file or directory)") != std::string::npos);
}
#endif

namespace {

struct SpeedLimitRun {
  int limited_steps = 0;
  double worst_error = 0, work = 0, loss = 0;
};

// The arm pushed out at its full force for 1.5 s, against its speed limit from the first steps.
SpeedLimitRun arm_at_speed_limit(double step) {
  exc::plant::test::SceneText t;
  t.actuators = "fidelity: limited, lag: 0";
  t.q_a = "[0.0, 2.2, 2.3, 2.1]";
  t.step = step;
  Plant p(t.scene());
  const Machine& m = p.scene().machine;
  ActuatorCommand cmd;
  cmd.value = p.hold_effort();
  cmd.value[2] = m.arm.max_force;
  SpeedLimitRun r;
  int last_events = 0;
  for (int i = 0; i < 1500; ++i) {
    const PlantStatus st = p.step(cmd);
    INFO(std::string(st.text()));
    REQUIRE(st.ok());
    const PlantState& s = p.state();
    if (s.end_stop_events > last_events) ++r.limited_steps;
    last_events = s.end_stop_events;
    r.worst_error = std::max(r.worst_error, std::abs(s.energy_error));
    CHECK(std::abs(s.qd_a[2]) <= m.arm.max_speed + 1e-12);
  }
  r.work = std::abs(p.state().actuator_work);
  r.loss = p.state().end_stop_loss;
  return r;
}

}  // namespace

TEST_CASE("plant/limited actuators' speed limit takes energy and the balance closes to first order in the step") {
  // The flow limit is an impulse along M_a^-1 e_i that also takes back the displacement the excess
  // speed made, and books the valve's loss lambda v_limit (plant.cpp). Clamping the one coordinate
  // moved energy into the coupled joints instead (the fault campaign's case 267 was stopped by the
  // energy check for it). Independent evidence: the balance error is small against the work and
  // falls with the step as a first-order method's does (a bookkeeping bias would not).
  const SpeedLimitRun coarse = arm_at_speed_limit(1e-3), fine = arm_at_speed_limit(2.5e-4);
  MESSAGE("speed limit active in ", coarse.limited_steps, " of 1500 cycles; worst |energy error| ", coarse.worst_error,
          " J at 1 ms, ", fine.worst_error, " J at 0.25 ms, of ", coarse.work, " J of actuator work (", coarse.loss,
          " J taken by the limit)");
  CHECK(coarse.limited_steps > 1000);
  CHECK(coarse.loss > 0.5 * coarse.work);  // most of the arm's work goes into the valve at its limit
  CHECK(coarse.worst_error < 0.005 * coarse.work);
  CHECK(fine.worst_error < 0.4 * coarse.worst_error);
}
