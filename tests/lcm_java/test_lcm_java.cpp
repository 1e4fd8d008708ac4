// Our LCM types as the Java side of LCM sees them: the classes lcm-gen --java made of lcmtypes/*.lcm
// (<build>/lcmtypes/exlcm.jar) decode a run's log through LCM's own Java log reader, channel for
// channel as many events as the C++ side wrote; and lcm-spy, started under Xvfb as the README says,
// shows every channel of a live excavator-sim run over udpm decoded, every type found.
#include <doctest/doctest.h>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <iterator>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "log_channels.hpp"
#include "sim_runs.hpp"
#include "telemetry/telemetry_channels.hpp"

extern char** environ;

namespace fs = std::filesystem;
using exc::test::kDig;
using exc::test::kPerCycleChannels;
using exc::test::read_text_file;
using exc::test::Run;
using exc::test::run_sim;

namespace {

// A channel as one reader counted it.
struct Counted {
  std::string type;
  long long events = 0, undecodable = 0;
  long long first_seq = -1, last_seq = -1, seq_gaps = 0, first_utime = -1, last_utime = -1;
};

// Every type lcmtypes/ defines (the .lcm files' names).
std::set<std::string> defined_types() {
  std::set<std::string> types;
  for (const auto& entry : fs::directory_iterator(fs::path(EXC_SOURCE_DIR) / "lcmtypes"))
    if (entry.path().extension() == ".lcm") types.insert(entry.path().stem().string());
  return types;
}

// Every channel a run of `controller` publishes: the base names with its suffix.
std::vector<std::string> channels_of(const std::string& controller) {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < exc::telemetry::channel_count; ++i)
    names.push_back(std::string(exc::telemetry::channel_base_name(static_cast<exc::telemetry::Channel>(i))) + "/" + controller);
  return names;
}

std::string java_classpath() { return std::string(EXC_LCM_JAR) + ":" + EXC_LCMTYPES_JAR + ":" + EXC_LCM_JAVA_CHECKS_JAR; }

// LogChannelCount's table (tests/lcm_java/LogChannelCount.java).
std::map<std::string, Counted> java_counts(const fs::path& log, const fs::path& dir) {
  const std::string cmd = std::string(EXC_JAVA) + " -cp " + java_classpath() + " LogChannelCount " + EXC_LCMTYPES_JAR +
                          " '" + log.string() + "' > '" + (dir / "java.txt").string() + "' 2> '" +
                          (dir / "java_err.txt").string() + "'";
  const int status = std::system(cmd.c_str());
  INFO(read_text_file(dir / "java_err.txt"));
  REQUIRE(WIFEXITED(status));
  REQUIRE(WEXITSTATUS(status) == 0);
  std::map<std::string, Counted> counts;
  std::istringstream lines(read_text_file(dir / "java.txt"));
  for (std::string line; std::getline(lines, line);) {
    std::istringstream fields(line);
    std::string channel;
    Counted c;
    REQUIRE_MESSAGE(std::getline(fields, channel, '\t'), line);
    REQUIRE_MESSAGE((fields >> c.type >> c.events >> c.undecodable >> c.first_seq >> c.last_seq >> c.seq_gaps >>
                     c.first_utime >> c.last_utime), line);
    counts[channel] = c;
  }
  return counts;
}

// excavator-log info's table: channel, type, messages, rate, undecodable.
std::map<std::string, Counted> excavator_log_counts(const fs::path& log, const fs::path& dir) {
  const std::string cmd = std::string(EXC_LOG_TOOL) + " info '" + log.string() + "' > '" + (dir / "info.txt").string() + "'";
  REQUIRE(std::system(cmd.c_str()) == 0);
  std::map<std::string, Counted> counts;
  std::istringstream lines(read_text_file(dir / "info.txt"));
  std::string line;
  std::getline(lines, line);  // the log's line
  std::getline(lines, line);  // the header
  REQUIRE(line.rfind("channel", 0) == 0);
  while (std::getline(lines, line)) {
    std::istringstream fields(line);
    std::string channel, rate;
    Counted c;
    REQUIRE_MESSAGE((fields >> channel >> c.type >> c.events >> rate >> c.undecodable), line);
    counts[channel] = c;
  }
  return counts;
}

// A child process, ended (SIGTERM, then waited for) when the test leaves, however it leaves.
struct Child {
  pid_t pid = -1;
  ~Child() { stop(); }
  void stop() {
    if (pid <= 0) return;
    kill(pid, SIGTERM);
    int status = 0;
    waitpid(pid, &status, 0);
    pid = -1;
  }
  bool running() {
    if (pid > 0 && waitpid(pid, nullptr, WNOHANG) == pid) pid = -1;  // it ended (and is reaped)
    return pid > 0;
  }
};

// Spawns `argv` with stdout and stderr into `log_file` and `env` as its environment (it inherits this
// process's descriptors that are not close-on-exec).
pid_t spawn(const std::vector<std::string>& argv, const std::vector<std::string>& env, const fs::path& log_file) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  std::vector<char*> args, envp;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  for (const std::string& e : env) envp.push_back(const_cast<char*>(e.c_str()));
  envp.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  return rc == 0 ? pid : -1;
}

// This process's environment with `set` (NAME=value each) put in.
std::vector<std::string> environment_with(const std::vector<std::string>& set) {
  std::vector<std::string> env;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string entry = *e;
    bool replaced = false;
    for (const std::string& s : set) replaced = replaced || entry.substr(0, entry.find('=') + 1) == s.substr(0, s.find('=') + 1);
    if (!replaced) env.push_back(entry);
  }
  env.insert(env.end(), set.begin(), set.end());
  return env;
}

// Waits up to `seconds` for `done` to hold, checking every 200 ms; false when it never did.
template <class Done>
bool wait_for(double seconds, Done done) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  return true;
}

// SpyTableProbe's snapshot of lcm-spy's table (tests/lcm_java/SpyTableProbe.java): channel -> type,
// Num Msgs, Undecodable.
std::map<std::string, Counted> spy_table(const fs::path& file) {
  std::map<std::string, Counted> rows;
  std::istringstream lines(read_text_file(file));
  std::string line;
  if (!std::getline(lines, line) || line != "Channel\tType\tNum Msgs\tUndecodable") return rows;
  while (std::getline(lines, line)) {
    std::istringstream fields(line);
    std::string channel, type, messages, undecodable;
    std::getline(fields, channel, '\t');
    std::getline(fields, type, '\t');
    std::getline(fields, messages, '\t');
    std::getline(fields, undecodable, '\t');
    Counted c;
    c.type = type;
    c.events = std::atoll(messages.c_str());
    c.undecodable = undecodable.empty() ? -1 : std::atoll(undecodable.c_str());
    rows[channel] = c;
  }
  return rows;
}

}  // namespace

TEST_CASE("telemetry/java: LCM's Java log reader with the exlcm jar decodes every event of a run's log, per channel as many as excavator-log counts and the publishers sent, every type") {
  // The hydraulic dig for 1 s with the three controllers it runs: every channel, every type.
  const Run r = run_sim("run " + kDig + " --duration 1 --quiet --no-report --out out");
  INFO(r.err);
  REQUIRE(r.status == 0);
  const fs::path log = r.dir / "out" / "run.lcm";
  const std::map<std::string, Counted> java = java_counts(log, r.dir);
  const std::map<std::string, Counted> cpp = excavator_log_counts(log, r.dir);
  const nlohmann::json summary = nlohmann::json::parse(read_text_file(r.dir / "out" / "summary.json"));
  const std::int64_t cycles = 1000;
  std::set<std::string> java_types;
  for (const std::string controller : {"pid", "adaptive", "flow"}) {
    long long sent = 0;  // what the publisher handed to LCM: every channel but its own counters
    for (const std::string& channel : channels_of(controller)) {
      INFO(channel);
      REQUIRE(java.count(channel) == 1);
      REQUIRE(cpp.count(channel) == 1);
      const Counted& j = java.at(channel);
      const Counted& c = cpp.at(channel);
      CHECK(j.type == c.type);
      CHECK(j.events == c.events);
      CHECK(j.events > 0);
      CHECK(j.undecodable == 0);
      CHECK(c.undecodable == 0);
      // Decoded fields: each channel's seq 0, 1, 2, ... without a gap.
      CHECK(j.first_seq == 0);
      CHECK(j.seq_gaps == 0);
      CHECK(j.last_seq == j.events - 1);
      java_types.insert(j.type);
      const std::string base = channel.substr(0, channel.find('/'));
      if (std::find(std::begin(kPerCycleChannels), std::end(kPerCycleChannels), base) != std::end(kPerCycleChannels)) {
        CHECK(j.events == cycles);  // one per cycle, stamped with its cycle's end
        CHECK(j.first_utime == 1000);
        CHECK(j.last_utime == cycles * 1000);
      }
      if (base != "EXC_TELEMETRY_STATS") sent += j.events;
    }
    CHECK(sent == summary[controller]["telemetry"]["published"].get<long long>());
  }
  CHECK(java.size() == 3 * exc::telemetry::channel_count);  // no channel beyond the three runs' own
  CHECK(java.size() == cpp.size());
  CHECK(java_types == defined_types());
}

TEST_CASE("telemetry/lcm-spy under Xvfb, started as the README says with the exlcm jar, shows every channel of a live excavator-sim run over udpm decoded, every type found") {
  const bool lo_multicast = std::system("ip link show lo 2>/dev/null | grep -q MULTICAST") == 0;
  const bool routed = std::system("ip route get 239.255.76.67 2>/dev/null | grep -q ' dev lo '") == 0;
  REQUIRE_MESSAGE((lo_multicast && routed),
                  "LCM's multicast does not reach the loopback; as root run: ip link set lo multicast on; "
                  "ip route add 239.255.0.0/16 dev lo (tools/install-deps test does)");
  const fs::path dir = exc::test::scratch_dir(fs::path(EXC_BINARY_DIR) / "tests" / "lcm_java" /
                                              ("spy_" + std::to_string(getpid())));
  // A port of this process's own: other tests' and users' LCM traffic stays out.
  const std::string url = "udpm://239.255.76.67:" + std::to_string(18000 + getpid() % 500) + "?ttl=0";

  // The types each channel carries, from a short run into a file as excavator-log reads it.
  const Run reference = run_sim("run " + kDig + " --controller adaptive --duration 0.3 --quiet --no-report --out out");
  REQUIRE(reference.status == 0);
  const std::map<std::string, Counted> expected = excavator_log_counts(reference.dir / "out" / "run.lcm", reference.dir);

  // Xvfb on a display number it picks itself (-displayfd), so that parallel tests do not collide.
  int display_pipe[2];
  REQUIRE(pipe(display_pipe) == 0);
  Child xvfb;
  xvfb.pid = spawn({"Xvfb", "-displayfd", std::to_string(display_pipe[1]), "-nolisten", "tcp", "-screen", "0", "1024x768x24"},
                   environment_with({}), dir / "xvfb.txt");
  close(display_pipe[1]);
  REQUIRE_MESSAGE(xvfb.pid > 0, "cannot start Xvfb (Debian package xvfb; tools/install-deps test installs it)");
  std::string display;
  pollfd readable{display_pipe[0], POLLIN, 0};
  char c = 0;
  while (poll(&readable, 1, 60000) == 1 && read(display_pipe[0], &c, 1) == 1 && c != '\n') display += c;
  close(display_pipe[0]);
  REQUIRE_MESSAGE(!display.empty(), "Xvfb gave no display: " << read_text_file(dir / "xvfb.txt"));

  // lcm-spy as the README starts it (CLASSPATH names the jar; Debian's script passes Java 8's
  // -Xincgc, which Java 17 refuses unless told to ignore it), with the table probe loaded beside it.
  const fs::path table = dir / "spy-table.txt", spy_out = dir / "spy.txt";
  Child spy;
  spy.pid = spawn({"lcm-spy", "--lcm-url=" + url},
                  environment_with({"DISPLAY=:" + display, std::string("CLASSPATH=") + EXC_LCMTYPES_JAR,
                                    "JDK_JAVA_OPTIONS=-XX:+IgnoreUnrecognizedVMOptions",
                                    "JAVA_TOOL_OPTIONS=-javaagent:" + std::string(EXC_LCM_JAVA_CHECKS_JAR) + "=" + table.string()}),
                  spy_out);
  REQUIRE_MESSAGE(spy.pid > 0, "cannot start lcm-spy (Debian package liblcm-bin)");
  // lcm-spy prints its plugins once it has subscribed: then it hears everything sent after.
  const bool listening = wait_for(120, [&] {
    return (read_text_file(spy_out).find(" plugins") != std::string::npos && fs::exists(table)) || !spy.running();
  });
  const std::string spy_says = read_text_file(spy_out);
  REQUIRE_MESSAGE((listening && spy.running()), "lcm-spy did not come up: " << spy_says);
  // It found every type in the jar on CLASSPATH (and nothing else).
  CHECK(spy_says.find("Found " + std::to_string(defined_types().size()) + " LCM types") != std::string::npos);

  const Run live = run_sim("run " + kDig + " --controller adaptive --duration 2 --quiet --no-report --lcm '" + url + "'");
  INFO(live.err);
  REQUIRE(live.status == 0);
  // No log file here: the run says what a logger of it would write.
  CHECK(live.err.find("excavator-sim: telemetry to " + url + " (no log file here); logged, it takes about ") != std::string::npos);
  // Every channel the run sent, shown with its type: waited for generously (lcm-spy counts as it
  // receives; a loaded machine only makes that later).
  const auto complete = [&] {
    const std::map<std::string, Counted> rows = spy_table(table);
    for (const std::string& channel : channels_of("adaptive"))
      if (rows.count(channel) == 0 || rows.at(channel).events == 0 || rows.at(channel).type.rfind("??", 0) == 0) return false;
    return true;
  };
  const bool shown = wait_for(120, complete);
  const std::map<std::string, Counted> rows = spy_table(table);
  INFO("lcm-spy's table:\n" << read_text_file(table));
  CHECK(shown);
  std::set<std::string> types;
  for (const std::string& channel : channels_of("adaptive")) {
    INFO(channel);
    REQUIRE(rows.count(channel) == 1);
    REQUIRE(expected.count(channel) == 1);
    CHECK(rows.at(channel).type == expected.at(channel).type);  // lcm-spy shows the class's name
    CHECK(rows.at(channel).events > 0);
    types.insert(rows.at(channel).type);
  }
  for (const auto& [channel, row] : rows) {
    INFO(channel);
    CHECK(row.undecodable == 0);        // each message decoded by its class
    CHECK(row.type.rfind("??", 0) != 0);  // no channel of unknown type
  }
  CHECK(types == defined_types());
  spy.stop();
  xvfb.stop();
}
