// Instructions per cycle late in a long hold against early in it (subnormal numbers must not slow a held loop): the whole loop (the
// firmware's cycle, the CAN frames, the plant's step) counted by callgrind over 1000 cycles from 11 s
// (the path ends at 10.05 s) and over the last 1000 of a 60 s run, for each law. A cost that grows
// with the run's history (a search over what was logged, an iteration that needs more steps the
// longer the machine stands) fails it. Subnormal numbers do not: they cost the processor time, not
// instructions, and valgrind does not emulate the flush-to-zero mode at all (docs/floating-point.md);
// test_long_hold.cpp looks for them.
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "scratch_files.hpp"
#include "text_file.hpp"

namespace fs = std::filesystem;

namespace {

// The events of each dump in `dir`, by its trigger's name: callgrind writes a dump's total as
// "totals: N" (or "summary: N") and its trigger as "desc: Trigger: Client Request: NAME".
std::map<std::string, double> dumps(const fs::path& dir) {
  std::map<std::string, double> out;
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
    if (e.path().filename().string().rfind("callgrind.out", 0) != 0) continue;
    std::ifstream in(e.path());
    std::string line, name;
    double total = -1;
    while (std::getline(in, line)) {
      const std::string trigger = "desc: Trigger: Client Request: ";
      if (line.rfind(trigger, 0) == 0) name = line.substr(trigger.size());
      if (line.rfind("totals: ", 0) == 0) total = std::stod(line.substr(8));
      if (line.rfind("summary: ", 0) == 0 && total < 0) total = std::stod(line.substr(9));
    }
    if (!name.empty() && total >= 0) out[name] = total;
  }
  return out;
}

void check_hold_instructions(const char* law) {
  const fs::path dir = exc::test::scratch_dir(fs::path(EXC_BINARY_DIR) / "tests" / "plant" /
                                              (std::string("hold_instructions_") + law + "_" + std::to_string(getpid())));
  constexpr int kWindow = 1000;
  const std::string cmd = "valgrind -q --tool=callgrind --instr-atstart=no --callgrind-out-file='" +
                          (dir / "callgrind.out").string() + "' " + EXC_HOLD_WINDOWS + " --controller " + law +
                          " --duration 60 --early 11 --window " + std::to_string(kWindow) + " > '" +
                          (dir / "out.txt").string() + "' 2> '" + (dir / "err.txt").string() + "'";
  const int raw = std::system(cmd.c_str());
  INFO(exc::test::read_text_file(dir / "out.txt"));
  INFO(exc::test::read_text_file(dir / "err.txt"));
  REQUIRE(WIFEXITED(raw));
  REQUIRE(WEXITSTATUS(raw) == 0);  // valgrind is an install step (tools/install-deps test)
  const std::map<std::string, double> d = dumps(dir);
  REQUIRE(d.count("early") == 1);
  REQUIRE(d.count("late") == 1);
  const double early = d.at("early") / kWindow, late = d.at("late") / kWindow;
  MESSAGE(std::string(law), ": ", early, " instructions per cycle from 11 s, ", late, " in the last second of 60 s (",
          late / early, "x)");
  CHECK(early > 1e4);  // the whole loop was counted: firmware, bus and plant
  // Late may be cheaper (the valves settle into position and stay centred); never dearer beyond the
  // windows' 0.1 % of difference in the periodic messages' contents.
  CHECK(late <= early * 1.001);
}

}  // namespace

TEST_CASE("firmware/instructions per cycle late in a 60 s hold do not exceed those early in it, by callgrind (pid)") {
  check_hold_instructions("pid");
}

TEST_CASE("firmware/instructions per cycle late in a 60 s hold do not exceed those early in it, by callgrind (adaptive)") {
  check_hold_instructions("adaptive");
}

TEST_CASE("firmware/instructions per cycle late in a 60 s hold do not exceed those early in it, by callgrind (flow)") {
  check_hold_instructions("flow");
}
