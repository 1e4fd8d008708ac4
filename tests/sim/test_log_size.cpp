// The size of a run's log, before and after: excavator-sim states the log's expected size before its
// runs (and the statement holds against the file it writes), refuses a run whose log the disk cannot
// hold, and --log-every records the per-cycle channels at a lower rate, saying so where the run is
// reported.
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>

#include "log_channels.hpp"
#include "scratch_files.hpp"
#include "sim_runs.hpp"

namespace fs = std::filesystem;
using exc::test::csv_data_rows;
using exc::test::kDig;
using exc::test::kPerCycleChannels;
using exc::test::LogChannel;
using exc::test::read_log_channels;
using exc::test::read_text_file;
using exc::test::Run;
using exc::test::run_sim;

namespace {

// The expected size stated on stderr for the log at `log` ("excavator-sim: log PATH: about 4.6 MB
// (4612345 bytes: ...)"), -1 if there is no such line.
long long stated_log_bytes(const std::string& err, const fs::path& log) {
  const std::regex line("excavator-sim: log ([^:]+): about [^(]+\\(([0-9]+) bytes: [^\n]*free on its file system\n");
  for (std::sregex_iterator m(err.begin(), err.end(), line), end; m != end; ++m)
    if (fs::weakly_canonical((*m)[1].str()) == fs::weakly_canonical(log)) return std::stoll((*m)[2].str());
  return -1;
}

// The prefix that runs a shell command in a private mount namespace (its mounts vanish with it and
// are seen by no other process), tried on `mount_point`: as root (CAP_SYS_ADMIN), else as root of a
// user namespace. Empty when the kernel or the container allows neither.
std::string private_mount_namespace(const fs::path& mount_point) {
  for (const char* prefix : {"unshare --mount", "unshare --mount --map-root-user"}) {
    const std::string probe = std::string(prefix) + " sh -c 'mount -t tmpfs -o size=64k exc-probe \"" +
                              mount_point.string() + "\"' > /dev/null 2>&1";
    if (std::system(probe.c_str()) == 0) return prefix;
  }
  return "";
}

}  // namespace

TEST_CASE("tools/excavator-sim states its log's expected size on stderr before its runs, within 1 % of the log it writes, whole and with --log-every 50") {
  for (const std::string every : {"1", "50"}) {
    INFO("--log-every " << every);
    const Run r = run_sim("run " + kDig + " --duration 1 --no-report --out out --log-every " + every);
    INFO(r.err);
    REQUIRE(r.status == 0);
    const fs::path log = r.dir / "out" / "run.lcm";
    const long long stated = stated_log_bytes(r.err, log);
    REQUIRE(stated > 0);
    const auto written = static_cast<long long>(fs::file_size(log));
    MESSAGE("--log-every " << every << ": stated " << stated << " bytes, written " << written);
    CHECK(std::abs(stated - written) <= written / 100);
    // Said before the first run starts (its progress line), with the rate and the controllers.
    const auto statement = r.err.find("excavator-sim: log ");
    CHECK(statement < r.err.find(" with pid"));
    CHECK(r.err.find("3 controllers x 1000 cycles, EXC_STATE, EXC_COMMAND and EXC_CONTROLLER " +
                     std::string(every == "1" ? "every cycle" : "every 50th cycle")) != std::string::npos);
  }
}

TEST_CASE("tools/excavator-sim --log-every 10 records EXC_STATE, EXC_COMMAND and EXC_CONTROLLER of every 10th cycle, the other channels whole, and says so on stdout, in the JSON and in the report") {
  const Run whole = run_sim("run " + kDig + " --controller adaptive --duration 1 --quiet --no-report --out out");
  const Run thinned = run_sim("run " + kDig + " --controller adaptive --duration 1 --quiet --out out --log-every 10");
  INFO(thinned.err);
  REQUIRE(whole.status == 0);
  REQUIRE(thinned.status == 0);
  const auto all = read_log_channels(whole.dir / "out" / "run.lcm");
  const auto kept = read_log_channels(thinned.dir / "out" / "run.lcm");
  for (const char* base : kPerCycleChannels) {
    const std::string name = std::string(base) + "/adaptive";
    INFO(name);
    REQUIRE(all.count(name) == 1);
    REQUIRE(kept.count(name) == 1);
    CHECK(all.at(name).count == 1000);
    // Cycles 1, 11, ..., 991: seq 0 .. 99 without a gap (a gap still means a lost message), each
    // message 10 cycles after the one before.
    const LogChannel& c = kept.at(name);
    CHECK(c.count == 100);
    CHECK(c.first_seq == 0);
    CHECK(c.last_seq == 99);
    CHECK(c.seq_gaps == 0);
    CHECK(c.first_utime == 1000);
    CHECK(c.last_utime == 991000);
    CHECK(c.utime_steps.size() == 1);
    CHECK(c.utime_steps.count(10000) == 1);
  }
  for (const char* base : {"EXC_TIMING", "EXC_CAN_STATS", "EXC_FAULT"}) {
    const std::string name = std::string(base) + "/adaptive";
    INFO(name);
    REQUIRE(all.count(name) == 1);
    REQUIRE(kept.count(name) == 1);
    CHECK(kept.at(name).count == all.at(name).count);
  }
  // What the run says of it: the summary on stdout, the JSON, the report page.
  CHECK(thinned.out.find("telemetry: EXC_STATE, EXC_COMMAND and EXC_CONTROLLER logged every 10 cycles (--log-every)") !=
        std::string::npos);
  CHECK(whole.out.find("(--log-every)") == std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(read_text_file(thinned.dir / "out" / "summary.json"));
  CHECK(j["adaptive"]["telemetry"]["per_cycle_every"].get<int>() == 10);
  long long logged = 0;
  for (const auto& [name, channel] : kept)
    if (name != "EXC_TELEMETRY_STATS/adaptive") logged += channel.count;
  CHECK(j["adaptive"]["telemetry"]["published"].get<long long>() == logged);
  const std::string report = read_text_file(thinned.dir / "out" / "report" / "report.md");
  CHECK(report.find("| per-cycle channels logged | every 10 cycles |") != std::string::npos);
  CHECK(report.find("EXC_CONTROLLER of one control cycle in 10 only (`--log-every 10`)") != std::string::npos);
  CHECK(csv_data_rows(thinned.dir / "out" / "report" / "csv" / "EXC_STATE__adaptive.csv") == 100);
  // The option's range, as every numeric option's.
  const Run zero = run_sim("run " + kDig + " --log-every 0");
  CHECK(zero.status != 0);
  CHECK(zero.err.find("--log-every: is 0; allowed range [1, 10000]") != std::string::npos);
}

TEST_CASE("tools/excavator-sim refuses a run whose log the disk cannot hold before the run, naming the log, both sizes and what to change, and runs it with --log-every 50 on the same disk") {
  // A 1 MiB disk: a tmpfs mounted in a private mount namespace, the real statvfs of a real file system
  // (no test seam in the program). The namespace is root's own or a user namespace's.
  const fs::path dir = exc::test::scratch_dir(fs::path(EXC_BINARY_DIR) / "tests" / "sim" /
                                              ("small_disk_" + std::to_string(getpid())));
  fs::create_directories(dir / "small");
  const std::string ns = private_mount_namespace(dir / "small");
  REQUIRE_MESSAGE(!ns.empty(), "this test mounts a 1 MiB tmpfs in a private mount namespace (unshare --mount, as root "
                               "or in a user namespace): neither is allowed here");
  // Inside the namespace: mount, run, and record what the disk holds after (the tmpfs vanishes with it).
  const auto run_small = [&](const std::string& args, const std::string& tag) {
    const std::string script = "mount -t tmpfs -o size=1m exc-small small && " + std::string(EXC_SIM_TOOL) + " " + args +
                               " > " + tag + ".out 2> " + tag + ".err; echo \\$? > " +
                               tag + ".status; stat -c %s small/out/run.lcm > " + tag + ".size 2>/dev/null; ls small/out > " +
                               tag + ".files 2>/dev/null; true";
    const std::string cmd = "cd '" + dir.string() + "' && " + ns + " sh -c \"" + script + "\"";
    REQUIRE(std::system(cmd.c_str()) == 0);
  };
  // The hydraulic dig's three controllers for 1 s: about 3 MB.
  const std::string dig_run = "run " + kDig + " --duration 1 --out small/out";
  run_small(dig_run, "whole");
  const std::string err = read_text_file(dir / "whole.err");
  INFO(err);
  CHECK(std::atoi(read_text_file(dir / "whole.status").c_str()) == 2);
  const long long stated = stated_log_bytes(err, dir / "small" / "out" / "run.lcm");
  CHECK(stated > (1 << 20));
  const std::regex refusal("excavator-sim: the log [^ ]*small/out/run\\.lcm needs about [0-9.]+ MB \\(" + std::to_string(stated) +
                           " bytes\\) but its file system \\([^)]*small[^)]*\\) has [0-9.]+ (kB|MB) free: shorten the run "
                           "\\(--duration\\), record the per-cycle channels less often \\(--log-every N\\) or write the log "
                           "to another disk");
  CHECK(std::regex_search(err, refusal));
  CHECK(err.find(" with pid") == std::string::npos);  // no run started
  CHECK(read_text_file(dir / "whole.files").find("run.lcm") == std::string::npos);
  // The same run recording the per-cycle channels every 50th cycle fits, and its statement holds.
  run_small(dig_run + " --log-every 50 --no-report --quiet", "thinned");
  const std::string thinned_err = read_text_file(dir / "thinned.err");
  INFO(thinned_err);
  CHECK(std::atoi(read_text_file(dir / "thinned.status").c_str()) == 0);
  const long long written = std::atoll(read_text_file(dir / "thinned.size").c_str());
  const long long thinned_stated = stated_log_bytes(thinned_err, dir / "small" / "out" / "run.lcm");
  CHECK(written > 0);
  CHECK(written < (1 << 20));
  CHECK(std::abs(thinned_stated - written) <= written / 100);
  // paper's three scenes for 0.3 s: each log would fit alone (0.6 to 0.9 MB), the three together do
  // not; all are sized before the first runs.
  const std::string scenes = std::string(EXC_SOURCE_DIR) + "/scenes/";
  run_small("paper --duration 0.3 --out small/paper --free-motion " + scenes + "paper_free_motion.yaml --dig " + scenes +
                "paper_dig.yaml --hydraulic-dig " + kDig,
            "paper");
  const std::string paper_err = read_text_file(dir / "paper.err");
  INFO(paper_err);
  CHECK(std::atoi(read_text_file(dir / "paper.status").c_str()) == 2);
  long long each_max = 0;
  for (const char* scene : {"free_motion", "dig", "hydraulic_dig"}) {
    const long long bytes = stated_log_bytes(paper_err, dir / "small" / "paper" / scene / "run.lcm");
    CHECK(bytes > 0);
    each_max = std::max(each_max, bytes);
  }
  CHECK(each_max < (1 << 20));
  CHECK(std::regex_search(paper_err, std::regex("the logs [^ ]*free_motion/run\\.lcm, [^ ]*dig/run\\.lcm, "
                                                "[^ ]*hydraulic_dig/run\\.lcm need about [0-9.]+ MB")));
  CHECK(paper_err.find(" with ") == std::string::npos);  // no scene ran
}
