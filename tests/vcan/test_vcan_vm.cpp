// vcan-vm end to end: options, output and exit status passed back, frames on a real vcan0 (raw
// sockets and a candump -L capture), the HAL's SocketCAN test run for real, timeout, missing
// package. On this project's machines each run boots a QEMU VM; on a host with vcan it runs there.
// Nothing here depends on how fast the VM is: waits end on events, timeouts only catch hangs.
#include <doctest/doctest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "candump_log.hpp"
#include "text_file.hpp"

namespace fs = std::filesystem;

using exc::test::read_text_file;

namespace {

const std::string kVcanVm = EXC_BINARY_DIR "/tools/vcan-vm";

struct RunResult {
  int status = -1;  // exit status, or -1 if the shell did not exit normally
  std::string out, err;
};


std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// A fresh directory under the build tree that the VM gets read-write (--share).
fs::path make_work_dir(const std::string& name) {
  const fs::path dir = fs::path(EXC_BINARY_DIR) / "tests" / "vcan" / "work" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// Runs `command` under /bin/sh with stdout and stderr captured apart.
RunResult run(const std::string& command, const fs::path& dir) {
  const fs::path out = dir / "run.stdout", err = dir / "run.stderr";
  const std::string line = "(" + command + ") >" + quote(out.string()) + " 2>" + quote(err.string()) + " </dev/null";
  const int raw = std::system(line.c_str());
  RunResult r;
  r.status = (raw != -1 && WIFEXITED(raw)) ? WEXITSTATUS(raw) : -1;
  r.out = read_text_file(out);
  r.err = read_text_file(err);
  return r;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

}  // namespace

TEST_CASE("vcan/vcan-vm rejects bad options, naming the option and its range") {
  const fs::path dir = make_work_dir("options");
  RunResult help = run(kVcanVm + " --help", dir);
  CHECK(help.status == 0);
  CHECK(help.out.find("Usage: vcan-vm") != std::string::npos);
  CHECK(help.out.find("--share DIR") != std::string::npos);

  struct Bad {
    const char* args;
    const char* says;
  };
  for (const Bad& bad : {Bad{"--timeout 0 -- true", "--timeout '0': must be whole seconds in 1..86400"},
                         Bad{"--timeout 1.5 -- true", "--timeout '1.5'"},
                         Bad{"--memory 64 -- true", "--memory '64': must be MiB in 128..16384"},
                         Bad{"--cpus 0 -- true", "--cpus '0': must be in 1..16"},
                         Bad{"--accel xen -- true", "--accel 'xen': must be tcg or kvm"},
                         Bad{"--share /nonexistent/dir -- true", "--share '/nonexistent/dir': not an existing directory"},
                         Bad{"--frobnicate -- true", "unknown option '--frobnicate'"},
                         Bad{"--timeout", "option --timeout needs a value"},
                         Bad{"", "no command given"}}) {
    CAPTURE(bad.args);
    RunResult r = run(kVcanVm + " " + bad.args, dir);
    CHECK(r.status == 2);
    CHECK(r.err.find(bad.says) != std::string::npos);
    CHECK(r.out.empty());
  }
}

// One VM boot for everything that needs a running vcan0 (each boot costs 12-40 s of CI time).
TEST_CASE("vcan/vcan-vm passes output and status and directory and environment and its vcan0 carries frames and the HAL test") {
  const fs::path dir = make_work_dir("one_vm");
  // Edge IDs and lengths: classical 0..8 bytes, 11-bit extremes, one 29-bit ID; CAN FD with and
  // without the bit-rate switch at 0, 12 and 64 bytes, and the protocol's 48-byte sensor frame.
  std::string fd64 = "7FF##1", fd48 = "180##1";
  for (int i = 0; i < 64; ++i) fd64 += "0123456789ABCDEF"[i % 16] + std::string(1, "FEDCBA9876543210"[i % 16]);
  for (int i = 0; i < 48; ++i) fd48 += i % 2 ? "5A" : "C3";
  const std::vector<std::string> sent = {"123#DEADBEEF", "000#",           "7FF#0102030405060708",
                                         "080#00",       "1ABCDEF0#11",    "456#A1B2C3",
                                         "001#FFFFFFFFFFFFFFFF", "7FE#0A0B0C0D0E", "234#1122",
                                         "080##1",       "103##0112233445566778899AABBCC", fd48, fd64};
  std::string frames;
  for (const std::string& f : sent) frames += " " + f;
  // candump is started first; the probe sends only once the kernel lists candump's receiver on
  // vcan0 (so no frame can be missed whatever the VM's speed), and candump stops after the count.
  const std::string receivers = "cat /proc/net/can/rcvlist_* | grep -c -E '^ +vcan0 +[0-9A-Fa-f]'";
  std::string inner =
      "pwd > where.txt; printf %s \"$EXC_VCAN_TEST_VALUE\" > env.txt; ip -o link show dev vcan0 > link.txt; "
      "n0=$(" + receivers + "); candump -L -n " + std::to_string(sent.size()) + " vcan0 > capture.log & c=$!; "
      "while [ \"$(" + receivers + ")\" -le \"$n0\" ]; do sleep 0.05; done; " +
      quote(VCAN_FRAME_PROBE) + " vcan0" + frames + " > probe.out 2> probe.err; echo $? > probe.status; "
      // A probe that failed sent fewer frames than candump waits for: stop candump rather than hang.
      "[ \"$(cat probe.status)\" = 0 ] || kill $c; wait $c; echo $? > candump.status; ";
#ifdef EXC_HAL_TESTS
  inner += quote(EXC_HAL_TESTS) +
           " > hal.out 2>&1; echo $? > hal.status; ";
#endif
  // Last: two lines on stdout (no carriage returns may appear), one on stderr, exit status 3.
  inner += "printf 'out 1\\nout 2\\n'; printf 'err\\n' >&2; exit 3";
  RunResult r = run("cd " + quote(dir.string()) + " && EXC_VCAN_TEST_VALUE=\"a b'c\" " + kVcanVm + " --share " +
                        quote(dir.string()) + " -- sh -c " + quote(inner),
                    dir);

  // Output, status, directory, environment.
  CHECK(r.status == 3);
  CHECK(r.out == "out 1\nout 2\n");
  CHECK(r.err == "err\n");
  CHECK(read_text_file(dir / "where.txt") == dir.string() + "\n");
  CHECK(read_text_file(dir / "env.txt") == "a b'c");
  const std::string link = read_text_file(dir / "link.txt");
  CHECK(link.find("vcan0") != std::string::npos);
  CHECK(link.find("UP") != std::string::npos);
  CHECK(link.find("link/can") != std::string::npos);
  CHECK(link.find("mtu 72") != std::string::npos);  // CANFD_MTU: vcan0 carries CAN FD frames

  // What the probe's second raw socket received, in order.
  INFO("probe stderr: ", read_text_file(dir / "probe.err"));
  CHECK(read_text_file(dir / "probe.status") == "0\n");
  CHECK(lines_of(read_text_file(dir / "probe.out")) == sent);

  // What candump recorded: same frames, same order, on vcan0, with time stamps that do not go back.
  CHECK(read_text_file(dir / "candump.status") == "0\n");
  const std::vector<std::string> captured = lines_of(read_text_file(dir / "capture.log"));
  REQUIRE(captured.size() == sent.size());
  std::int64_t last_ns = 0;
  for (std::size_t i = 0; i < sent.size(); ++i) {
    CAPTURE(captured[i]);
    exc::test::CandumpLine line;
    std::string error;
    REQUIRE_MESSAGE(exc::test::parse_candump_line(captured[i], line, error), error);
    CHECK(line.interface_name == "vcan0");
    CHECK(line.frame.timestamp_ns >= last_ns);
    last_ns = line.frame.timestamp_ns;
    // The frame text after "vcan0 " is candump's own rendering: compare it with what was sent (an
    // FD frame's flags digit without CANFD_FDF, 4, which the kernel adds to every FD frame it
    // delivers), and the parsed fields with the bytes of the sent text.
    std::string rendered = captured[i].substr(captured[i].find(' ', captured[i].find(' ') + 1) + 1);
    const std::size_t flags_at = rendered.find("##");
    if (flags_at != std::string::npos && flags_at + 2 < rendered.size()) {
      const int flags = std::stoi(rendered.substr(flags_at + 2, 1), nullptr, 16);
      rendered[flags_at + 2] = "0123456789ABCDEF"[flags & ~4];
    }
    CHECK(rendered == sent[i]);
    const std::string& s = sent[i];
    const std::size_t hash = s.find('#');
    const bool fd = s.compare(hash, 2, "##") == 0;
    const std::size_t data_at = hash + (fd ? 3 : 1);
    CHECK(line.extended == (hash == 8));
    CHECK(line.frame.fd == fd);
    CHECK(line.frame.brs == (fd && s[hash + 2] == '1'));
    CHECK(line.frame.id == std::stoul(s.substr(0, hash), nullptr, 16));
    CHECK(line.frame.len == (s.size() - data_at) / 2);
    for (std::size_t b = 0; b < line.frame.len; ++b)
      CHECK(line.frame.data[b] == std::stoul(s.substr(data_at + 2 * b, 2), nullptr, 16));
  }

#ifdef EXC_HAL_TESTS
  // The HAL's SocketCAN tests (not host tests: this kernel has no CAN) run for real on the VM's vcan0.
  const std::string hal = read_text_file(dir / "hal.out");
  INFO("hal test output: ", hal);
  CHECK(read_text_file(dir / "hal.status") == "0\n");
  CHECK(hal.find("SKIPPED") == std::string::npos);
  CHECK(std::regex_search(hal, std::regex("test cases: +3 \\| +3 passed \\| +0 failed")));
#endif
}

TEST_CASE("vcan/vcan-vm stops a command at the timeout and reports it") {
  const fs::path dir = make_work_dir("timeout");
  const auto start = std::chrono::steady_clock::now();
  RunResult r = run(kVcanVm + " --timeout 5 -- sleep 1000", dir);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  CHECK(r.status == 124);
  CHECK(r.err.find("timed out after 5 s") != std::string::npos);
  CHECK(seconds < 120.0);  // generous: the kill comes at 5 s, a grace of 5 s more, then clean-up
}

TEST_CASE("vcan/vcan-vm names the Debian package when QEMU is missing") {
  const fs::path dir = make_work_dir("missing");
  // A PATH with everything of /usr/bin and /usr/sbin but QEMU.
  const fs::path bin = dir / "bin";
  fs::create_directories(bin);
  for (const char* from : {"/usr/bin", "/usr/sbin"}) {
    for (const auto& entry : fs::directory_iterator(from)) {
      const std::string name = entry.path().filename().string();
      if (name.rfind("qemu-system", 0) == 0 || fs::exists(bin / name)) continue;
      fs::create_symlink(entry.path(), bin / name);
    }
  }
  RunResult r = run("PATH=" + quote(bin.string()) + " " + kVcanVm + " --vm -- true", dir);
  CHECK(r.status == 125);
  CHECK(r.err.find("qemu-system-x86_64") != std::string::npos);
  CHECK(r.err.find("Debian package qemu-system-x86") != std::string::npos);
}

TEST_CASE("vcan/vcan-vm removes the run directories that killed runs left, and keeps a live run's and a just-made one's") {
  // A SIGKILL (ctest's timeout) runs no trap: the run directory stayed in TMPDIR. Each run names its
  // owner (pid and start time); the next run removes a directory whose owner is gone.
  const fs::path dir = make_work_dir("stale");
  const fs::path tmp = dir / "tmp";
  fs::create_directories(tmp);
  // This process's start time (field 22 of /proc/self/stat, counted after the name's ')').
  const std::string stat = read_text_file("/proc/self/stat");
  std::istringstream fields(stat.substr(stat.rfind(')') + 2));
  std::string field, started;
  for (int i = 3; i <= 22 && fields >> field; ++i) started = field;
  REQUIRE(!started.empty());
  const std::string self = std::to_string(getpid());
  const auto make = [&](const std::string& name, const std::string& owner) {
    const fs::path d = tmp / ("exc-vcan-vm-run." + name);
    fs::create_directories(d / "out");
    if (!owner.empty()) std::ofstream(d / "owner") << owner << "\n";
    return d;
  };
  const fs::path gone = make("gone", "4194305 12345");         // above any pid_max: no such process
  const fs::path reused = make("reused", self + " 1");         // a live pid, but not the process that made it
  const fs::path live = make("live", self + " " + started);    // this process: a run still going
  const fs::path old_unowned = make("old", "");                // no owner file, two hours old
  fs::last_write_time(old_unowned, fs::file_time_type::clock::now() - std::chrono::hours(2));
  const fs::path new_unowned = make("new", "");                // no owner file yet: a run being set up
  const fs::path unreadable = make("torn", "4194305");         // an owner line without its start time: left alone
  // --host fails at once on a host without vcan (125) and runs `true` on one with it (0): either way
  // no VM boots, and the clean-up has run.
  RunResult r = run("TMPDIR=" + quote(tmp.string()) + " " + kVcanVm + " --host --verbose -- true", dir);
  INFO(r.err);
  CHECK((r.status == 0 || r.status == 125));
  CHECK_FALSE(fs::exists(gone));
  CHECK_FALSE(fs::exists(reused));
  CHECK_FALSE(fs::exists(old_unowned));
  CHECK(fs::exists(live / "owner"));
  CHECK(fs::exists(new_unowned / "out"));
  CHECK(fs::exists(unreadable / "owner"));
  CHECK(r.err.find("removed " + gone.string() + ", left by a run that was killed") != std::string::npos);
}
