// excavator-sim end to end: the main job's JSON summary, the robustness table and the errors a user
// sees, through the program itself (firmware and plant over the in-memory CAN bus).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include "exlcm/controller_state_t.hpp"
#include "exlcm/machine_state_t.hpp"
#include <array>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>
#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include "harness/lockstep_run.hpp"
#include "matplotlib_probe.hpp"
#include "run_report.hpp"
#include "log_channels.hpp"
#include "sim_runs.hpp"
#include "model/machine_reader.hpp"

namespace fs = std::filesystem;

extern char** environ;

using exc::test::kOtherChannels;
using exc::test::kPerCycleChannels;
using exc::test::LogChannel;
using exc::test::read_log_channels;
using exc::test::edited_dig;
using exc::test::edited_scene;
using exc::test::kDig;
using exc::test::kPaperDig;
using exc::test::read_text_file;
using exc::test::Run;
using exc::test::run_sim;

namespace {

const char* const kJoints[4] = {"swing", "boom", "arm", "bucket"};

// A shipped sweep spec with fewer cases, the shipped scenes by absolute path and `extra` lines
// appended to the sweep's mapping, written to `to`.
void write_sweep_spec(const std::string& shipped, int cases, const std::string& extra, const fs::path& to) {
  std::string spec = read_text_file(std::string(EXC_SOURCE_DIR) + "/sweeps/" + shipped);
  const auto count = spec.find("cases: ");
  REQUIRE(count != std::string::npos);
  spec.replace(count, spec.find('\n', count) - count, "cases: " + std::to_string(cases));
  const std::string scenes = "../scenes/", absolute = std::string(EXC_SOURCE_DIR) + "/scenes/";
  REQUIRE(spec.find(scenes) != std::string::npos);
  for (auto at = spec.find(scenes); at != std::string::npos; at = spec.find(scenes, at + absolute.size()))
    spec.replace(at, scenes.size(), absolute);
  std::ofstream(to) << spec << extra;
}


// A log of `controllers` each run for `cycles` cycles of 1 ms: on every per-cycle channel of every
// controller, one message per cycle, counted by the channel's own sequence numbers (0 .. cycles-1,
// no gap) and stamped with consecutive cycles (utime 1000, 2000, ... us, each cycle's end: no
// repeat, no gap);
// and no channel the list above does not know (a new per-cycle channel must be added there).
// `allowed_missing` > 0 only for a receiver known to drop (lcm-logger over udpm): up to that many
// messages of a channel may be absent, and what was recorded must still be in order, each message
// stamped with its own cycle.
void check_every_cycle_logged(const std::map<std::string, LogChannel>& log, const std::vector<std::string>& controllers,
                              std::int64_t cycles, std::int64_t allowed_missing = 0) {
  for (const auto& [name, channel] : log) {
    const std::string base = name.substr(0, name.find('/'));
    const std::string suffix = name.find('/') == std::string::npos ? "" : name.substr(name.find('/') + 1);
    INFO("channel " << name << " (" << channel.count << " messages)");
    bool known = false;
    for (const char* c : kPerCycleChannels) known = known || base == c;
    for (const char* c : kOtherChannels) known = known || base == c;
    CHECK(known);
    CHECK(std::find(controllers.begin(), controllers.end(), suffix) != controllers.end());
  }
  for (const std::string& c : controllers) {
    for (const char* base : kPerCycleChannels) {
      const std::string name = std::string(base) + "/" + c;
      INFO(name);
      REQUIRE(log.count(name) == 1);
      const LogChannel& l = log.at(name);
      CHECK(l.out_of_order == 0);
      CHECK(l.stamp_mismatches == 0);
      if (allowed_missing > 0) {
        // Sequence numbers 0 .. cycles-1 in order, some absent: what is absent was lost at the receiver.
        const std::int64_t missing = cycles - l.count;
        MESSAGE(name << ": " << missing << " of " << cycles << " messages not recorded by the receiver");
        CHECK(missing >= 0);
        CHECK(missing <= allowed_missing);
        CHECK(l.seq_gaps <= missing);
        CHECK(l.last_seq <= cycles - 1);
        continue;
      }
      CHECK(l.count == cycles);
      CHECK(l.first_seq == 0);
      CHECK(l.seq_gaps == 0);
      CHECK(l.last_seq == cycles - 1);
      CHECK(l.first_utime == 1000);
      CHECK(l.last_utime == cycles * 1000);
      std::string steps;
      for (const auto& [step, n] : l.utime_steps) steps += " " + std::to_string(n) + " x " + std::to_string(step) + " us;";
      INFO("utime steps:" << steps);
      CHECK(l.utime_steps.size() == 1);
      CHECK(l.utime_steps.count(1000) == 1);
    }
  }
}

}  // namespace

TEST_CASE("tools/excavator-sim run on the paper's force-actuated dig writes the issue's JSON summary: adaptive beats PID 5x on arm and bucket, no heap in the loop") {
  const Run r = run_sim("run " + kPaperDig + " --no-report --quiet --json summary.json --out out");
  INFO(r.err);
  REQUIRE(r.status == 0);
  const nlohmann::json j = nlohmann::json::parse(read_text_file(r.dir / "summary.json"));
  for (const char* c : {"pid", "adaptive"}) {
    REQUIRE(j.contains(c));
    for (const char* joint : kJoints) {
      const double rms = j[c]["rms_error"][joint].get<double>();
      const double max = j[c]["max_error"][joint].get<double>();
      CHECK(std::isfinite(rms));
      CHECK(std::isfinite(max));
      CHECK(rms <= max + 1e-15);  // a root mean square never exceeds the largest sample
    }
  }
  for (const char* joint : {"arm", "bucket"}) {
    const double pid = j["pid"]["rms_error"][joint].get<double>();
    const double adaptive = j["adaptive"]["rms_error"][joint].get<double>();
    INFO(joint << ": PID " << pid << " m, adaptive " << adaptive << " m");
    CHECK(pid >= 5 * adaptive);
  }
  // The summary says what ran: the scene's actuators and the firmware's compensation of their lag.
  CHECK(j["setup"].get<std::string>().find(
            "actuators limited (effort lag 20 ms), firmware commands efforts, lag compensation 20 ms -> 5 ms") == 0);
  CHECK(r.out.find("scene paper_dig: actuators limited") != std::string::npos);
  CHECK(j["heap_allocations_in_loop"].get<long long>() == 0);
  CHECK(j["simulated_seconds"].get<double>() == doctest::Approx(10.1).epsilon(1e-3));
  CHECK(j["control_step_us"]["median"].get<double>() > 0);

  // The log holds every message of every cycle: 10.1 s at 1 kHz = 10,100 per controller on each
  // per-cycle channel, counted by its sequence numbers 0 .. 10,099 and stamped 1 ms apart (counted,
  // not weighed).
  const std::map<std::string, LogChannel> log = read_log_channels(r.dir / "out" / "run.lcm");
  check_every_cycle_logged(log, {"pid", "adaptive"}, 10100);
  for (const char* c : {"pid", "adaptive"}) {
    // The report's CSVs (excavator-log export, as the report writes them) have one row per cycle.
    {
      const fs::path csv = r.dir / ("csv_" + std::string(c));
      const std::string cmd = std::string(EXC_LOG_TOOL) + " export '" + (r.dir / "out" / "run.lcm").string() +
                              "' --csv '" + csv.string() + "' > /dev/null 2>&1";
      REQUIRE(std::system(cmd.c_str()) == 0);
      for (const char* base : {"EXC_STATE", "EXC_COMMAND", "EXC_CONTROLLER"}) {
        INFO(base);
        CHECK(exc::test::csv_data_rows(csv / (std::string(base) + "__" + c + ".csv")) == 10100);
      }
    }
    // The telemetry path's own counters: nothing dropped (blocking publisher), every message published.
    INFO(c);
    CHECK(j[c]["telemetry"]["dropped"].get<long long>() == 0);
    CHECK(j[c]["telemetry"]["overflow_policy"].get<std::string>() == "block");
    CHECK(j[c]["telemetry"]["published"].get<long long>() == j[c]["telemetry"]["enqueued"].get<long long>());
  }
}

TEST_CASE("tools/excavator-sim robustness: adaptive completes every variant and stays at least 2x better than PID on arm and bucket wherever PID completes, and PID stops only by the tracking-error fault") {
  REQUIRE_MESSAGE(exc::test::matplotlib_available(), exc::test::kMatplotlibMissing);
  const Run r = run_sim("robustness " + kDig + " --quiet --json robust.json --out rob");
  INFO(r.err);
  REQUIRE(r.status == 0);
  const nlohmann::json j = nlohmann::json::parse(read_text_file(r.dir / "robust.json"));
  const nlohmann::json& rows = j["robustness"];
  REQUIRE(rows.size() == 7);
  CHECK(rows[0]["variant"] == "nominal");
  for (const nlohmann::json& row : rows) {
    const std::string name = row["variant"].get<std::string>();
    INFO("variant " << name);
    // The adaptive law completes every variant. PID either completes or is stopped by the firmware's
    // tracking-error fault (it drifts 0.2 m on the bucket in 3x stiffer soil), and the row says so.
    CHECK(row["adaptive"]["ok"].get<bool>());
    const bool pid_completed = row["pid"]["ok"].get<bool>();
    if (!pid_completed) {
      CHECK(row["pid"]["failure"].get<std::string>().find("tracking error: bucket") != std::string::npos);
      CHECK_FALSE(row["ok"].get<bool>());
      continue;
    }
    CHECK(row["ok"].get<bool>());
    for (const char* joint : {"arm", "bucket"}) {
      const double pid = row["pid"]["rms_error"][joint].get<double>();
      const double adaptive = row["adaptive"]["rms_error"][joint].get<double>();
      INFO(joint << ": PID " << pid << " m, adaptive " << adaptive << " m");
      CHECK(std::isfinite(adaptive));
      CHECK(pid >= 2 * adaptive);
      CHECK(row["pid_over_adaptive_rms"][joint].get<double>() == doctest::Approx(pid / adaptive));
    }
  }
  // Each variant changes something: none may reproduce the nominal figures exactly.
  const double nominal_bucket = rows[0]["adaptive"]["rms_error"]["bucket"].get<double>();
  for (std::size_t i = 1; i < rows.size(); ++i) CHECK(rows[i]["adaptive"]["rms_error"]["bucket"].get<double>() != nominal_bucket);
  CHECK(r.out.find("PID/adapt.") != std::string::npos);
  // The same table next to its chart (1200 x 700 PNG).
  CHECK(read_text_file(r.dir / "rob" / "robustness.json") == read_text_file(r.dir / "robust.json"));
  CHECK(fs::file_size(r.dir / "rob" / "robustness.png") > 20000);
}

TEST_CASE("tools/excavator-sim: on the paper dig's lagging force actuators the firmware's lag compensation keeps the adaptive law's lead") {
  // The shipped scene with the compensation switched off: same plant, same laws.
  REQUIRE(read_text_file(kPaperDig).find("fidelity: limited") != std::string::npos);
  const fs::path scene = edited_scene(kPaperDig, {{"actuator_lag: 0.02", "actuator_lag: 0"}}, "dig_no_compensation");
  const Run with = run_sim("run " + kPaperDig + " --no-report --quiet --json s.json --out out");
  const Run without = run_sim("run " + scene.string() + " --no-report --quiet --json s.json --out out");
  REQUIRE(with.status == 0);
  REQUIRE(without.status == 0);
  const nlohmann::json a = nlohmann::json::parse(read_text_file(with.dir / "s.json"));
  const nlohmann::json b = nlohmann::json::parse(read_text_file(without.dir / "s.json"));
  for (const char* joint : {"arm", "bucket"}) {
    const double on = a["adaptive"]["rms_error"][joint].get<double>();
    const double uncompensated = b["adaptive"]["rms_error"][joint].get<double>();
    INFO(joint << ": adaptive RMS " << on << " m compensated, " << uncompensated << " m without");
    // Measured: arm 3.7x, bucket 1.6x better with the compensation.
    CHECK(uncompensated >= 1.3 * on);
  }
  CHECK(a["heap_allocations_in_loop"].get<long long>() == 0);
  fs::remove(scene);
}

TEST_CASE("tools/excavator-sim names the file and field of a bad scene and exits 2") {
  const fs::path bad = edited_dig("duration: 10.1", "duration: -3", "bad_scene");
  for (const char* sub : {"run", "robustness"}) {
    const Run r = run_sim(std::string(sub) + " " + bad.string() + " --quiet");
    INFO(sub << ": " << r.err);
    CHECK(r.status == 2);
    CHECK(r.err.find(bad.string()) != std::string::npos);
    CHECK(r.err.find("duration") != std::string::npos);
    CHECK(r.err.find("nan") == std::string::npos);
  }
  fs::remove(bad);
  const Run unknown = run_sim("run " + kDig + " --controller lqr --quiet --no-report");
  CHECK(unknown.status == 2);
  CHECK(unknown.err.find("pid, adaptive, slotine_li, flow") != std::string::npos);
  const Run help = run_sim("robustness --help");
  CHECK(help.status == 0);
  CHECK(help.out.find("--json") != std::string::npos);
}

TEST_CASE("tools/excavator-sim refuses a too-fast swing before the run, and forced, stops it safely with the reason and exit 1") {
  const std::string free_motion = std::string(EXC_SOURCE_DIR) + "/scenes/free_motion.yaml";
  std::string text = read_text_file(free_motion);
  const std::string from = "    - {t: 2.0, q: [0.4, 2.70, 2.60, 1.90]}";
  const auto pos = text.find(from);
  REQUIRE(pos != std::string::npos);
  text.replace(pos, from.size(), "    - {t: 2.5, q: [2.0, 2.70, 2.60, 1.90]}");
  const fs::path dir = fs::path(EXC_BINARY_DIR) / "tests" / "sim";
  const fs::path refused = exc::test::scratch_file(dir / ("fast_swing_" + std::to_string(getpid()) + ".yaml"));
  std::ofstream(refused) << text;
  const Run r = run_sim("run " + refused.string() + " --quiet --no-report");
  INFO(r.err);
  CHECK(r.status == 2);
  CHECK(r.err.find("the swing needs") != std::string::npos);
  CHECK(r.err.find("kN m") != std::string::npos);

  std::string forced_text = text;
  const std::string type = "  type: joint_waypoints";
  const auto at = forced_text.find(type);
  REQUIRE(at != std::string::npos);
  forced_text.insert(at + type.size(), "\n  efforts: {check: false}");
  const fs::path forced = exc::test::scratch_file(dir / ("fast_swing_forced_" + std::to_string(getpid()) + ".yaml"));
  std::ofstream(forced) << forced_text;
  const Run f = run_sim("run " + forced.string() + " --quiet --no-report --json summary.json");
  INFO(f.err);
  CHECK(f.status == 1);
  const nlohmann::json j = nlohmann::json::parse(read_text_file(f.dir / "summary.json"));
  CHECK_FALSE(j["ok"].get<bool>());
  for (const char* c : {"pid", "adaptive"}) {
    INFO(c);
    CHECK_FALSE(j[c]["ok"].get<bool>());
    CHECK(j[c]["failure"].get<std::string>().find("tracking error: swing") != std::string::npos);
    // The printed summary carries the whole reason (it was cut at 256 characters of the run's line).
    CHECK(f.out.find("  FAILED: " + j[c]["failure"].get<std::string>() + "\n") != std::string::npos);
  }
  fs::remove(refused);
  fs::remove(forced);
}

TEST_CASE("tools/excavator-sim refuses a scene whose firmware commands what its machine does not take, naming the file, the line and both fields (exit 2)") {
  // The paper dig's force-actuated plant takes efforts; valve commands to it could only fail at the
  // first one. Given in the file: refused at its line.
  const fs::path valves = edited_scene(
      kPaperDig, {{"  actuator_lag: 0.02           # s: the firmware compensates the actuators' lag (target 5 ms)",
                   "  command_interface: valve"}},
      "paper_dig_valves");
  const Run r = run_sim("run " + valves.string() + " --controller pid --duration 1 --no-report --quiet --out out");
  INFO(r.out << r.err);
  CHECK(r.status == 2);
  CHECK(r.err.find(valves.string() + ":25:") != std::string::npos);
  CHECK(r.err.find("controller.command_interface: is valve but actuators.fidelity is limited") != std::string::npos);
  CHECK(r.err.find("set command_interface: effort") != std::string::npos);
  CHECK_FALSE(fs::exists(r.dir / "out" / "summary.json"));
  // The hydraulic dig without its command_interface line: the default (effort) does not fit, and the
  // message says it was the default, placed as the settings reader places a missing key: at its
  // section (the section's first key).
  const fs::path efforts = edited_scene(
      kDig, {{"  command_interface: valve     # pilot pressures through the valve stage; every law on its defaults\n",
              "  blend_time: 0.2\n"}},
      "dig_efforts");
  const Run e = run_sim("run " + efforts.string() + " --controller pid --duration 1 --no-report --quiet --out out");
  INFO(e.out << e.err);
  CHECK(e.status == 2);
  int section_line = 0, line_number = 0;
  bool in_controller = false;
  std::istringstream edited(read_text_file(efforts));
  for (std::string line; section_line == 0 && std::getline(edited, line);) {
    ++line_number;
    if (line == "controller:") in_controller = true;
    else if (in_controller && line.size() > 2 && line.compare(0, 2, "  ") == 0 && line[2] != ' ' && line[2] != '#')
      section_line = line_number;
  }
  REQUIRE(section_line > 0);
  CHECK(e.err.find(efforts.string() + ":" + std::to_string(section_line) +
                   ":3: controller.command_interface: is effort (not given: the default) but "
                   "actuators.fidelity is hydraulic, which takes valve (pilot pressure) commands; set command_interface: valve") !=
        std::string::npos);
  fs::remove(valves);
  fs::remove(efforts);
}

TEST_CASE("tools/excavator-sim: a run that never tracked (it ends before the task starts) says so: ok false, the reason, null tracking figures, exit 1") {
  // The firmware holds the machine for its first 50 ms and tracks after: a 20 ms run never tracks.
  const Run r = run_sim("run " + kPaperDig + " --controller pid,adaptive --duration 0.02 --no-report --quiet --json summary.json --out out");
  INFO(r.out << r.err);
  CHECK(r.status == 1);
  const nlohmann::json j = nlohmann::json::parse(read_text_file(r.dir / "summary.json"));
  CHECK_FALSE(j["ok"].get<bool>());
  for (const char* c : {"pid", "adaptive"}) {
    INFO("controller " << c);
    CHECK_FALSE(j[c]["ok"].get<bool>());
    const std::string failure = j[c]["failure"].get<std::string>();
    CHECK(failure == "the firmware never tracked (mode hold)");
    CHECK(j[c]["tracking_samples"].get<long long>() == 0);
    // A metric of no samples is absent, not 0.
    CHECK(j[c]["rms_error"].is_null());
    CHECK(j[c]["max_error"].is_null());
    CHECK(j[c]["tracking"]["rms_error"].is_null());
    CHECK(j[c]["tracking"]["max_error"].is_null());
    CHECK(r.out.find("  FAILED: " + failure + "\n") != std::string::npos);
  }
  CHECK(r.out.find("n/a") != std::string::npos);
  CHECK(r.out.find("0.000e+00") == std::string::npos);
}

TEST_CASE("tools/excavator-sim: the report reads the log --lcm named, and without a log file says why there is no report") {
  // The log goes outside the output directory; the report must come from it, not from <out>/run.lcm.
  const fs::path logs = exc::test::scratch_dir(fs::path(EXC_BINARY_DIR) / "tests" / "sim" /
                                               ("lcm_elsewhere_" + std::to_string(getpid())));
  const fs::path log = logs / "elsewhere.lcm";
  const Run r = run_sim("run " + kDig + " --controller adaptive --duration 0.3 --quiet --out out --lcm 'file://" +
                        log.string() + "?mode=w'");
  INFO(r.err);
  REQUIRE(r.status == 0);
  CHECK(fs::exists(log));
  CHECK(!fs::exists(r.dir / "out" / "run.lcm"));
  const std::string report = read_text_file(r.dir / "out" / "report" / "report.md");
  CHECK(report.find("| tracking: RMS error arm (mm) |") != std::string::npos);  // the summary table's row
  CHECK(r.out.find("report: out/report/report.md") != std::string::npos);
  // A provider that writes no file (here LCM's in-process queue, as udpm:// would be) leaves nothing
  // to report from: said on stderr, and the run is still a success.
  const Run live = run_sim("run " + kDig + " --controller adaptive --duration 0.05 --quiet --out out --lcm memq://");
  INFO(live.err);
  CHECK(live.status == 0);
  CHECK(live.err.find("no report: the telemetry went to memq://, not to a log file") != std::string::npos);
  CHECK(!fs::exists(live.dir / "out" / "report"));
  fs::remove_all(logs);
}

TEST_CASE("tools/excavator-sim over udpm: a real lcm-logger on the loopback records the 10 s dig of every controller the scene runs, in order, losing at most 1 % at the logger") {
  // Multicast on the loopback must work: a machine without it fails here with what to run.
  const int port = 17700 + static_cast<int>(getpid() % 200);
  const std::string url = "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0";
  const bool lo_multicast = std::system("ip link show lo 2>/dev/null | grep -q MULTICAST") == 0;
  const bool routed = std::system("ip route get 239.255.76.67 2>/dev/null | grep -q ' dev lo '") == 0;
  REQUIRE_MESSAGE((lo_multicast && routed),
                  "LCM's multicast does not reach the loopback (lo " << std::string(lo_multicast ? "has" : "lacks")
                  << " MULTICAST, 239.255.0.0/16 " << std::string(routed ? "is" : "is not") << " routed to lo); as root run: "
                  "ip link set lo multicast on; ip route add 239.255.0.0/16 dev lo (tools/install-deps test does)");
  const fs::path dir = fs::path(EXC_BINARY_DIR) / "tests" / "sim";
  fs::create_directories(dir);
  const fs::path log_path = exc::test::scratch_file((fs::is_directory("/dev/shm") ? fs::path("/dev/shm") : dir) /
                                         ("exc-main-job-" + std::to_string(getpid()) + ".lcm"));
  fs::remove(log_path);
  const std::string log_arg = log_path.string(), url_arg = "--lcm-url=" + url;
  const char* argv[] = {"lcm-logger", "-f", "-q", url_arg.c_str(), log_arg.c_str(), nullptr};
  pid_t logger = 0;
  REQUIRE_MESSAGE(posix_spawnp(&logger, "lcm-logger", nullptr, nullptr, const_cast<char* const*>(argv), environ) == 0,
                  "cannot start lcm-logger (Debian package liblcm-bin)");
  // The logger's main thread must not fall behind LCM's 30-message subscription queue: real-time
  // priority where permitted (root in CI), and the publisher paces udpm to 4 messages per ms.
  sched_param priority{};
  priority.sched_priority = 10;
  sched_setscheduler(logger, SCHED_FIFO, &priority);
  // Ready once its file exists (lcm-logger creates it when it starts listening).
  for (int i = 0; i < 250 && !fs::exists(log_path); ++i) usleep(20000);
  usleep(200000);
  // The main job's shipped dig, 10 s, with the controllers the scene runs by default.
  const Run r = run_sim("run " + kDig + " --quiet --no-report --json summary.json --lcm '" + url + "' --out out");
  usleep(500000);  // the tail reaches the logger
  kill(logger, SIGINT);
  int status = 0;
  waitpid(logger, &status, 0);
  INFO(r.err);
  REQUIRE(r.status == 0);
  REQUIRE(fs::exists(log_path));
  const nlohmann::json j = nlohmann::json::parse(read_text_file(r.dir / "summary.json"));
  CHECK(j["simulated_seconds"].get<double>() == doctest::Approx(10.1).epsilon(1e-3));
  std::vector<std::string> controllers;
  for (const auto& [key, value] : j.items())
    if (value.is_object() && value.contains("telemetry")) controllers.push_back(key);
  CHECK(controllers == std::vector<std::string>{"adaptive", "flow", "pid"});  // the JSON's keys, sorted
  // lcm-logger (Debian's LCM 1.3.1) keeps LCM's 30-message subscription queue and drops beyond it
  // when its thread falls behind: a freshly installed CI machine under ctest -j2 lost one message of
  // each per-cycle channel with the logger at real-time priority, and the kernel's UDP counters no
  // drop. So up to 1 % may be absent here, as in the telemetry path's own udpm test; the sender's
  // side must lose nothing (below), and the file:// log of the main job (the paper dig test) must
  // hold every message.
  check_every_cycle_logged(read_log_channels(log_path), controllers, 10100, 10100 / 100);
  for (const std::string& c : controllers) {
    INFO(c);
    CHECK(j[c]["telemetry"]["dropped"].get<long long>() == 0);
    CHECK(j[c]["telemetry"]["published"].get<long long>() == j[c]["telemetry"]["enqueued"].get<long long>());
  }
  fs::remove(log_path);
}

TEST_CASE("tools/excavator-sim paper writes the paper's Figs. 4-12 from its force-actuated scenes, then the dig through the valves, each figure on file and its numbers the scenes' own") {
  const std::string scenes = std::string(EXC_SOURCE_DIR) + "/scenes/";
  const Run r = run_sim("paper --free-motion " + scenes + "paper_free_motion.yaml --dig " + kPaperDig + " --hydraulic-dig " +
                        kDig + " --duration 3 --quiet --out paper");
  INFO(r.err);
  REQUIRE(r.status == 0);
  const fs::path out = r.dir / "paper";
  const std::string page = read_text_file(out / "report.md");
  for (int fig = 4; fig <= 12; ++fig) {
    const std::string tag = "![Fig. " + std::to_string(fig) + "](";
    const auto at = page.find(tag);
    INFO("Fig. " << fig);
    REQUIRE(at != std::string::npos);
    const auto end = page.find(')', at + tag.size());
    const fs::path png = out / page.substr(at + tag.size(), end - at - tag.size());
    CHECK(fs::exists(png));
    CHECK(fs::file_size(png) > 10000);
  }
  // The page's numbers are the scenes' own: Fig. 11's arm RMS figures, formatted from summary.json.
  const nlohmann::json dig = nlohmann::json::parse(read_text_file(out / "dig" / "summary.json"));
  CHECK(dig["scene"] == "paper_dig");
  char expected[96];
  std::snprintf(expected, sizeof expected, "RMS error PID %.3g mm, adaptive %.3g mm",
                dig["pid"]["rms_error"]["arm"].get<double>() * 1e3, dig["adaptive"]["rms_error"]["arm"].get<double>() * 1e3);
  const auto fig11 = page.find("### Fig. 11");
  REQUIRE(fig11 != std::string::npos);
  CHECK(page.find(expected, fig11) < page.find("### Fig. 12"));
  CHECK(fs::exists(out / "free_motion" / "run.lcm"));
  CHECK(fs::exists(out / "dig" / "report" / "report.md"));
  // Then the same dig through the valves: three controllers, their row of figures from its summary.
  const nlohmann::json h = nlohmann::json::parse(read_text_file(out / "hydraulic_dig" / "summary.json"));
  CHECK(h["scene"] == "dig");
  const auto section = page.find("## Beyond the paper: the same dig through a hydraulic machine's valves");
  REQUIRE(section != std::string::npos);
  for (const char* c : {"pid", "adaptive", "flow"}) {
    INFO(c);
    REQUIRE(h.contains(c));
    char row[96];
    std::snprintf(row, sizeof row, "| %s | %.3g mrad / %.3g / %.3g / %.3g mm |", c, h[c]["rms_error"]["swing"].get<double>() * 1e3,
                  h[c]["rms_error"]["boom"].get<double>() * 1e3, h[c]["rms_error"]["arm"].get<double>() * 1e3,
                  h[c]["rms_error"]["bucket"].get<double>() * 1e3);
    CHECK(page.find(row, section) != std::string::npos);
  }
  CHECK(fs::exists(out / "hydraulic_dig" / "report" / "tracking_bucket.png"));
}

TEST_CASE("tools/excavator-sim: a scene's controller.type chooses the controller, --controller in conflict with it is an error") {
  const fs::path scene = edited_dig("controller:\n", "controller:\n  type: pid\n", "typed_scene");
  const Run r = run_sim("run " + scene.string() + " --duration 0.5 --quiet --no-report --json s.json");
  INFO(r.err);
  REQUIRE(r.status == 0);
  const nlohmann::json j = nlohmann::json::parse(read_text_file(r.dir / "s.json"));
  CHECK(j.contains("pid"));
  CHECK_FALSE(j.contains("adaptive"));
  const Run same = run_sim("run " + scene.string() + " --controller pid --duration 0.5 --quiet --no-report");
  CHECK(same.status == 0);
  const Run conflict = run_sim("run " + scene.string() + " --controller adaptive --duration 0.5 --quiet --no-report");
  CHECK(conflict.status == 2);
  CHECK(conflict.err.find("controller.type: pid") != std::string::npos);
  fs::remove(scene);
  // A name the controller table does not hold is refused by the scene parser as by the command line.
  const fs::path unknown = edited_dig("controller:\n", "controller:\n  type: lqr\n", "unknown_type");
  const Run bad = run_sim("run " + unknown.string() + " --quiet --no-report");
  CHECK(bad.status == 2);
  CHECK(bad.err.find("controller.type: is 'lqr'; allowed values: pid, adaptive, slotine_li, flow") != std::string::npos);
  fs::remove(unknown);
}

TEST_CASE("tools/excavator-sim truck loading: five cycles of all four actuators, a per-cycle record for each controller, PID the same every pass and the adaptive law, which learns the soil from the measured force within its first dig, as good from its first pass and at least 2x better than PID on arm and bucket") {
  const Run r = run_sim("run " + std::string(EXC_SOURCE_DIR) +
                        "/scenes/truck_loading.yaml --controller pid,adaptive --quiet --no-report --json s.json");
  INFO(r.err);
  REQUIRE(r.status == 0);
  const nlohmann::json j = nlohmann::json::parse(read_text_file(r.dir / "s.json"));
  for (const char* c : {"pid", "adaptive"}) {
    INFO(c);
    REQUIRE(j[c]["cycles"].size() == 5);
    CHECK(j[c]["task_finished"].get<bool>());
    // Every cycle swings and digs: the swing error is measured on a moving joint, the soil pushes back.
    for (const auto& k : j[c]["cycles"]) {
      CHECK(k["peak_soil_force"].get<double>() > 5e3);
      CHECK(k["end"].get<double>() - k["start"].get<double>() == doctest::Approx(22.0).epsilon(0.01));
    }
  }
  // PID has no memory: the same ground gives the same error every pass (within 2 %).
  const auto& pid = j["pid"]["cycles"];
  for (std::size_t k = 1; k < 5; ++k)
    CHECK(pid[k]["rms_error"]["bucket"].get<double>() ==
          doctest::Approx(pid[0]["rms_error"]["bucket"].get<double>()).epsilon(0.02));
  // The adaptive law's composite update identifies the soil from the measured cylinder forces during
  // the first dig, so its first pass is as good as the later ones (no pass worse than the first by
  // more than 2 %: nothing drifts), and every pass at least 2x better than PID's on arm and bucket.
  // (Before the valve stage metered the chambers' pressurising, the first pass carried a start-up
  // error the later passes did not; the 50-pass test below holds the estimates themselves.)
  const auto& ad = j["adaptive"]["cycles"];
  for (std::size_t k = 0; k < 5; ++k) {
    CAPTURE(k);
    for (const char* a : {"arm", "bucket"}) {
      CAPTURE(a);
      CHECK(ad[k]["rms_error"][a].get<double>() <= 1.02 * ad[0]["rms_error"][a].get<double>());
      CHECK(2 * ad[k]["rms_error"][a].get<double>() <= pid[k]["rms_error"][a].get<double>());
    }
  }
  CHECK(r.out.find("per work cycle") != std::string::npos);
}

TEST_CASE("tools/excavator-sim truck loading over fifty passes: on its defaults the adaptive law's errors stay flat and the soil's spring and damper estimates within 20 % of the truth, and the paper's update alone runs them to their bounds") {
  // The shipped scene's passes, its telemetry to /dev/null (a million messages a run).
  const auto passes = [](int n, const std::string& controller_edit, const std::string& stem) {
    std::vector<std::pair<std::string, std::string>> edits = {
        {"repeat: 5", "repeat: " + std::to_string(n)},
        {"duration: 112.0", "duration: " + std::to_string(22 * n + 2) + ".0"}};
    if (!controller_edit.empty()) edits.push_back({"\ncontroller:\n", "\ncontroller:\n" + controller_edit});
    const fs::path scene = edited_scene(std::string(EXC_SOURCE_DIR) + "/scenes/truck_loading.yaml", edits, stem);
    const Run r = run_sim("run " + scene.string() +
                          " --controller adaptive --quiet --no-report --json s.json --lcm 'file:///dev/null?mode=w'");
    fs::remove(scene);
    INFO(r.err);
    REQUIRE(r.status == 0);
    const nlohmann::json j = nlohmann::json::parse(read_text_file(r.dir / "s.json"));
    REQUIRE(j["adaptive"]["cycles"].size() == static_cast<std::size_t>(n));
    CHECK(j["adaptive"]["heap_allocations_in_loop"].get<std::uint64_t>() == 0);
    return j["adaptive"]["cycles"];
  };
  const auto rms = [](const nlohmann::json& c, int k, const char* joint) { return c[k]["rms_error"][joint].get<double>(); };
  const auto theta = [](const nlohmann::json& c, int k, const char* p) { return c[k]["theta_hat"][p].get<double>(); };

  const nlohmann::json composite = passes(50, "", "truck50");
  for (int k = 2; k < 50; ++k) {
    CAPTURE(k);
    for (const char* joint : {"arm", "bucket"}) CHECK(rms(composite, k, joint) < 1.1 * rms(composite, 1, joint));
  }
  // Loam (machine.md): K 70 kN/m, B 5 kN s/m on both axes; excited by every pass, identified in the
  // first and held there (the soil's added mass is not excited: not checked).
  for (int k : {0, 9, 49}) {
    CAPTURE(k);
    for (const char* p : {"K_x", "K_z"}) CHECK(theta(composite, k, p) == doctest::Approx(7e4).epsilon(0.2));
    for (const char* p : {"B_x", "B_z"}) CHECK(theta(composite, k, p) == doctest::Approx(5e3).epsilon(0.2));
  }
  MESSAGE("pass 50: bucket RMS " << rms(composite, 49, "bucket") * 1e3 << " mm, K_x " << theta(composite, 49, "K_x")
                                 << ", K_z " << theta(composite, 49, "K_z") << ", B_x " << theta(composite, 49, "B_x")
                                 << ", B_z " << theta(composite, 49, "B_z"));

  // The negative control: the paper's update alone (eq. 27 at a tenth of the force-commanded rate, no
  // observer, no composite term, no dead zone) on fifteen of the same passes reads the valves' lag as
  // soil and runs the vertical estimates to their lower bounds (theta_min: 1e4 N/m, 1e3 N s/m).
  const nlohmann::json paper = passes(
      15, "  external_force: {observer: false, identification_memory: 0}\n  tracking_dead_zone: [0, 0, 0, 0]\n"
          "  adaptation_rate: [6e6, 6e9, 3e11, 6e6, 6e9, 3e11]\n", "truck15_paper");
  CHECK(theta(paper, 14, "K_z") == doctest::Approx(1e4));
  CHECK(theta(paper, 14, "B_z") == doctest::Approx(1e3));
  CHECK(theta(paper, 14, "B_x") < 5e3 / 3);
}

TEST_CASE("tools/excavator-sim sweeps record a never-tracked run's errors as null, and the merged table leaves their cells empty, not 0") {
  // The record: a run with no tracking samples has no error figure; one with samples has all four.
  exc::sim::RunRecord never;
  never.tracking_samples = 0;
  CHECK(exc::sim::tracked_per_joint(never, never.rms_error).is_null());
  exc::sim::RunRecord tracked;
  tracked.tracking_samples = 10;
  tracked.rms_error[3] = 2e-3;
  const nlohmann::json figure = exc::sim::tracked_per_joint(tracked, tracked.rms_error);
  CHECK(figure["bucket"].get<double>() == 2e-3);
  CHECK(figure.size() == 4);

  // The merge: case 1's PID run as a never-tracked run records it.
  const Run setup = run_sim("--help");
  const fs::path dir = setup.dir;
  write_sweep_spec("dig_monte_carlo.yaml", 2, "  duration: 0.3\n", dir / "spec.yaml");
  const std::string in_dir = "cd '" + dir.string() + "' && " + EXC_SIM_TOOL;
  REQUIRE(std::system((in_dir + " sweep spec.yaml --quiet --out one.jsonl > /dev/null 2>&1").c_str()) == 0);
  std::ifstream in(dir / "one.jsonl");
  std::ofstream edited(dir / "edited.jsonl");
  std::string line;
  while (std::getline(in, line)) {
    nlohmann::json j = nlohmann::json::parse(line);
    if (j["case"] == 1) {
      j["pid"]["ok"] = false;
      j["pid"]["rms_error"] = j["pid"]["max_error"] = nullptr;
      j["pid"]["failure"] = "never tracked";
    }
    edited << j.dump() << "\n";
  }
  edited.close();
  REQUIRE(std::system((in_dir + " sweep-merge spec.yaml edited.jsonl --out merged --no-charts > /dev/null 2>&1").c_str()) == 0);
  std::ifstream csv(dir / "merged" / "sweep.csv");
  std::vector<std::vector<std::string>> rows;
  while (std::getline(csv, line)) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    rows.push_back(cells);
  }
  REQUIRE(rows.size() == 3);
  const auto column = [&](const std::string& name) {
    const auto at = std::find(rows[0].begin(), rows[0].end(), name);
    REQUIRE(at != rows[0].end());
    return static_cast<std::size_t>(at - rows[0].begin());
  };
  for (const char* joint : {"swing", "boom", "arm", "bucket"}) {
    CAPTURE(joint);
    CHECK(rows[2][column(std::string("pid_rms_") + joint)].empty());       // never tracked: no figure
    CHECK_FALSE(rows[1][column(std::string("pid_rms_") + joint)].empty()); // tracked: its figure
  }
  CHECK(rows[2][column("pid_ok")] == "0");
}

TEST_CASE("tools/excavator-sim opens a scene file once per run, counted by strace") {
  // Both sides (plant and firmware) read their sections from one reading of the file.
  const Run r = run_sim("run " + kDig + " --duration 0.05 --quiet --no-report");
  REQUIRE(r.status == 0);
  const fs::path trace = r.dir / "opens.txt";
  const std::string cmd = "strace -f -qq -e trace=open,openat -o '" + trace.string() + "' " + EXC_SIM_TOOL + " run " +
                          kDig + " --duration 0.05 --quiet --no-report --out '" + (r.dir / "traced").string() + "' > /dev/null 2>&1";
  REQUIRE_MESSAGE(std::system(cmd.c_str()) == 0, "strace (Debian package strace, installed by tools/install-deps test)");
  std::ifstream in(trace);
  std::string line;
  int opens = 0, lines = 0;
  while (std::getline(in, line)) {
    ++lines;
    if (line.find("scenes/dig.yaml\"") != std::string::npos && line.find("ENOENT") == std::string::npos) ++opens;
  }
  INFO(lines << " open calls traced");
  CHECK(lines > 10);  // the trace is real: the loader, libraries and the log are opened too
  CHECK(opens == 1);
}

TEST_CASE("tools/excavator-sim sweep: shards run through GNU parallel merge to the same table as one process, case for case, and a missing shard's cases are named") {
  const Run setup = run_sim("--help");
  const fs::path dir = setup.dir;
  write_sweep_spec("dig_monte_carlo.yaml", 8, "  duration: 0.3\n", dir / "spec.yaml");
  const std::string tool = EXC_SIM_TOOL;
  const std::string in_dir = "cd '" + dir.string() + "' && ";
  REQUIRE(std::system((in_dir + tool + " sweep spec.yaml --quiet --out one.jsonl > /dev/null 2>&1").c_str()) == 0);
  REQUIRE(std::system((in_dir + tool + " sweep-merge spec.yaml one.jsonl --out single > /dev/null 2>&1").c_str()) == 0);
  const int par = std::system((in_dir + "parallel -j2 " + tool + " sweep spec.yaml --quiet --shard {}/4 --out shard{}.jsonl ::: 0 1 2 3 > /dev/null 2>&1").c_str());
  REQUIRE_MESSAGE(par == 0, "GNU parallel (Debian package parallel, installed by tools/install-deps test)");
  REQUIRE(std::system((in_dir + tool + " sweep-merge spec.yaml shard0.jsonl shard1.jsonl shard2.jsonl shard3.jsonl --out merged > /dev/null 2>&1").c_str()) == 0);
  const std::string single = read_text_file(dir / "single" / "sweep.csv");
  CHECK(std::count(single.begin(), single.end(), '\n') == 1 + 8);  // header and one row per case
  CHECK(read_text_file(dir / "merged" / "sweep.csv") == single);
  // A shard that never ran: the merge fails and names its cases (1 and 5 of 8 in 4 shards).
  const int partial = std::system((in_dir + tool + " sweep-merge spec.yaml shard0.jsonl shard2.jsonl shard3.jsonl --out partial > /dev/null 2>&1").c_str());
  CHECK(partial != 0);
  const nlohmann::json j = nlohmann::json::parse(read_text_file(dir / "partial" / "sweep.json"));
  CHECK(j["missing"] == nlohmann::json::array({1, 5}));
  // A shard file that is not there (its task died before writing): named with its cases, the rest merged.
  const int absent = std::system((in_dir + tool + " sweep-merge spec.yaml shard0.jsonl nowhere/shard1.jsonl shard2.jsonl shard3.jsonl --out absent > absent.out 2> absent.err").c_str());
  CHECK(absent != 0);
  const nlohmann::json a = nlohmann::json::parse(read_text_file(dir / "absent" / "sweep.json"));
  CHECK(a["missing"] == nlohmann::json::array({1, 5}));
  REQUIRE(a["missing_shard_files"].size() == 1);
  CHECK(a["missing_shard_files"][0]["shard"] == "1/4");
  CHECK(a["missing_shard_files"][0]["cases"] == nlohmann::json::array({1, 5}));
  CHECK(read_text_file(dir / "absent.err").find("nowhere/shard1.jsonl is not there (shard 1/4") != std::string::npos);
  CHECK(a["merged"].get<int>() == 6);
}

TEST_CASE("tools/excavator-sim sweep-merge takes only this spec's records: shards of another spec or of an edited spec, scene or machine file, and lines of the wrong shape, are named and left out, and a case with two different records fails the merge") {
  // Shard files of an earlier run left in the directory (a shell glob picks them up) merged silently
  // into a table of another spec; a line with a missing or mistyped field stopped the merge with a
  // JSON library exception naming no file, or read past a missing field (undefined behaviour).
  const Run setup = run_sim("--help");
  const fs::path dir = setup.dir;
  // The scene names its machine file (a copy of the reference one), whose bytes the digest covers too.
  const std::string machine = read_text_file(std::string(EXC_SOURCE_DIR) + "/machines/reference-20t.yaml");
  std::ofstream(dir / "machine.yaml") << machine;
  const std::string scene = read_text_file(kDig) + "machine: machine.yaml\n";
  std::ofstream(dir / "scene.yaml") << scene;
  std::string spec = "sweep:\n  scene: scene.yaml\n  controllers: [pid]\n  cases: 2\n  duration: 0.2\n"
                     "  perturbations:\n    soil_stiffness: [0.5, 3.0]\n    model_mass: [-0.1, 0.1]\n"
                     "    delay_cycles: [0, 2]\n";
  std::ofstream(dir / "spec.yaml") << spec;
  const std::string in_dir = "cd '" + dir.string() + "' && " + EXC_SIM_TOOL;
  REQUIRE(std::system((in_dir + " sweep spec.yaml --quiet --out one.jsonl > /dev/null 2>&1").c_str()) == 0);
  const auto merge = [&](const std::string& files, const std::string& out) {
    const int raw = std::system((in_dir + " sweep-merge spec.yaml " + files + " --out " + out + " --no-charts > /dev/null 2> " +
                                 out + ".err").c_str());
    return std::pair<int, nlohmann::json>(WIFEXITED(raw) ? WEXITSTATUS(raw) : -1,
                                          nlohmann::json::parse(read_text_file(dir / out / "sweep.json")));
  };
  // The control: its own records merge whole.
  auto [status, j] = merge("one.jsonl", "whole");
  CHECK(status == 0);
  CHECK(j["merged"] == 2);
  CHECK(j["ignored_lines"].empty());

  // Edited shapes: a run without its ok, a mistyped failure, a case out of range, a mistyped draw,
  // no digest; each line named with its file and number.
  std::vector<nlohmann::json> lines;
  std::istringstream records(read_text_file(dir / "one.jsonl"));
  for (std::string l; std::getline(records, l);) lines.push_back(nlohmann::json::parse(l));
  REQUIRE(lines.size() == 2);
  const std::vector<std::pair<std::function<void(nlohmann::json&)>, std::string>> edits = {
      {[](nlohmann::json& l) { l["pid"].erase("ok"); }, "run 'pid' has no ok"},
      {[](nlohmann::json& l) { l["pid"]["failure"] = 3; }, "run 'pid' has a field of the wrong type"},
      {[](nlohmann::json& l) { l["case"] = 7; }, "its case is not a whole number in [0, 2)"},
      {[](nlohmann::json& l) { l["soil_stiffness"] = "stiff"; }, "its soil_stiffness is not a number"},
      {[](nlohmann::json& l) { l.erase("model_mass"); }, "its model_mass is not a number"},
      {[](nlohmann::json& l) { l.erase("spec"); }, "no spec digest"},
  };
  for (const auto& [edit, why] : edits) {
    CAPTURE(why);
    nlohmann::json bad = lines[0];
    edit(bad);
    std::ofstream(dir / "edited.jsonl") << bad.dump() << "\n" << lines[1].dump() << "\n";
    auto [edited_status, e] = merge("edited.jsonl", "edited");
    CHECK(edited_status == 1);
    CHECK(e["missing"] == nlohmann::json::array({0}));
    REQUIRE(e["ignored_lines"].size() == 1);
    CHECK(e["ignored_lines"][0]["line"] == 1);
    CHECK(e["ignored_lines"][0]["why"].get<std::string>().find(why) == 0);
    CHECK(read_text_file(dir / "edited.err").find("edited.jsonl line 1: " + why) != std::string::npos);
  }

  // A second record of a case: the same one is taken once; a different one fails the merge.
  std::tie(status, j) = merge("one.jsonl one.jsonl", "twice");
  CHECK(status == 0);
  CHECK(j["conflicting_records"].empty());
  nlohmann::json other = lines[1];
  other["pid"]["ok"] = !other["pid"]["ok"].get<bool>();
  std::ofstream(dir / "other.jsonl") << other.dump() << "\n";
  std::tie(status, j) = merge("one.jsonl other.jsonl", "conflict");
  CHECK(status == 1);
  REQUIRE(j["conflicting_records"].size() == 1);
  CHECK(j["conflicting_records"][0]["case"] == 1);

  // The spec edited (a longer run), its scene or the scene's machine file edited (a comment line is
  // enough: the bytes count): the old records are another sweep's.
  for (const std::string what : {"spec", "scene", "machine"}) {
    CAPTURE(what);
    std::ofstream(dir / "spec.yaml") << spec << (what == "spec" ? "  seed: 2\n" : "");
    std::ofstream(dir / "scene.yaml") << scene << (what == "scene" ? "# edited\n" : "");
    std::ofstream(dir / "machine.yaml") << machine << (what == "machine" ? "# edited\n" : "");
    std::tie(status, j) = merge("one.jsonl", "stale-" + what);
    CHECK(status == 1);
    CHECK(j["merged"] == 0);
    REQUIRE(j["ignored_lines"].size() == 2);
    CHECK(j["ignored_lines"][0]["why"].get<std::string>().find(
              "of another spec, or of this one before it, its scenes or their machine files were edited") == 0);
  }
  // All three as they were: the records are this spec's again.
  std::ofstream(dir / "spec.yaml") << spec;
  std::ofstream(dir / "scene.yaml") << scene;
  std::ofstream(dir / "machine.yaml") << machine;
  std::tie(status, j) = merge("one.jsonl", "restored");
  CHECK(status == 0);
  CHECK(j["merged"] == 2);
}

TEST_CASE("tools/excavator-sim sweep: grids cross their values and number the cases deterministically, variants and a second grid follow, the merge writes the table, the failures by value and the stability chart") {
  const Run setup = run_sim("--help");
  const fs::path dir = setup.dir;
  // Two grids (2 x 2 on the valve stage against the plant's spool lag, then 2 gain scales), 0.3 s runs.
  std::ofstream(dir / "spec.yaml") << "sweep:\n  scene: " << kDig << "\n  controllers: [adaptive]\n  duration: 0.3\n"
      "  stop_at_safe_state: true\n  grid:\n"
      "    - controller.valves.force_time_constant: [0.01, 0.03]\n"
      "      machine.hydraulics.valve_time_constant: [0.03, 0.2]\n"
      "    - gain_scale: [1, 8]\n  record: [failures, stability]\n";
  const std::string in_dir = "cd '" + dir.string() + "' && ";
  REQUIRE(std::system((in_dir + EXC_SIM_TOOL + " sweep spec.yaml --quiet --shard 1/2 --out b.jsonl > /dev/null 2>&1").c_str()) == 0);
  REQUIRE(std::system((in_dir + EXC_SIM_TOOL + " sweep spec.yaml --quiet --shard 0/2 --out a.jsonl > /dev/null 2>&1").c_str()) == 0);
  REQUIRE(std::system((in_dir + EXC_SIM_TOOL + " sweep-merge spec.yaml a.jsonl b.jsonl --out merged > merge.out 2>&1").c_str()) == 0);
  const std::string csv = read_text_file(dir / "merged" / "sweep.csv");
  INFO(csv);
  CHECK(csv.rfind("case,controller.valves.force_time_constant,machine.hydraulics.valve_time_constant,gain_scale,adaptive_ok,"
                  "adaptive_rms_swing,adaptive_rms_boom,adaptive_rms_arm,adaptive_rms_bucket,adaptive_failure\n", 0) == 0);
  // The first grid's last key fastest, then the second grid.
  for (const char* row : {"\n0,0.01,0.03,,", "\n1,0.01,0.2,,", "\n2,0.03,0.03,,", "\n3,0.03,0.2,,", "\n4,,,1,", "\n5,,,8,"})
    CHECK(csv.find(row) != std::string::npos);
  CHECK(std::count(csv.begin(), csv.end(), '\n') == 1 + 6);
  CHECK(csv.find("nan") == std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(read_text_file(dir / "merged" / "sweep.json"));
  CHECK(j["missing"].empty());
  CHECK(j["failures_by_value"]["adaptive"]["machine.hydraulics.valve_time_constant"]["0.2"]["runs"].get<int>() == 2);
  CHECK(j["failures_by_value"]["adaptive"]["gain_scale"]["8"]["runs"].get<int>() == 1);
  REQUIRE_MESSAGE(exc::test::matplotlib_available(), exc::test::kMatplotlibMissing);
  CHECK(fs::file_size(dir / "merged" / "stability.png") > 20000);
  // A chart that cannot be written (its file name taken by a directory): the table and summary are
  // written all the same, the merge says which chart failed and exits 1.
  fs::create_directories(dir / "unwritable" / "stability.png");
  const int broken = std::system((in_dir + EXC_SIM_TOOL + " sweep-merge spec.yaml a.jsonl b.jsonl --out unwritable > broken.out 2> broken.err").c_str());
  CHECK(WIFEXITED(broken));
  CHECK(WEXITSTATUS(broken) == 1);
  CHECK(read_text_file(dir / "broken.err").find("the charts failed") != std::string::npos);
  CHECK(read_text_file(dir / "broken.out").find("(a chart failed)") != std::string::npos);
  CHECK(read_text_file(dir / "unwritable" / "sweep.csv") == csv);
  // Variants with random draws: each variant gets `cases` draws, case = variant * cases + draw.
  std::ofstream(dir / "variants.yaml") << "sweep:\n  scenes: [" << kDig << "]\n  controllers: [pid]\n  duration: 0.2\n"
      "  cases: 2\n  perturbations: {model_mass: [-0.1, 0.1]}\n"
      "  variants:\n    - {name: nominal}\n    - {name: late, delay_cycles: 2}\n";
  REQUIRE(std::system((in_dir + EXC_SIM_TOOL + " sweep variants.yaml --quiet --out v.jsonl > /dev/null 2>&1").c_str()) == 0);
  REQUIRE(std::system((in_dir + EXC_SIM_TOOL + " sweep-merge variants.yaml v.jsonl --out v > /dev/null 2>&1").c_str()) == 0);
  const std::string v = read_text_file(dir / "v" / "sweep.csv");
  CHECK(v.rfind("case,variant,model_mass,delay_cycles,pid_ok,", 0) == 0);
  for (const char* row : {"\n0,nominal,", "\n1,nominal,", "\n2,late,", "\n3,late,"}) CHECK(v.find(row) != std::string::npos);
  // A knob set twice, or unknown, is refused with the file, line and field.
  std::ofstream(dir / "bad.yaml") << "sweep:\n  scene: " << kDig << "\n  grid:\n    bulk_modulus: [1e9]\n";
  const Run bad = run_sim("sweep " + (dir / "bad.yaml").string() + " --quiet");
  CHECK(bad.status == 2);
  CHECK(bad.err.find("bad.yaml") != std::string::npos);
  CHECK(bad.err.find("bulk_modulus") != std::string::npos);
  // A value that is not a finite number (read as a settings file reads it) is refused at its element.
  for (const char* value : {".nan", ".inf", "fast", "1e3x"}) {
    std::ofstream(dir / "nan.yaml") << "sweep:\n  scene: " << kDig << "\n  grid:\n    gain_scale: [1, " << value << "]\n";
    const Run nan = run_sim("sweep " + (dir / "nan.yaml").string() + " --quiet");
    INFO(value << ": " << nan.err);
    CHECK(nan.status == 2);
    CHECK(nan.err.find("nan.yaml") != std::string::npos);
    CHECK(nan.err.find("gain_scale[1]") != std::string::npos);
    CHECK(nan.err.find("must be a number") != std::string::npos);
  }
}

TEST_CASE("tools/excavator-sim fault campaign (a CI sample): every run under a random fault on the dig and the free motion ends tracking within its limits or in the safe state within the watchdog time of the fault's detection, none otherwise, every fault kind drawn") {
  const Run setup = run_sim("--help");
  const fs::path dir = setup.dir;
  write_sweep_spec("fault_campaign.yaml", 12, "", dir / "spec.yaml");  // 12 cases on each scene
  const std::string in_dir = "cd '" + dir.string() + "' && ";
  REQUIRE(std::system((in_dir + EXC_SIM_TOOL + " sweep spec.yaml --quiet --out all.jsonl > /dev/null 2>&1").c_str()) == 0);
  REQUIRE(std::system((in_dir + EXC_SIM_TOOL + " sweep-merge spec.yaml all.jsonl --out merged > /dev/null 2>&1").c_str()) == 0);
  const nlohmann::json j = nlohmann::json::parse(read_text_file(dir / "merged" / "sweep.json"));
  const double watchdog = exc::sim::load_scene_bundle(kDig).firmware.controller.watchdog_timeout;
  int runs = 0, kinds = 0;
  // Judged by the machine (docs/safety.md, the stop requirement): every stopped run carries its stop
  // judged on the plant's truth, and a stop that misses R3 is "neither". Those are counted and
  // printed apart; every other way of ending neither must not happen.
  std::map<std::string, int> not_at_rest;
  int not_at_rest_total = 0, judged = 0;
  // R1 counted here from each run's own stop (a stuck spool's: within 100 ms of its onset of
  // disagreement, later, or found before its spool disagreed), for the tables' R1 line below.
  std::map<std::string, std::array<int, 3>> r1;
  {
    std::istringstream lines(read_text_file(dir / "all.jsonl"));
    for (std::string line; std::getline(lines, line);) {
      const nlohmann::json l = nlohmann::json::parse(line);
      for (const char* c : {"pid", "adaptive"}) {
        const nlohmann::json& r = l[c];
        INFO("case " << l["case"] << " " << c << ": " << r.dump());
        if (r.contains("safe_state_time")) {
          REQUIRE(r.contains("stop"));
          const nlohmann::json& stop = r["stop"];
          CHECK(stop["detected_after_s"].get<double>() ==
                doctest::Approx(r["fault_detected_time"].get<double>() - l["fault"]["start"].get<double>()));
          CHECK(stop["outputs_after_s"].get<double>() >= 0);
          // R1 from a stuck spool's onset of disagreement when it came before detection, else from
          // the fault's start.
          if (stop["onset_after_s"].is_null())
            CHECK(stop["detected_after_onset_s"].get<double>() == doctest::Approx(stop["detected_after_s"].get<double>()));
          else
            CHECK(stop["detected_after_onset_s"].get<double>() ==
                  doctest::Approx(stop["detected_after_s"].get<double>() - stop["onset_after_s"].get<double>()));
          CHECK(stop["drift_after_1_5_s"].size() == 4);
          CHECK(stop["ring_tau_s"].size() == 4);
          CHECK(stop["drift_fit_span_s"].get<double>() >= 2.0 - 2e-3);  // the run went on until the fit had its span
          CHECK(stop["exempt"].is_array());
          ++judged;
          const std::string kind = l["fault"]["kind"].get<std::string>();
          if (kind == "spool_stuck" || kind == "actuator_jam")
            ++r1[c][stop["onset_after_s"].is_null() ? 2 : stop["detected_after_onset_s"].get<double>() <= 0.1 + 1e-9 ? 0 : 1];
        }
        if (r.value("outcome", "") != "neither") continue;
        const std::string why = r.value("why", "");
        CHECK(why.rfind("the stop misses R3", 0) == 0);
        CHECK(r["safe_state_time"].get<double>() - r["fault_detected_time"].get<double>() <= watchdog + 1e-9);
        ++not_at_rest[std::string(c) + " " + l["fault"]["kind"].get<std::string>()];
        ++not_at_rest_total;
      }
    }
  }
  MESSAGE("stopped runs judged against R3: " << judged << ", missing it: " << not_at_rest_total);
  CHECK(judged > 0);
  for (const char* c : {"pid", "adaptive"}) {
    REQUIRE(j["campaign"].contains(c));
    std::map<std::string, int> per_scene;
    for (const auto& [kind, k] : j["campaign"][c].items()) {
      INFO(c << " " << kind << ": " << k.dump());
      CHECK(k["neither"].get<int>() == not_at_rest[std::string(c) + " " + kind]);
      CHECK(k["tracked"].get<int>() + k["safe_state"].get<int>() + k["neither"].get<int>() == k["runs"].get<int>());
      if (!k["worst_time_from_detection"].is_null()) CHECK(k["worst_time_from_detection"].get<double>() <= watchdog + 1e-9);
      for (const auto& [scene, n] : k["scenes"].items()) per_scene[scene] += n["runs"].get<int>();
      runs += k["runs"].get<int>();
      ++kinds;
    }
    CHECK(per_scene == std::map<std::string, int>{{"dig", 12}, {"free_motion", 12}});  // cases 0-11 on the dig, 12-23 on the free motion
    // The same runs per safety function (the fault that took the stop): they add up to the runs,
    // and each row's kinds to its runs.
    REQUIRE(j["safety_functions"].contains(c));
    int by_function = 0;
    for (const auto& [name, f] : j["safety_functions"][c].items()) {
      INFO(c << " " << name << ": " << f.dump());
      int by_kind = 0;
      for (const auto& [kind, n] : f["kinds"].items()) by_kind += n.get<int>();
      CHECK(by_kind == f["runs"].get<int>());
      by_function += f["runs"].get<int>();
    }
    CHECK(by_function == 24);
  }
  CHECK(runs == 2 * 24);
  CHECK(kinds == 2 * 7);
  // docs/safety.md's tables come from this file through tools/sweep/campaign_tables.py: each fault
  // kind's row carries the merge's tracked / safe / neither per law.
  REQUIRE(std::system((in_dir + "/usr/bin/python3 " + EXC_SOURCE_DIR +
                       "/tools/sweep/campaign_tables.py merged > tables.md 2> tables.err").c_str()) == 0);
  const std::string tables = read_text_file(dir / "tables.md");
  for (const auto& [kind, k] : j["campaign"]["pid"].items()) {
    const nlohmann::json& a = j["campaign"]["adaptive"][kind];
    const auto cell = [](const nlohmann::json& r) {
      return std::to_string(r["tracked"].get<int>()) + " / " + std::to_string(r["safe_state"].get<int>()) + " / " +
             std::to_string(r["neither"].get<int>());
    };
    const std::string row = "| " + kind + " | " + std::to_string(k["runs"].get<int>()) + " | " + cell(k) + " | " + cell(a) + " |";
    INFO(row << "\n" << tables);
    CHECK(tables.find(row) != std::string::npos);
  }
  CHECK(tables.find("| H3 sensor watchdog |") != std::string::npos);  // bus_burst's stops, under their hazard
  // The documented --requirements column: the watchdog's row names its requirement.
  REQUIRE(std::system((in_dir + "/usr/bin/python3 " + EXC_SOURCE_DIR +
                       "/tools/sweep/campaign_tables.py merged --requirements > req.md 2> req.err").c_str()) == 0);
  CHECK(read_text_file(dir / "req.md").find("| H3 sensor watchdog | 20 ms watchdog (H3) |") != std::string::npos);
  // And the stop requirement's table: R4's count is the merge's "neither" over every kind.
  int neither = 0;
  for (const auto& [kind, k] : j["campaign"]["pid"].items()) neither += k["neither"].get<int>();
  CHECK(read_text_file(dir / "req.md").find("R4, runs that neither track nor meet R3: " + std::to_string(neither) + " / ") !=
        std::string::npos);
  // R1's line: the stuck spools' counts per law as the runs' own stops give them.
  const auto pair = [&r1](int i) { return std::to_string(r1["pid"][i]) + " / " + std::to_string(r1["adaptive"][i]); };
  const std::string r1_line = "onset of disagreement (pid / adaptive): " + pair(0) + "; later: " + pair(1) +
                              "; found before their spool disagreed past the spool monitor's limits: " + pair(2) + ".";
  INFO(r1_line << "\n" << read_text_file(dir / "req.md"));
  CHECK(read_text_file(dir / "req.md").find(r1_line) != std::string::npos);
}

TEST_CASE("tools/excavator-sim sweep refuses a spec naming both scene and scenes, and pump_loss on a scene without pumps before any run") {
  const Run setup = run_sim("--help");
  const std::string in_dir = "cd '" + setup.dir.string() + "' && ";
  std::ofstream(setup.dir / "both.yaml") << "sweep:\n  scene: " << kDig << "\n  scenes: [" << kDig << "]\n";
  std::ofstream(setup.dir / "pumps.yaml") << "sweep:\n  scene: " << kPaperDig << "\n  faults: [rock, pump_loss]\n";
  for (const auto& [spec, reason] : {std::pair<std::string, std::string>{"both.yaml", "scene: FILE or scenes: [FILE, ...] (one of them)"},
                                     {"pumps.yaml", "pump_loss needs the hydraulic machine; " + kPaperDig}}) {
    const int status = std::system((in_dir + EXC_SIM_TOOL + " sweep " + spec + " --quiet --out x.jsonl > out.txt 2> err.txt").c_str());
    const std::string err = read_text_file(setup.dir / "err.txt");
    INFO(spec << ": " << err);
    CHECK(WEXITSTATUS(status) == 2);
    CHECK(err.find(reason) != std::string::npos);
  }
}

TEST_CASE("tools/excavator-sim: the 10 s paper dig run for 40 s ends its task at 10.05 s and holds, no worse than the 10 s run") {
  const Run short_run = run_sim("run " + kPaperDig + " --quiet --no-report --json s.json");
  const Run long_run = run_sim("run " + kPaperDig + " --duration 40 --quiet --no-report --json l.json --out out");
  REQUIRE(short_run.status == 0);
  REQUIRE(long_run.status == 0);
  const nlohmann::json s = nlohmann::json::parse(read_text_file(short_run.dir / "s.json"));
  const nlohmann::json l = nlohmann::json::parse(read_text_file(long_run.dir / "l.json"));
  for (const char* c : {"pid", "adaptive"}) {
    INFO(c);
    CHECK(l[c]["task_finished"].get<bool>());
    CHECK(l[c]["task_finish_time"].get<double>() == doctest::Approx(10.05).epsilon(1e-4));
    CHECK(long_run.out.find(std::string(c) + (std::string(c) == "pid" ? "       " : "  ") + " task finished at 10.050 s;") !=
          std::string::npos);
    // The pass itself is the 10 s run's (the metric covers tracking only).
    CHECK(l[c]["max_error"]["bucket"].get<double>() <= s[c]["max_error"]["bucket"].get<double>() * 1.0001);
  }
  // After the end, from the log: the desired pose never moves again and the error stays small (before:
  // the path restarted every 10 s, a 0.5 m step on the bucket).
  lcm::LogFile log((long_run.dir / "out" / "run.lcm").string(), "r");
  REQUIRE(log.good());
  std::map<std::string, double> worst_error, desired_change;
  std::map<std::string, exlcm::controller_state_t> first_after;
  long held = 0;
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    if (e->channel.rfind("EXC_CONTROLLER/", 0) != 0) continue;
    exlcm::controller_state_t m;
    REQUIRE(m.decode(e->data, 0, e->datalen) > 0);
    if (m.utime < 12'000'000) continue;  // from 2 s after the end on (the end's transient has settled)
    ++held;
    const std::string c = e->channel;
    if (!first_after.count(c)) first_after[c] = m;
    for (int j = 0; j < 4; ++j) {
      worst_error[c] = std::max(worst_error[c], std::abs(m.error[j]));
      desired_change[c] = std::max(desired_change[c], std::abs(m.q_desired[j] - first_after[c].q_desired[j]));
    }
  }
  CHECK(held == 2 * 28001);  // every cycle from 12 s to 40 s, both controllers
  for (const auto& [c, w] : worst_error) {
    INFO(c);
    CHECK(desired_change[c] == 0.0);
    CHECK(w < 1e-3);  // held within a millimetre of the final pose
  }
}

TEST_CASE("tools/excavator-sim: the hydraulic dig run for 40 s holds its final pose with the valves centred, every controller, no hunting and no drift beyond the leakage's creep") {
  const Run r = run_sim("run " + kDig + " --duration 40 --quiet --no-report --json l.json --out out");
  INFO(r.err);
  REQUIRE(r.status == 0);
  const nlohmann::json l = nlohmann::json::parse(read_text_file(r.dir / "l.json"));
  for (const char* c : {"pid", "adaptive", "flow"}) {
    INFO(c);
    CHECK(l[c]["task_finished"].get<bool>());
    CHECK(l[c]["task_finish_time"].get<double>() == doctest::Approx(10.05).epsilon(1e-4));
  }
  lcm::LogFile log((r.dir / "out" / "run.lcm").string(), "r");
  REQUIRE(log.good());
  std::map<std::string, double> worst_error, desired_change, moved;
  std::map<std::string, exlcm::controller_state_t> first_after;
  std::map<std::string, exlcm::machine_state_t> at_20s;
  std::map<std::string, std::array<double, 4>> moved_by;  // per joint, from 20 s to 40 s
  long held = 0;
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    const std::string channel = e->channel;
    if (channel.rfind("EXC_STATE/", 0) == 0) {
      exlcm::machine_state_t m;
      REQUIRE(m.decode(e->data, 0, e->datalen) > 0);
      if (m.utime < 20'000'000) continue;
      const std::string c = channel.substr(10);
      if (!at_20s.count(c)) at_20s[c] = m;
      for (int j = 0; j < 4; ++j) {
        moved[c] = std::max(moved[c], std::abs(m.q_active[j] - at_20s[c].q_active[j]));
        moved_by[c][j] = m.q_active[j] - at_20s[c].q_active[j];
      }
      continue;
    }
    if (channel.rfind("EXC_CONTROLLER/", 0) != 0) continue;
    exlcm::controller_state_t m;
    REQUIRE(m.decode(e->data, 0, e->datalen) > 0);
    if (m.utime < 12'000'000) continue;  // from 2 s after the end on
    ++held;
    const std::string c = channel.substr(15);
    if (!first_after.count(c)) first_after[c] = m;
    for (int j = 0; j < 4; ++j) {
      worst_error[c] = std::max(worst_error[c], std::abs(m.error[j]));
      desired_change[c] = std::max(desired_change[c], std::abs(m.q_desired[j] - first_after[c].q_desired[j]));
    }
  }
  CHECK(held == 3 * 28001);  // every cycle from 12 s to 40 s, three controllers
  REQUIRE(moved.size() == 3);
  for (const auto& [c, w] : worst_error) {
    INFO(c << ": worst error " << w << " m, moved " << moved[c] << " m from 20 s to 40 s");
    CHECK(desired_change[c] == 0.0);
    // In position (1 mm window, the valve corrects again beyond 2 mm): no hunting around the pose...
    CHECK(w < 2e-3);
    // ...and the closed valves hold it: the machine stays where it settled, but for the creep of the
    // machine's internal leakage (docs/plant.md): no chamber loses more than (C_spool + C_piston)
    // (p - p_tank) past its spool and piston, which moves the piston at most that over its area, at
    // the pressures of 20 s (leakage only lowers them). The seals may hold a function all the while.
    const exc::Machine machine = exc::reference_machine();
    const exc::HydraulicParameters& hp = machine.hydraulics;
    const exc::Vec4 lo = machine.effort_min(), hi = machine.effort_max();
    const exlcm::machine_state_t& s20 = at_20s[c];
    CHECK(std::abs(moved_by[c][0]) < 1e-4);  // the swing carries no load: it does not creep
    for (int j = 1; j < 4; ++j) {
      const double leak = hp.spool_leakage[j] + hp.piston_leakage[j];
      const double creep = 20.0 * leak * std::max((s20.pressure_a[j] - hp.tank_pressure) * machine.relief_pressure / hi[j],
                                                  (s20.pressure_b[j] - hp.tank_pressure) * machine.relief_pressure / -lo[j]);
      MESSAGE(c << " joint " << j << ": moved " << moved_by[c][j] * 1e3 << " mm in 20 s, the leakage's creep at most "
                << creep * 1e3 << " mm");
      CHECK(std::abs(moved_by[c][j]) <= creep);
    }
  }
}

TEST_CASE("tools/excavator-sim: an output file that cannot be written is an error naming it (run --json before the run, sweep-merge's table, excavator-firmware --json before the bus), not a quiet success") {
  // --json into a directory that does not exist: the run itself tracked, the summary is lost.
  const Run json = run_sim("run " + kDig + " --controller pid --duration 0.1 --no-report --out out --json no/such/dir/run.json");
  INFO(json.err);
  CHECK(json.status == 2);
  CHECK(json.err.find("no/such/dir/run.json: cannot write") != std::string::npos);
  // ...refused before the run: no log, no summary, no tracking printed.
  CHECK_FALSE(fs::exists(json.dir / "out" / "run.lcm"));
  CHECK_FALSE(fs::exists(json.dir / "out" / "summary.json"));
  // The control: the same run with a writable path writes it and exits 0.
  const Run ok = run_sim("run " + kDig + " --controller pid --duration 0.1 --no-report --out out --json run.json");
  CHECK(ok.status == 0);
  CHECK(fs::file_size(ok.dir / "run.json") > 100);
  // sweep-merge whose table's name a directory takes.
  const fs::path dir = ok.dir;
  std::ofstream(dir / "spec.yaml") << "sweep:\n  scene: " << kDig << "\n  controllers: [pid]\n  duration: 0.1\n"
                                      "  grid:\n    gain_scale: [1]\n";
  const std::string in_dir = "cd '" + dir.string() + "' && ";
  REQUIRE(std::system((in_dir + EXC_SIM_TOOL + " sweep spec.yaml --quiet --out s.jsonl > /dev/null 2>&1").c_str()) == 0);
  fs::create_directories(dir / "merged" / "sweep.csv");
  const int merged = std::system((in_dir + EXC_SIM_TOOL + " sweep-merge spec.yaml s.jsonl --out merged --no-charts > /dev/null 2> merge.err").c_str());
  CHECK(WIFEXITED(merged));
  CHECK(WEXITSTATUS(merged) == 2);
  CHECK(read_text_file(dir / "merge.err").find("sweep.csv: cannot write") != std::string::npos);
  // excavator-firmware's --json too is refused before the bus is opened: with an interface that does
  // not exist, the unwritable path is what it names; the control (a writable path) gets to the bus.
  const std::string firmware = in_dir + EXC_FIRMWARE_TOOL + " --can exc_no_such_if --scene " + kDig;
  const int fw_bad = std::system((firmware + " --json no/such/dir/fw.json > /dev/null 2> fw_bad.err").c_str());
  const std::string fw_bad_err = read_text_file(dir / "fw_bad.err");
  INFO(fw_bad_err);
  CHECK(WIFEXITED(fw_bad));
  CHECK(WEXITSTATUS(fw_bad) == 2);
  CHECK(fw_bad_err.find("no/such/dir/fw.json: cannot write") != std::string::npos);
  CHECK(fw_bad_err.find("exc_no_such_if") == std::string::npos);
  const int fw_good = std::system((firmware + " --json fw.json > /dev/null 2> fw_good.err").c_str());
  const std::string fw_good_err = read_text_file(dir / "fw_good.err");
  INFO(fw_good_err);
  CHECK(WIFEXITED(fw_good));
  CHECK(WEXITSTATUS(fw_good) != 0);
  CHECK(fw_good_err.find("exc_no_such_if") != std::string::npos);
  CHECK(fw_good_err.find("cannot write") == std::string::npos);
}

TEST_CASE("tools/excavator-sim refuses a controller named twice (run --controller, a sweep spec's list) and an unknown one, before any run") {
  // Two runs of one controller would share its telemetry channels and its summary entry.
  const Run twice = run_sim("run " + kDig + " --controller pid,pid --duration 0.1 --no-report --out out");
  INFO(twice.err);
  CHECK(twice.status == 2);
  CHECK(twice.err.find("--controller: 'pid' is given twice") != std::string::npos);
  CHECK(twice.out.find("pid  ") == std::string::npos);  // no run's table
  // An unknown name after a valid one: refused before the valid one runs.
  const Run unknown = run_sim("run " + kDig + " --controller pid,bogus --duration 0.1 --no-report --out out");
  INFO(unknown.err);
  CHECK(unknown.status == 2);
  CHECK(unknown.err.find("unknown controller 'bogus'") != std::string::npos);
  CHECK(unknown.err.find("excavator-sim: dig with pid") == std::string::npos);  // no run's progress line
  // A sweep spec's list, at its line and element; the control runs.
  const fs::path dir = twice.dir;
  std::ofstream(dir / "twice.yaml") << "sweep:\n  scene: " << kDig << "\n  controllers: [pid, pid]\n  duration: 0.1\n";
  std::ofstream(dir / "once.yaml") << "sweep:\n  scene: " << kDig << "\n  controllers: [pid]\n  duration: 0.1\n";
  const Run spec = run_sim("sweep " + (dir / "twice.yaml").string() + " --quiet --out s.jsonl");
  INFO(spec.err);
  CHECK(spec.status == 2);
  CHECK(spec.err.find("twice.yaml:3:22: sweep.controllers[1]: 'pid' is listed twice") != std::string::npos);
  const Run control = run_sim("sweep " + (dir / "once.yaml").string() + " --quiet --out s.jsonl");
  CHECK(control.status == 0);
  const Run control_run = run_sim("run " + kDig + " --controller pid --duration 0.1 --no-report --out out");
  CHECK(control_run.status == 0);
}

TEST_CASE("tools/excavator-sim refuses a law its scene's command interface cannot carry before the log's size line, writing nothing") {
  const Run flow = run_sim("run " + kPaperDig + " --controller flow --duration 0.1 --out out");
  INFO(flow.err);
  CHECK(flow.status == 2);
  CHECK(flow.err.find("--controller: flow commands the valves' flow: it needs command_interface: valve") != std::string::npos);
  CHECK(flow.err.find("controller.command_interface is effort") != std::string::npos);
  CHECK(flow.err.find("excavator-sim: log ") == std::string::npos);  // no log-size line
  CHECK(!fs::exists(flow.dir / "out" / "effective.yaml"));
  CHECK(!fs::exists(flow.dir / "out" / "run.lcm"));
  // The control: a law that fits runs and writes both.
  const Run pid = run_sim("run " + kPaperDig + " --controller pid --duration 0.1 --no-report --out out");
  CHECK(pid.status == 0);
  CHECK(fs::exists(pid.dir / "out" / "effective.yaml"));
}

namespace {

// excavator-sim started in `dir` with `args` (stdout and stderr to files there), not waited for.
pid_t spawn_sim(const fs::path& dir, const std::vector<std::string>& args) {
  std::vector<std::string> all = {EXC_SIM_TOOL};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  const std::string out = (dir / "out.txt").string(), err = (dir / "err.txt").string();
  posix_spawn_file_actions_addopen(&files, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&files, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addchdir_np(&files, dir.c_str());
  // A process group of its own, as a terminal's job: kill(-pid) reaches its helper programs too.
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attributes, 0);
  pid_t pid = 0;
  REQUIRE(posix_spawn(&pid, EXC_SIM_TOOL, &files, &attributes, argv.data(), environ) == 0);
  posix_spawn_file_actions_destroy(&files);
  posix_spawnattr_destroy(&attributes);
  return pid;
}

// Waits (up to a minute) until `ready` holds.
bool wait_for(const std::function<bool()>& ready) {
  for (int i = 0; i < 6000; ++i) {
    if (ready()) return true;
    usleep(10000);
  }
  return false;
}

}  // namespace

TEST_CASE("tools/excavator-sim: a first Ctrl-C ends the run at a cycle, writes its summary marked interrupted, a closed log and the report, exit 130, and a second aborts") {
  const fs::path dir = exc::test::scratch_dir(fs::path(EXC_BINARY_DIR) / "tests" / "sim" / ("interrupt_" + std::to_string(getpid())));
  const fs::path log = dir / "out" / "run.lcm";
  const pid_t sim = spawn_sim(dir, {"run", kDig, "--controller", "pid,adaptive", "--duration", "600", "--out", "out"});
  // Running once its log has events in it.
  REQUIRE(wait_for([&] { std::error_code ec; return fs::file_size(log, ec) > 100000 && !ec; }));
  kill(sim, SIGINT);
  int status = 0;
  waitpid(sim, &status, 0);
  const std::string err = read_text_file(dir / "err.txt");
  INFO(err);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 130);
  CHECK(err.find("interrupted: the run ends at the next cycle") != std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(read_text_file(dir / "out" / "summary.json"));
  CHECK(j["ok"] == false);
  CHECK(j["interrupted"] == true);
  REQUIRE(j.contains("pid"));
  CHECK(j["pid"]["failure"].get<std::string>().rfind("interrupted (SIGINT) at ", 0) == 0);
  CHECK(j["pid"]["simulated_seconds"].get<double>() < 600);
  CHECK(!j.contains("adaptive"));  // the controller after the interrupted one did not run
  // The log is whole (every event complete) and the report of what ran is written.
  const std::string info = "'" + std::string(EXC_LOG_TOOL) + "' info '" + log.string() + "' > '" + (dir / "info.txt").string() +
                           "' 2> '" + (dir / "info_err.txt").string() + "'";
  CHECK(std::system(info.c_str()) == 0);
  CHECK(read_text_file(dir / "info_err.txt").find("no complete event") == std::string::npos);
  CHECK(fs::exists(dir / "out" / "report" / "report.md"));

  // A second Ctrl-C, once the first was taken (the report's helpers then run for seconds): the
  // program ends by the signal, at once.
  const fs::path again_dir = exc::test::scratch_dir(dir / "again");
  const pid_t again = spawn_sim(again_dir, {"run", kDig, "--controller", "pid", "--duration", "600", "--out", "out"});
  REQUIRE(wait_for([&] { std::error_code ec; return fs::file_size(again_dir / "out" / "run.lcm", ec) > 100000 && !ec; }));
  kill(again, SIGINT);
  REQUIRE(wait_for([&] { return read_text_file(again_dir / "err.txt").find("interrupted: the run ends") != std::string::npos; }));
  kill(-again, SIGINT);  // to the job, as a terminal sends it
  int again_status = 0;
  waitpid(again, &again_status, 0);
  CHECK(WIFSIGNALED(again_status));
  CHECK(WTERMSIG(again_status) == SIGINT);
}

TEST_CASE("tools/excavator-sim sweep refuses a --shard that is not exactly I/N with 0 <= I < N (trailing text, a third part, overflow, a sign), and runs one that is") {
  const Run first = run_sim("sweep --help");
  REQUIRE(first.status == 0);
  std::ofstream(first.dir / "spec.yaml") << "sweep:\n  scene: " << kDig << "\n  controllers: [pid]\n  duration: 0.05\n  cases: 2\n";
  const std::string spec = (first.dir / "spec.yaml").string();
  for (const char* bad : {"1/2/3", "0/2x", "0/100000000000", "+0/2", "-1/2", "2/2", "0/0", "1", "/2", " 0/2"}) {
    INFO("--shard '" << bad << "'");
    const Run r = run_sim("sweep " + spec + " --quiet --out s.jsonl --shard '" + bad + "'");
    CHECK(r.status == 2);
    CHECK(r.err.find("must be I/N with 0 <= I < N") != std::string::npos);
    CHECK_FALSE(fs::exists(r.dir / "s.jsonl"));
  }
  const Run good = run_sim("sweep " + spec + " --quiet --out s.jsonl --shard 1/2");  // the control: case 1 of 2
  INFO(good.err);
  CHECK(good.status == 0);
  CHECK(good.out.find("sweep shard 1/2: 1 cases") != std::string::npos);
}
