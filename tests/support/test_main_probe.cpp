// Cases for the tests' main's own tests (tests/support/CMakeLists.txt): one that asserts and one that
// asserts nothing, which the main must fail; one that writes scratch files.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "scratch_files.hpp"

TEST_CASE("probe/asserts") { CHECK(std::sqrt(4.0) == 2.0); }

TEST_CASE("probe/asserts nothing") {
  const double x = std::sqrt(4.0);
  (void)x;
}

// Writes a file into a scratch directory at $EXC_PROBE_SCRATCH, then fails if $EXC_PROBE_FAIL is set.
TEST_CASE("probe/scratch") {
  const char* dir = std::getenv("EXC_PROBE_SCRATCH");
  REQUIRE(dir != nullptr);
  const std::filesystem::path d = exc::test::scratch_dir(dir);
  std::ofstream(d / "written.txt") << "a case's output\n";
  std::ofstream(exc::test::scratch_file(d.parent_path() / "scratch_file.txt")) << "a loose file\n";
  REQUIRE(std::filesystem::exists(d / "written.txt"));
  CHECK(std::getenv("EXC_PROBE_FAIL") == nullptr);
}
