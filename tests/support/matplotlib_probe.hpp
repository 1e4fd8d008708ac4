#pragma once
// Whether Debian's python3 can import matplotlib, which plot-run draws with. tools/install-deps
// installs python3-matplotlib for the tests, so a test that draws figures requires it rather than
// skipping: a missing package is an install step to fix, not a pass.
#include <cstdlib>

namespace exc::test {

inline constexpr const char* kMatplotlibMissing =
    "/usr/bin/python3 cannot import matplotlib: install the Debian package python3-matplotlib (tools/install-deps)";

inline bool matplotlib_available() {
  return std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") == 0;
}

}  // namespace exc::test
