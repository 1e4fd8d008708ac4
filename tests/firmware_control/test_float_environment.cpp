// The loop's floating-point mode (firmware/app/float_environment.hpp, docs/floating-point.md): what
// it does to a tiny result and to a subnormal operand, that a scope gives the caller's mode back,
// that a thread started afterwards runs in it (the telemetry thread relies on that), and the
// subnormal test by bits.
#include <doctest/doctest.h>

#include <cfloat>
#include <cmath>
#include <limits>
#include <string>
#include <thread>

#include "app/float_environment.hpp"
#include "diagnostics/subnormal_scan.hpp"
#include "diagnostics/subnormal_scan.hpp"

using namespace exc::app;
using namespace exc::diagnostics;

namespace {
// Through volatile so the compiler folds nothing: the processor computes each product in the
// calling thread's mode.
double product(double a, double b) {
  volatile double x = a, y = b;
  return x * y;
}
}  // namespace

TEST_CASE("firmware/the loop's float mode flushes tiny results and subnormal operands to zero, ieee keeps them") {
  const double tiny = std::numeric_limits<double>::denorm_min() * 1024;  // subnormal
  REQUIRE(is_subnormal(tiny));
  const FloatControl caller = set_loop_float_mode(FloatMode::ieee);
  CHECK(float_mode_of_thread() == FloatMode::ieee);
  CHECK(is_subnormal(product(DBL_MIN, 0.5)));  // gradual underflow
  CHECK(product(tiny, 2.0) == 2 * 1024 * std::numeric_limits<double>::denorm_min());

  set_loop_float_mode(FloatMode::flush_subnormals);
  CHECK(float_mode_of_thread() == FloatMode::flush_subnormals);
  take_underflow_flag();
  const double flushed = product(DBL_MIN, 0.5);
  CHECK(flushed == 0.0);
  CHECK_FALSE(is_subnormal(flushed));
  CHECK(take_underflow_flag());        // the flush is counted
  CHECK_FALSE(take_underflow_flag());  // and the flag cleared by reading it
  CHECK(product(tiny, 1e300) == 0.0);  // the operand read as zero (DAZ): 1e300 x tiny would be ~5e-18
  CHECK(product(DBL_MIN, 2.0) == 2 * DBL_MIN);  // normal numbers as before
  restore_float_control(caller);
}

TEST_CASE("firmware/a float mode scope gives the caller's mode back, and a thread started in it inherits it") {
  const FloatControl caller = set_loop_float_mode(FloatMode::ieee);
  {
    const LoopFloatModeScope scope;
    CHECK(float_mode_of_thread() == FloatMode::flush_subnormals);
    // The telemetry thread is started by the loop's thread after the mode is set (run_lockstep,
    // excavator-firmware, excavator-plant) and is not set again: Linux copies the FPU state at clone.
    FloatMode in_thread = FloatMode::ieee;
    double thread_product = -1;
    std::thread t([&] {
      in_thread = float_mode_of_thread();
      thread_product = product(DBL_MIN, 0.5);
    });
    t.join();
    CHECK(in_thread == FloatMode::flush_subnormals);
    CHECK(thread_product == 0.0);
  }
  CHECK(float_mode_of_thread() == FloatMode::ieee);
  restore_float_control(caller);
}

TEST_CASE("firmware/is_subnormal tells subnormals by their bits, in either mode") {
  const FloatControl caller = set_loop_float_mode(FloatMode::flush_subnormals);
  const double d = std::numeric_limits<double>::denorm_min();
  CHECK(is_subnormal(d));
  CHECK(is_subnormal(-d));
  CHECK(is_subnormal(std::nextafter(DBL_MIN, 0.0)));  // the largest subnormal
  CHECK_FALSE(is_subnormal(DBL_MIN));
  CHECK_FALSE(is_subnormal(0.0));
  CHECK_FALSE(is_subnormal(-0.0));
  CHECK_FALSE(is_subnormal(std::numeric_limits<double>::infinity()));
  CHECK_FALSE(is_subnormal(std::numeric_limits<double>::quiet_NaN()));
  SubnormalScan scan;
  const double values[] = {1.0, d, 0.0, -3 * d};
  scan.visit("values", values, 4);
  CHECK(scan.scanned() == 4);
  CHECK(scan.found() == 2);
  CHECK(scan.first().index == 1);
  CHECK(std::string(scan.first().name) == "values");
  restore_float_control(caller);
}
