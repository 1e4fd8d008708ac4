#pragma once
// excavator-sim as a user runs it, for the tests/sim cases: a run in a directory of its own (its exit
// status, stdout and stderr) and the shipped dig scene with edits.
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "scratch_files.hpp"
#include "text_file.hpp"

namespace exc::test {

namespace fs = std::filesystem;

struct Run {
  int status = -1;
  std::string out, err;
  fs::path dir;
};

// Runs excavator-sim with 'args' in a fresh directory of its own (test cases run in parallel),
// removed when the test process passes.
inline Run run_sim(const std::string& args) {
  static int call = 0;
  Run r;
  r.dir = scratch_dir(fs::path(EXC_BINARY_DIR) / "tests" / "sim" / ("run_" + std::to_string(getpid()) + "_" + std::to_string(call++)));
  const std::string cmd = "cd '" + r.dir.string() + "' && " + EXC_SIM_TOOL + " " + args + " > out.txt 2> err.txt";
  const int raw = std::system(cmd.c_str());
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = read_text_file(r.dir / "out.txt");
  r.err = read_text_file(r.dir / "err.txt");
  return r;
}

// The shipped dig: the hydraulic machine through its valves; and the paper's force-actuated one.
inline const std::string kDig = std::string(EXC_SOURCE_DIR) + "/scenes/dig.yaml";
inline const std::string kPaperDig = std::string(EXC_SOURCE_DIR) + "/scenes/paper_dig.yaml";

// A shipped scene with edits (each must apply exactly once), written next to the test's runs under a
// name of this process (a scratch file); returns its path.
inline fs::path edited_scene(const std::string& scene, const std::vector<std::pair<std::string, std::string>>& edits,
                             const std::string& stem) {
  std::string text = read_text_file(scene);
  for (const auto& [from, to] : edits) {
    const auto pos = text.find(from);
    REQUIRE_MESSAGE(pos != std::string::npos, from);
    REQUIRE(text.find(from, pos + 1) == std::string::npos);
    text.replace(pos, from.size(), to);
  }
  const fs::path path = scratch_file(fs::path(EXC_BINARY_DIR) / "tests" / "sim" / (stem + "_" + std::to_string(getpid()) + ".yaml"));
  std::ofstream(path) << text;
  return path;
}

inline fs::path edited_dig(const std::vector<std::pair<std::string, std::string>>& edits, const std::string& stem) {
  return edited_scene(kDig, edits, stem);
}

inline fs::path edited_dig(const std::string& from, const std::string& to, const std::string& stem) {
  return edited_dig({{from, to}}, stem);
}

// The data rows of a CSV file (its lines but the header).
inline long csv_data_rows(const fs::path& csv) {
  std::ifstream in(csv);
  std::string line;
  long rows = -1;  // the header
  while (std::getline(in, line)) ++rows;
  return rows;
}

}  // namespace exc::test
