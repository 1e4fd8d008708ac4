// Cases for the tests' main's own tests (tests/support/CMakeLists.txt): one that asserts and one that
// asserts nothing, which the main must fail.
#include <doctest/doctest.h>

#include <cmath>

TEST_CASE("probe/asserts") { CHECK(std::sqrt(4.0) == 2.0); }

TEST_CASE("probe/asserts nothing") {
  const double x = std::sqrt(4.0);
  (void)x;
}
