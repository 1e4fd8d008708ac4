// The programs' numeric options: NaN, infinities, values out of range and text that is no number are
// refused with the option's name and its allowed range, as the settings files word it; the bounds
// themselves are accepted. Before these checks "--duration nan" ran the scene's own duration (a
// silent default) and "--repeats 0" crashed the two benches.
#include <doctest/doctest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "model/scene_common.hpp"
#include "option_checks.hpp"
#include "scratch_files.hpp"
#include "text_file.hpp"

namespace fs = std::filesystem;

namespace {

// The message CLI11 gives for `args` on an app with one option checked by `check`; empty when accepted.
std::string parse_error(const CLI::Validator& check, const std::string& value) {
  CLI::App app{"t"};
  std::string held;
  app.add_option("--x", held)->check(check);
  std::vector<std::string> args = {value, "--x"};  // CLI11 takes them in reverse
  try {
    app.parse(args);
  } catch (const CLI::ParseError& e) {
    return e.what();
  }
  return {};
}

struct Exit {
  int status = -1;
  std::string err;
};

Exit run(const std::string& command, const std::string& stdout_to = "out.txt") {
  static const fs::path dir =
      exc::test::scratch_dir(fs::path(EXC_BINARY_DIR) / "tests" / "sim" / ("option_checks_" + std::to_string(getpid())));
  const std::string cmd = "cd '" + dir.string() + "' && " + command + " > " + stdout_to + " 2> err.txt";
  const int raw = std::system(cmd.c_str());
  Exit e;
  e.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  e.err = exc::test::read_text_file(dir / "err.txt");
  return e;
}

}  // namespace

TEST_CASE("tools/option checks refuse nan, inf, out-of-range and non-numbers, naming the range, and accept the bounds") {
  const CLI::Validator duration = exc::cli::number_in(exc::kRunDurationBounds, "s");
  for (const char* bad : {"nan", "NaN", "-nan", "inf", "-inf", "0", "-1", "28800.5", "1e9"}) {
    INFO(bad);
    CHECK(parse_error(duration, bad).find("--x: is " + std::string(bad) + " s; allowed range [0.001, 28800] s") !=
          std::string::npos);
  }
  for (const char* text : {"abc", "", "1s", "0x"}) {
    INFO(text);
    CHECK(parse_error(duration, text).find("is not a number") != std::string::npos);
  }
  for (const char* good : {"0.001", "28800", "10.1", "1e3"}) {
    INFO(good);
    CHECK(parse_error(duration, good).empty());
  }
  const CLI::Validator repeats = exc::cli::count_in(1, 1000);
  CHECK(parse_error(repeats, "0").find("is 0; allowed range [1, 1000]") != std::string::npos);
  CHECK(parse_error(repeats, "1001").find("is 1001; allowed range [1, 1000]") != std::string::npos);
  CHECK(parse_error(repeats, "2.5").find("'2.5' is not a whole number") != std::string::npos);
  CHECK(parse_error(repeats, "99999999999999999999").find("is not a whole number") != std::string::npos);
  CHECK(parse_error(repeats, "1").empty());
  CHECK(parse_error(repeats, "1000").empty());
}

TEST_CASE("tools/every program refuses a NaN or zero count on its numeric options before it runs, exit non-zero") {
  const std::string dig = std::string(EXC_SOURCE_DIR) + "/scenes/dig.yaml";
  struct Case {
    std::string command, message;
  };
  const std::vector<Case> cases = {
      {std::string(EXC_SIM_TOOL) + " run " + dig + " --duration nan", "--duration: is nan s; allowed range [0.001, 28800] s"},
      {std::string(EXC_SIM_TOOL) + " paper --duration -inf", "--duration: is -inf s; allowed range [0.001, 28800] s"},
      {std::string(EXC_FIRMWARE_TOOL) + " --can vcan0 --scene " + dig + " --startup-timeout nan",
       "--startup-timeout: is nan s; allowed range [0.001, 86400] s"},
      {std::string(EXC_PLANT_TOOL) + " --can vcan0 --scene " + dig + " --silence-ms nan",
       "--silence-ms: is nan ms; allowed range [0.01, 600000] ms"},
      {std::string(EXC_PLANT_REPLAY_TOOL) + " --scene " + dig + " --efforts x.csv --duration nan",
       "--duration: is nan s; allowed range [0.001, 28800] s"},
      {std::string(EXC_LOOP_BENCH_TOOL) + " --repeats 0", "--repeats: is 0; allowed range [1, 1000]"},
      {std::string(EXC_PLANT_BENCH_TOOL) + " --repeats 0", "--repeats: is 0; allowed range [1, 1000]"},
  };
  for (const Case& c : cases) {
    INFO(c.command);
    const Exit e = run(c.command);
    CHECK(e.status == 2);  // bad input, as every refused option
    CHECK(e.err.find(c.message) != std::string::npos);
  }
}

TEST_CASE("tools/every program exits 2 with the reason on a bad command line: an unknown option, a value out of CLI11's own range, a missing argument (CLI11's codes are 100-114)") {
  const std::string src = EXC_SOURCE_DIR, dig = src + "/scenes/dig.yaml", python = "/usr/bin/python3 ";
  struct Case {
    std::string command, message;
  };
  std::vector<Case> cases = {
      {std::string(EXC_SIM_TOOL) + " run " + dig + " --no-such-option", "--no-such-option"},
      {std::string(EXC_SIM_TOOL) + " sweep", "spec is required"},
      {std::string(EXC_LOG_TOOL) + " report x.lcm --out r --buckets 5", "--buckets"},  // CLI::Range: 105 before
      {std::string(EXC_LOG_TOOL) + " info", "log is required"},
      {std::string(EXC_FIRMWARE_TOOL) + " --scene " + dig + " --controller lqr", "--controller"},
      {std::string(EXC_PLANT_TOOL) + " --can vcan0 --scene " + dig + " --no-such-option", "--no-such-option"},
      {std::string(EXC_PLANT_REPLAY_TOOL) + " --scene " + dig + " --efforts x.csv --no-such-option", "--no-such-option"},
      {std::string(EXC_LOOP_BENCH_TOOL) + " --repeats many", "--repeats"},
      {std::string(EXC_PLANT_BENCH_TOOL) + " --no-such-option", "--no-such-option"},
      {std::string(EXC_BENCH_TOOL) + " --no-such-option", "--no-such-option"},
      {std::string(EXC_MODEL_TOOL) + " fk --no-such-option", "--no-such-option"},
      {std::string(EXC_PLOT_RUN_DIR) + "/plot-run --no-such-option", "usage: plot-run"},
      {python + src + "/tools/sweep/plot_sweep.py --no-such-option out", "plot_sweep"},
      {python + src + "/tools/excavator_bench/plot_bench.py --no-such-option", "plot_bench"},
      {src + "/tools/sweep/parallel-sweep spec.yaml", "usage: parallel-sweep"},
      {src + "/tools/sweep/sweep-scaling spec.yaml", "usage: sweep-scaling"},
      {src + "/tools/vcan_vm/vcan-vm --no-such-option", "unknown option '--no-such-option'"},
      {src + "/tools/sanitizer-tests leaky", "unknown sanitizer 'leaky'"},
      {src + "/tools/sanitizer-tests address -j0", "-j0: -j takes a whole number 1-99"},
      {src + "/tools/sanitizer-tests address -j two", "-j 'two': a whole number 1-99"},
      {src + "/tools/install-deps everything", "unknown set 'everything'"},
  };
#ifdef EXC_MODEL_BENCH_TOOL
  cases.push_back({std::string(EXC_MODEL_BENCH_TOOL) + " --no-such-option", "--no-such-option"});
#endif
  for (const Case& c : cases) {
    INFO(c.command);
    const Exit e = run(c.command);
    INFO(e.err);
    CHECK(e.status == 2);
    CHECK(e.err.find(c.message) != std::string::npos);
  }
}

TEST_CASE("tools/sanitizer-tests takes its job count as -j 2 and as -j2, the way make and ctest take it") {
  const std::string src = EXC_SOURCE_DIR;
  for (const char* jobs : {"-j 2", "-j2"}) {
    INFO(jobs);
    // --left-out prints what the sanitizer leaves out and exits, after the options are read.
    // Exit 0 from grep only when the list came out (a refused option prints none).
    const Exit e = run(src + "/tools/sanitizer-tests address " + jobs + " --left-out | grep -q callgrind");
    INFO(e.err);
    CHECK(e.status == 0);
  }
}

TEST_CASE("tools/every program's --help names it and says in a sentence what it does, exit 0, and shows no code of its own") {
  const std::string src = EXC_SOURCE_DIR, python = "/usr/bin/python3 ";
  struct Case {
    std::string command, name;
  };
  std::vector<Case> cases = {
      {EXC_SIM_TOOL, "excavator-sim"},
      {EXC_FIRMWARE_TOOL, "excavator-firmware"},
      {EXC_PLANT_TOOL, "excavator-plant"},
      {EXC_OPERATOR_TOOL, "excavator-operator"},
      {EXC_LOG_TOOL, "excavator-log"},
      {EXC_MODEL_TOOL, "excavator-model"},
      {EXC_BENCH_TOOL, "excavator-bench"},
      {EXC_LOOP_BENCH_TOOL, "excavator-loop-bench"},
      {EXC_PLANT_BENCH_TOOL, "excavator-plant-bench"},
      {EXC_PLANT_REPLAY_TOOL, "excavator-plant-replay"},
      {std::string(EXC_PLOT_RUN_DIR) + "/plot-run", "plot-run"},
      {src + "/tools/sweep/parallel-sweep", "parallel-sweep"},
      {src + "/tools/sweep/sweep-scaling", "sweep-scaling"},
      {python + src + "/tools/sweep/plot_sweep.py", "plot_sweep.py"},
      {python + src + "/tools/sweep/plot_generalisation.py", "plot_generalisation.py"},
      {python + src + "/tools/sweep/campaign_tables.py", "campaign_tables.py"},
      {python + src + "/tools/excavator_bench/plot_bench.py", "plot_bench.py"},
      {src + "/tools/report_memory_bench/report-memory-bench", "report-memory-bench"},
      {src + "/tools/vcan_vm/vcan-vm", "vcan-vm"},
      {src + "/tools/sanitizer-tests", "sanitizer-tests"},
      {src + "/tools/install-deps", "install-deps"},
  };
#ifdef EXC_MODEL_BENCH_TOOL
  cases.push_back({EXC_MODEL_BENCH_TOOL, "model-bench"});
#endif
  for (const Case& c : cases) {
    INFO(c.command);
    const Exit e = run(c.command + " --help", "help.txt");
    CHECK(e.status == 0);
    const std::string help = exc::test::read_text_file(fs::path(EXC_BINARY_DIR) / "tests" / "sim" /
                                                       ("option_checks_" + std::to_string(getpid())) / "help.txt");
    INFO(help);
    CHECK(help.find(c.name) != std::string::npos);
    // A sentence: a line of at least eight words that is no option's line and no usage line.
    bool sentence = false;
    std::istringstream lines(help);
    for (std::string line; std::getline(lines, line);) {
      const auto first = line.find_first_not_of(" #");
      if (first == std::string::npos || line[first] == '-' || line.compare(first, 5, "usage") == 0 ||
          line.compare(first, 5, "Usage") == 0)
        continue;
      std::istringstream words(line);
      int n = 0;
      for (std::string w; words >> w;) ++n;
      sentence = sentence || n >= 8;
    }
    CHECK_MESSAGE(sentence, "no sentence saying what it does");
    CHECK(help.find("set -") == std::string::npos);  // a script's help cut from its own lines, one too many
  }
}

TEST_CASE("tools/every program exits non-zero naming standard output when its output cannot be written (a full disk), and 0 with the same command into /dev/null") {
  REQUIRE(fs::exists("/dev/full"));
  const std::string dig = std::string(EXC_SOURCE_DIR) + "/scenes/dig.yaml";
  const std::vector<std::string> commands = {
      std::string(EXC_SIM_TOOL) + " config " + dig,
      std::string(EXC_SIM_TOOL) + " --help",
      std::string(EXC_FIRMWARE_TOOL) + " --print-config --scene " + dig,
      std::string(EXC_PLANT_TOOL) + " --help",
      std::string(EXC_PLANT_REPLAY_TOOL) + " --help",
      std::string(EXC_LOG_TOOL) + " --help",
      std::string(EXC_LOOP_BENCH_TOOL) + " --help",
      std::string(EXC_PLANT_BENCH_TOOL) + " --help",
  };
  for (const std::string& command : commands) {
    INFO(command);
    const Exit lost = run(command, "/dev/full");
    INFO(lost.err);
    CHECK(lost.status > 0);
    CHECK(lost.status < 128);
    CHECK(lost.err.find("standard output: cannot write") != std::string::npos);
    const Exit kept = run(command, "/dev/null");  // the control
    CHECK(kept.status == 0);
  }
}
