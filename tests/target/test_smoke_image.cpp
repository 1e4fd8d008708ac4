// The smoke image (target/cortex_m7/smoke_main.cpp) on QEMU's emulated Cortex-M7 through the host's
// harness (harness/emulated_target): its double arithmetic against the host's, the instruction
// clock, the heap counter, the stack's high-water mark, 1000 echo rounds of the link, and the errors
// for a target that exits, faults or stops answering. Each case starts its own QEMU (0.2-0.5 s).
//
// Timeouts: generous (60 s a wait) for what must happen; a short one only where the test has made
// sure the target will never answer, so no result depends on this machine's speed.
#include <doctest/doctest.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "harness/emulated_target.hpp"
#include "harness/image_footprint.hpp"
#include "smoke_records.hpp"

using exc::sim::EmulatedTarget;
using exc::sim::EmulatedTargetError;
using exc::sim::EmulatedTargetOptions;
using exc::sim::TargetRecord;
namespace smoke = exc::target::smoke;

namespace {

constexpr double kGenerousTimeout = 60;  // s: a hang's net, not a speed test

EmulatedTargetOptions smoke_options(std::vector<std::string> arguments) {
  EmulatedTargetOptions o;
  o.image = EXC_TARGET_SMOKE_IMAGE;
  o.arguments = std::move(arguments);
  o.timeout_s = kGenerousTimeout;
  o.qemu = EXC_QEMU_SYSTEM_ARM;
  return o;
}

// The console's lines, split into words, by their first word (a key may come more than once).
std::multimap<std::string, std::vector<std::string>> lines_of(const std::string& text) {
  std::multimap<std::string, std::vector<std::string>> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    std::istringstream words(line);
    std::vector<std::string> w;
    for (std::string word; words >> word;) w.push_back(word);
    if (!w.empty()) lines.emplace(w[0], w);
  }
  return lines;
}

const std::vector<std::string>& line(const std::multimap<std::string, std::vector<std::string>>& lines,
                                     const std::string& key) {
  const auto it = lines.find(key);
  if (it == lines.end()) FAIL("the smoke image printed no '" << key << "' line");
  return it->second;
}

// "key a 1 b 2": the number after word `name`.
unsigned long long field(const std::vector<std::string>& words, const std::string& name) {
  for (std::size_t i = 0; i + 1 < words.size(); ++i) {
    if (words[i] == name) return std::strtoull(words[i + 1].c_str(), nullptr, 10);
  }
  FAIL("no field '" << name << "' in the line '" << words[0] << " ...'");
  return 0;
}

// Runs the smoke image without the link to its end; its stdout.
std::string run_to_exit(std::vector<std::string> arguments, int expected_status = 0) {
  EmulatedTarget target(smoke_options(std::move(arguments)));
  const int status = target.wait_for_exit();
  INFO("stderr: " << target.printed_stderr());
  CHECK(status == expected_status);
  return target.printed_stdout();
}

std::string run_tool(const std::string& command) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  REQUIRE(pipe != nullptr);
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) out.append(buffer, n);
  REQUIRE(pclose(pipe) == 0);
  return out;
}

// The units in the last place between two doubles of the same sign.
long long ulps_apart(double a, double b) {
  long long ia, ib;
  std::memcpy(&ia, &a, sizeof a);
  std::memcpy(&ib, &b, sizeof b);
  return ia > ib ? ia - ib : ib - ia;
}

std::vector<TargetRecord> random_batch(std::mt19937& rng, long round) {
  std::vector<TargetRecord> batch(1 + round % 4);
  for (auto& r : batch) {
    r.type = static_cast<std::uint8_t>(rng() % smoke::kEchoEndRecord);  // any type but the end's
    const std::size_t size = rng() % 8 == 0 ? rng() % 1500 : rng() % 80;
    r.payload.resize(size);
    for (auto& b : r.payload) b = static_cast<std::uint8_t>(rng());
  }
  const auto r32 = static_cast<std::uint32_t>(round);
  batch.push_back({smoke::kEchoEndRecord, {std::uint8_t(r32), std::uint8_t(r32 >> 8), std::uint8_t(r32 >> 16),
                                           std::uint8_t(r32 >> 24)}});
  return batch;
}

void send_batch(EmulatedTarget& target, const std::vector<TargetRecord>& batch) {
  for (const auto& r : batch) target.send(r.type, r.payload);
  target.flush();
}

}  // namespace

TEST_CASE("firmware/target: the smoke image runs on the emulated Cortex-M7, and its LDLT solve and atan2 agree with the host's to 4 ulp") {
  const auto lines = lines_of(run_to_exit({}));
  // The same computation on the host (smoke_main.cpp's compute(), with its scale at 1).
  Eigen::Matrix4d a;
  a << 4.0, 1.0, 0.5, 0.25, 1.0, 3.0, 0.75, 0.125, 0.5, 0.75, 2.5, 0.3, 0.25, 0.125, 0.3, 1.75;
  const Eigen::Vector4d b(1.0, -2.0, 0.5, 3.25);
  const Eigen::Vector4d x = a.ldlt().solve(b);
  const double angle = std::atan2(-0.7, -1.3);

  const auto& solved = line(lines, "ldlt_x");
  REQUIRE(solved.size() == 5);
  // Printed with %.17g, so the text holds every bit. The tolerance: newlib's atan2 is not glibc's,
  // and a compiler may fuse a multiply and an add on one end and not on the other; 4 ulp is far below
  // any difference that would matter to the loop (GCC 12 at -O2 on both ends: 0 ulp, bit for bit).
  long long worst = 0;
  for (int i = 0; i < 4; ++i) {
    const double t = std::strtod(solved[i + 1].c_str(), nullptr);
    CAPTURE(i);
    CAPTURE(t);
    CAPTURE(x[i]);
    CHECK(ulps_apart(t, x[i]) <= 4);
    worst = std::max(worst, ulps_apart(t, x[i]));
  }
  const double t_angle = std::strtod(line(lines, "atan2").at(1).c_str(), nullptr);
  CAPTURE(t_angle);
  CAPTURE(angle);
  CHECK(ulps_apart(t_angle, angle) <= 4);
  MESSAGE("target against host: LDLT solution within " << worst << " ulp, atan2 within "
                                                       << ulps_apart(t_angle, angle) << " ulp");
  // The residual on the host of the target's solution: it solves the system.
  Eigen::Vector4d xt;
  for (int i = 0; i < 4; ++i) xt[i] = std::strtod(solved[i + 1].c_str(), nullptr);
  CHECK((a * xt - b).norm() < 1e-14);
  // The start-up set flush-to-zero, and the computation repeated after start-up gave the same bits.
  CHECK(line(lines, "fpscr_fz").at(1) == "1");
  CHECK(line(lines, "compute_repeat_equal").at(1) == "1");
}

TEST_CASE("firmware/target: the known loop reads 2 instructions per iteration to the clock's 40-instruction resolution, the same in two runs, and the clock is monotonic across SysTick wraps") {
  // The loop is what the count assumes: subs, bne, then bx.
  const std::string disassembly =
      run_tool(std::string(EXC_ARM_OBJDUMP) + " -d --disassemble=exc_smoke_known_loop " + EXC_TARGET_SMOKE_IMAGE);
  std::vector<std::string> mnemonics;
  const std::regex instruction(R"(^\s+[0-9a-f]+:\s+(?:[0-9a-f]{4}\s?)+\s+(\S+))");
  std::istringstream in(disassembly);
  for (std::string text; std::getline(in, text);) {
    std::smatch m;
    if (std::regex_search(text, m, instruction)) mnemonics.push_back(m[1]);
  }
  CAPTURE(disassembly);
  REQUIRE(mnemonics.size() == 3);
  CHECK(mnemonics[0] == "subs");
  CHECK(mnemonics[1].rfind("bne", 0) == 0);
  CHECK(mnemonics[2] == "bx");

  const std::string first = run_to_exit({});
  const std::string second = run_to_exit({});
  const auto lines = lines_of(first);
  std::vector<unsigned long long> loops;
  for (auto [it, end] = lines.equal_range("known_loop"); it != end; ++it) {
    const auto n = field(it->second, "n"), empty = field(it->second, "empty"), loop = field(it->second, "loop");
    CAPTURE(n);
    CAPTURE(empty);
    CAPTURE(loop);
    CHECK(empty % 40 == 0);
    CHECK(loop % 40 == 0);
    // The section holds the loop (2n), its bx, the call and its argument, and the reading's own
    // instructions, which the empty section holds too: within one tick of 2n.
    const long long beyond = static_cast<long long>(loop) - static_cast<long long>(empty) - 2 * static_cast<long long>(n);
    CHECK(beyond >= -40);
    CHECK(beyond <= 40);
    loops.push_back(loop);
  }
  REQUIRE(loops.size() == 2);
  const long long slope = static_cast<long long>(loops[1]) - static_cast<long long>(loops[0]);
  CHECK(std::llabs(slope - 2000000) <= 40);  // n 2,000,000 against 1,000,000
  MESSAGE("known loop: n 1e6 reads " << loops[0] << " instructions, n 2e6 reads " << loops[1]);

  const auto& wraps = line(lines, "clock_wraps");
  CHECK(field(wraps, "monotonic") == 1);
  CHECK(field(wraps, "periods") >= 20);  // 100,000 readings over at least 20 periods of 40,000 instructions

  // Deterministic: the second run printed the same, every count included.
  CHECK(first == second);
}

TEST_CASE("firmware/target: the smoke image makes no heap call after start-up, counts a malloc, free, new and delete after it, and its stack high-water mark is inside the stack") {
  const auto lines = lines_of(run_to_exit({}));
  const auto& after = line(lines, "heap_calls_after_start_up");
  CHECK(after.at(1) == "0");
  // Start-up did allocate (stdio's buffers, dtoa's numbers): the counter sees newlib's own calls.
  CHECK(field(line(lines, "heap_calls_total"), "heap_calls_total") > 0);
  const auto& stack = line(lines, "stack_high_water");
  const auto used = std::strtoull(stack.at(1).c_str(), nullptr, 10);
  const auto size = field(stack, "of");
  CHECK(used > 64);
  CHECK(used < size);
  MESSAGE("stack high-water " << used << " of " << size << " bytes; heap calls in start-up "
                              << field(line(lines, "heap_calls_total"), "heap_calls_total"));

  const auto allocating = lines_of(run_to_exit({"--allocate-after-start-up"}));
  const auto& counted = line(allocating, "heap_calls_after_start_up");
  CHECK(counted.at(1) == "4");
  CHECK(field(counted, "malloc") == 2);  // malloc and operator new
  CHECK(field(counted, "free") == 2);    // free and operator delete
}

TEST_CASE("firmware/target: 1000 echo rounds of one to four records each come back bit for bit, in order, with no heap call in the target") {
  constexpr long kRounds = 1000;
  EmulatedTarget target(smoke_options({"--rounds", std::to_string(kRounds)}));
  std::mt19937 rng(21);
  std::uint64_t records = 0, bytes = 0;
  auto start = std::chrono::steady_clock::now();
  for (long round = 0; round < kRounds; ++round) {
    if (round == 1) start = std::chrono::steady_clock::now();  // after QEMU's start and the image's own checks
    const auto batch = random_batch(rng, round);
    send_batch(target, batch);
    const auto echoed = target.receive_until(smoke::kEchoEndRecord);
    CAPTURE(round);
    REQUIRE(echoed.size() == batch.size());
    for (std::size_t i = 0; i < batch.size(); ++i) {
      REQUIRE(echoed[i].type == batch[i].type);
      REQUIRE(echoed[i].payload == batch[i].payload);
      if (round > 0) bytes += batch[i].payload.size();
    }
    if (round > 0) records += batch.size();
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  REQUIRE(target.wait_for_exit() == 0);
  const auto lines = lines_of(target.printed_stdout());
  const auto& echo = line(lines, "echo_rounds");
  CHECK(field(echo, "echo_rounds") == kRounds);
  CHECK(field(echo, "records") == target.records_sent());
  CHECK(line(lines, "heap_calls_after_start_up").at(1) == "0");
  MESSAGE("echo: " << records << " records (" << bytes << " payload bytes) there and back in " << seconds
                   << " s wall clock: " << records / seconds << " records/s, " << (kRounds - 1) / seconds
                   << " rounds/s; the target's instructions for all rounds: " << field(echo, "instructions"));
}

TEST_CASE("firmware/target: a target that exits mid-round is an error naming the image, its exit status, what the host waited for and the last record seen") {
  EmulatedTarget target(smoke_options({"--rounds", "5", "--exit-after-records", "6"}));
  std::mt19937 rng(22);
  // Round 0: one record and the end, echoed; round 1: two and the end (5 echoed so far); round 2:
  // three and the end: the image stops once it has echoed 6, mid-round, before flushing any.
  for (long round = 0; round < 2; ++round) {
    send_batch(target, random_batch(rng, round));
    REQUIRE(target.receive_until(smoke::kEchoEndRecord).size() == static_cast<std::size_t>(2 + round));
  }
  send_batch(target, random_batch(rng, 2));
  try {
    target.receive_until(smoke::kEchoEndRecord);
    FAIL("receive_until returned although the target exited");
  } catch (const EmulatedTargetError& e) {
    const std::string message = e.what();
    CAPTURE(message);
    CHECK(message.find(EXC_TARGET_SMOKE_IMAGE) != std::string::npos);
    CHECK(message.find("exited with status " + std::to_string(smoke::kEarlyExit)) != std::string::npos);
    CHECK(message.find("a record of type 0xfe") != std::string::npos);
    CHECK(message.find("last record seen: type 0xfe, 4 bytes, record 5 received") != std::string::npos);
    CHECK(message.find("smoke: exiting after 6 records, as asked") != std::string::npos);
  }
}

TEST_CASE("firmware/target: a target that stops answering is a timeout naming what the host waited for, and QEMU is killed and reaped with its FIFOs removed") {
  pid_t pid = -1;
  std::string folder;
  {
    EmulatedTarget target(smoke_options({"--rounds", "3", "--stall-after-records", "2"}));
    pid = target.qemu_pid();
    folder = target.work_folder();
    std::mt19937 rng(23);
    send_batch(target, random_batch(rng, 0));  // one record and the end: echoed, so the target is up
    REQUIRE(target.receive_until(smoke::kEchoEndRecord).size() == 2);
    // From here the target spins forever: the short timeout only shortens the test.
    target.set_timeout(2);
    send_batch(target, random_batch(rng, 1));
    try {
      target.receive_until(smoke::kEchoEndRecord);
      FAIL("receive_until returned although the target stalled");
    } catch (const EmulatedTargetError& e) {
      const std::string message = e.what();
      CAPTURE(message);
      CHECK(message.find(EXC_TARGET_SMOKE_IMAGE) != std::string::npos);
      CHECK(message.find("timed out after 2") != std::string::npos);
      CHECK(message.find("a record of type 0xfe") != std::string::npos);
      CHECK(message.find("last record seen: type 0xfe, 4 bytes, record 2 received") != std::string::npos);
      CHECK(message.find("smoke: stalling after 2 records, as asked") != std::string::npos);
    }
    CHECK_FALSE(target.exited());
  }
  // No zombie: QEMU was this process's child and is reaped; no folder, no FIFO.
  errno = 0;
  CHECK(waitpid(pid, nullptr, WNOHANG) == -1);
  CHECK(errno == ECHILD);
  struct stat info;
  CHECK(stat(folder.c_str(), &info) != 0);
}

TEST_CASE("firmware/target: a target that faults mid-round is an error naming the fault, its exit status and the last record seen") {
  EmulatedTarget target(smoke_options({"--rounds", "3", "--fault-after-records", "3"}));
  std::mt19937 rng(24);
  send_batch(target, random_batch(rng, 0));
  REQUIRE(target.receive_until(smoke::kEchoEndRecord).size() == 2);
  send_batch(target, random_batch(rng, 1));
  try {
    target.receive_until(smoke::kEchoEndRecord);
    FAIL("receive_until returned although the target faulted");
  } catch (const EmulatedTargetError& e) {
    const std::string message = e.what();
    CAPTURE(message);
    CHECK(message.find("exited with status 125") != std::string::npos);
    CHECK(message.find("fault: HardFault") != std::string::npos);
    CHECK(message.find("last record seen: type 0xfe, 4 bytes, record 2 received") != std::string::npos);
  }
}

TEST_CASE("firmware/target: a missing image, a file that is no image and a missing QEMU are errors naming them") {
  auto o = smoke_options({});
  o.image = "/nonexistent/firmware.elf";
  try {
    EmulatedTarget target(o);
    FAIL("a missing image started");
  } catch (const EmulatedTargetError& e) {
    CHECK(std::string(e.what()).find("/nonexistent/firmware.elf: the image cannot be read") != std::string::npos);
  }
  o = smoke_options({});
  o.qemu = "/nonexistent/qemu-system-arm";
  try {
    EmulatedTarget target(o);
    FAIL("a missing QEMU started");
  } catch (const EmulatedTargetError& e) {
    CHECK(std::string(e.what()).find("'/nonexistent/qemu-system-arm' not found") != std::string::npos);
  }
  o = smoke_options({"two words"});
  CHECK_THROWS_WITH_AS(EmulatedTarget{o}, doctest::Contains("holds white space"), EmulatedTargetError);
  // A file that is no ELF: QEMU loads it as raw bytes and locks up on them; its own message and its
  // end (an abort) are in the error.
  o = smoke_options({});
  o.image = std::string(EXC_SOURCE_DIR) + "/target/cortex_m7/mps2_an500.ld";
  EmulatedTarget target(o);
  try {
    target.receive_until(smoke::kEchoEndRecord);
    FAIL("receive_until returned from a QEMU that could not load its image");
  } catch (const EmulatedTargetError& e) {
    const std::string message = e.what();
    CAPTURE(message);
    CHECK(message.find("mps2_an500.ld") != std::string::npos);
    CHECK(message.find("before it opened the link") != std::string::npos);
    CHECK(message.find("its stderr: 'qemu") != std::string::npos);
  }
}

TEST_CASE("firmware/target: the smoke image holds no pthread symbol, does its double arithmetic in the FPU and fits the board's flash and RAM") {
  const std::string symbols = run_tool(std::string(EXC_ARM_NM) + " -C " + EXC_TARGET_SMOKE_IMAGE);
  REQUIRE(symbols.find("exc_reset_handler") != std::string::npos);  // nm read the image
  CHECK(symbols.find("pthread") == std::string::npos);
  // Hard-float: no soft-float double helpers linked, and the FPU's double instructions present.
  CHECK(symbols.find("__aeabi_dadd") == std::string::npos);
  CHECK(symbols.find("__aeabi_dmul") == std::string::npos);
  CHECK(symbols.find("__aeabi_ddiv") == std::string::npos);
  const std::string code = run_tool(std::string(EXC_ARM_OBJDUMP) + " -d " + EXC_TARGET_SMOKE_IMAGE);
  for (const char* instruction : {"vadd.f64", "vmul.f64", "vdiv.f64", "vfma.f64"}) {
    CAPTURE(instruction);
    CHECK(code.find(instruction) != std::string::npos);
  }

  const auto footprint = exc::sim::read_image_footprint(EXC_TARGET_SMOKE_IMAGE);
  CHECK(footprint.flash_bytes > 10000);
  CHECK(footprint.flash_bytes <= exc::sim::kMps2An500FlashBytes);
  CHECK(footprint.ram_bytes == exc::sim::kMps2An500RamBytes);  // the heap takes what the rest leaves
  CHECK(footprint.stack_bytes == 64 * 1024);
  CHECK(footprint.ram_static_bytes + footprint.heap_bytes + footprint.stack_bytes == footprint.ram_bytes);
  // The same figures as binutils' own reading of the section headers.
  const std::string sizes = run_tool(std::string(EXC_ARM_SIZE) + " -A " + EXC_TARGET_SMOKE_IMAGE);
  for (const auto& s : footprint.sections) {
    CAPTURE(s.name);
    const std::regex row("\\n" + std::regex_replace(s.name, std::regex(R"([.])"), R"(\.)") + R"(\s+(\d+)\s+(\d+))");
    std::smatch m;
    REQUIRE(std::regex_search(sizes, m, row));
    CHECK(std::stoul(m[1]) == s.bytes);
    CHECK(std::stoul(m[2]) == s.address);
  }
  MESSAGE("smoke image: flash " << footprint.flash_bytes << " bytes, RAM " << footprint.ram_static_bytes
                                << " bytes of .data and .bss, heap " << footprint.heap_bytes << ", stack "
                                << footprint.stack_bytes);
  CHECK_THROWS_WITH_AS(exc::sim::read_image_footprint(std::string(EXC_SOURCE_DIR) + "/README.md"),
                       doctest::Contains("README.md: not an ELF file"), std::runtime_error);
}
