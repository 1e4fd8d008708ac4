#pragma once
// The whole content of a file as a string (empty if it cannot be read): for tests that compare
// outputs, edit shipped files or parse what a program wrote.
#include <fstream>
#include <sstream>
#include <string>

namespace exc::test {

inline std::string read_text_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace exc::test
