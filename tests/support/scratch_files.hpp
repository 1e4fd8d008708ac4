#pragma once
// The files a test process writes (runs' logs and summaries, edited scenes, reports). One run of the
// suite left about 1.3 GB of them in the build tree, and each rerun added as much under new process
// ids. A path registered here is removed when the process's run passed, and kept and named on
// stderr when it failed (or always kept with EXC_KEEP_TEST_FILES=1), so a failure can be looked into.
#include <filesystem>

namespace exc::test {

// `dir` emptied (anything left there by an earlier process removed), created and registered.
std::filesystem::path scratch_dir(const std::filesystem::path& dir);

// A file (or directory) the test is about to write, registered; its parent directory is created.
std::filesystem::path scratch_file(const std::filesystem::path& file);

// Called by the tests' main when the run has ended: removes every registered path when `passed`,
// else names those that exist.
void finish_scratch_files(bool passed);

}  // namespace exc::test
