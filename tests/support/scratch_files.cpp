#include "scratch_files.hpp"

#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <string>
#include <vector>

namespace exc::test {

namespace fs = std::filesystem;

namespace {
std::mutex g_mutex;  // a case may run its tools from threads
std::vector<fs::path>& registered() {
  static std::vector<fs::path> paths;
  return paths;
}
void add(const fs::path& path) {
  const std::lock_guard<std::mutex> lock(g_mutex);
  registered().push_back(path);
}
}  // namespace

fs::path scratch_dir(const fs::path& dir) {
  fs::remove_all(dir);
  fs::create_directories(dir);
  add(dir);
  return dir;
}

fs::path scratch_file(const fs::path& file) {
  if (file.has_parent_path()) fs::create_directories(file.parent_path());
  add(file);
  return file;
}

void finish_scratch_files(bool passed) {
  const std::lock_guard<std::mutex> lock(g_mutex);
  const char* keep = std::getenv("EXC_KEEP_TEST_FILES");
  const bool remove = passed && !(keep != nullptr && std::string(keep) == "1");
  for (const fs::path& path : registered()) {
    std::error_code ec;
    if (remove)
      fs::remove_all(path, ec);
    else if (!passed && fs::exists(path, ec))
      std::fprintf(stderr, "kept for inspection: %s\n", path.c_str());
  }
  registered().clear();
}

}  // namespace exc::test
