// The smoke image: what the bring-up of the emulated Cortex-M7 proves before the firmware is ported
// onto it (docs/target.md, "The smoke image"). Each result is a console line "key value ...", which
// tests/target reads:
//   ldlt_x, atan2     a 4x4 LDLT solve with fixed-size Eigen and an atan2, in double (%.17g: every bit)
//   fpscr_fz          the flush-to-zero bit the start-up set
//   known_loop        instructions of an empty section and of exc_smoke_known_loop(N), twice
//   clock_wraps       the instruction clock read across many wraps of a short SysTick period
//   echo_rounds       rounds served: each record of a round's batch sent back, the end record last
//   heap_calls_*      calls into the allocator after start-up (the firmware's rule: 0) and in all
//   stack_high_water  bytes of the painted stack ever used
//
//   smoke [--rounds N] [--link-in PATH --link-out PATH] [--allocate-after-start-up]
//         [--exit-after-records K | --stall-after-records K | --fault-after-records K]
//
// The last three misbehave on purpose when K records of the rounds have been echoed, for the host's
// error tests.
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>

#include "heap_calls.hpp"
#include "instruction_clock.hpp"
#include "smoke_records.hpp"
#include "stack_usage.hpp"
#include "target_link.hpp"

// A loop of known length: 2 instructions per iteration (subs, bne), then bx. In assembly so that no
// compiler setting changes it; tests/target reads its disassembly back. n must be at least 1.
extern "C" void exc_smoke_known_loop(std::uint32_t n);
asm(R"(
    .section .text.exc_smoke_known_loop, "ax", %progbits
    .global exc_smoke_known_loop
    .type exc_smoke_known_loop, %function
    .thumb_func
exc_smoke_known_loop:
1:  subs    r0, r0, #1
    bne     1b
    bx      lr
    .size exc_smoke_known_loop, . - exc_smoke_known_loop
)");

namespace {

using namespace exc::target;

struct Options {
  long rounds = 0;
  bool allocate_after_start_up = false;
  long exit_after = -1;
  long stall_after = -1;
  long fault_after = -1;
};

[[noreturn]] void refuse(const char* argument, const char* reason) {
  std::fprintf(stderr, "smoke: %s: %s\n", argument, reason);
  std::exit(smoke::kBadArguments);
}

long count_argument(const char* name, const char* text) {
  char* end = nullptr;
  const long value = std::strtol(text, &end, 10);
  if (end == text || *end != '\0' || value < 0 || value > 100000000) refuse(name, "expects a count 0..100000000");
  return value;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const char* a = argv[i];
    const bool has_value = i + 1 < argc;
    if (std::strcmp(a, "--link-in") == 0 || std::strcmp(a, "--link-out") == 0) {
      if (!has_value) refuse(a, "expects a path");
      ++i;  // TargetLink::open_from_arguments reads it
    } else if (std::strcmp(a, "--rounds") == 0 && has_value) {
      o.rounds = count_argument(a, argv[++i]);
    } else if (std::strcmp(a, "--exit-after-records") == 0 && has_value) {
      o.exit_after = count_argument(a, argv[++i]);
    } else if (std::strcmp(a, "--stall-after-records") == 0 && has_value) {
      o.stall_after = count_argument(a, argv[++i]);
    } else if (std::strcmp(a, "--fault-after-records") == 0 && has_value) {
      o.fault_after = count_argument(a, argv[++i]);
    } else if (std::strcmp(a, "--allocate-after-start-up") == 0) {
      o.allocate_after_start_up = true;
    } else {
      refuse(a, "unknown argument or missing value (--rounds N, --link-in PATH, --link-out PATH, "
                "--allocate-after-start-up, --exit-after-records K, --stall-after-records K, --fault-after-records K)");
    }
  }
  return o;
}

// Inputs through a volatile, so the compiler cannot fold the computation into constants: the target's
// FPU and newlib's libm must compute it. tests/target computes the same on the host.
volatile double g_scale = 1.0;

struct MathResult {
  Eigen::Vector4d x;
  double angle = 0;
};

MathResult compute() {
  const double s = g_scale;
  Eigen::Matrix4d a;
  a << 4.0 * s, 1.0, 0.5, 0.25,  //
      1.0, 3.0 * s, 0.75, 0.125,  //
      0.5, 0.75, 2.5 * s, 0.3,    //
      0.25, 0.125, 0.3, 1.75 * s;
  const Eigen::Vector4d b(1.0 * s, -2.0, 0.5, 3.25);
  MathResult r;
  r.x = a.ldlt().solve(b);
  r.angle = std::atan2(-0.7 * s, -1.3);
  return r;
}

std::uint32_t fpscr() {
  std::uint32_t value;
  asm volatile("vmrs %0, fpscr" : "=r"(value));
  return value;
}

// The instruction clock read across many wraps of a 1000-tick period (40,000 instructions): every
// reading at or after the one before, then the full period back.
void check_clock_wraps() {
  InstructionClock::start(999);
  std::uint64_t previous = InstructionClock::ticks();
  const std::uint64_t first = previous;
  bool monotonic = true;
  for (int i = 0; i < 100000; ++i) {
    const std::uint64_t now = InstructionClock::ticks();
    if (now < previous) monotonic = false;
    previous = now;
  }
  const unsigned long long periods = (previous - first) / 1000;
  InstructionClock::start();
  std::printf("clock_wraps monotonic %d periods %llu\n", monotonic ? 1 : 0, periods);
}

void known_loop_line(std::uint32_t n) {
  const std::uint64_t a = InstructionClock::instructions();
  const std::uint64_t b = InstructionClock::instructions();
  exc_smoke_known_loop(n);
  const std::uint64_t c = InstructionClock::instructions();
  std::printf("known_loop n %lu empty %llu loop %llu\n", static_cast<unsigned long>(n),
              static_cast<unsigned long long>(b - a), static_cast<unsigned long long>(c - b));
}

[[noreturn]] void link_failed(const TargetLink& link, TargetLink::Status status, const char* doing) {
  std::fprintf(stderr, "smoke: link: %s: %s (host errno %d", doing, TargetLink::to_string(status), link.host_errno());
  if (status == TargetLink::Status::decode_error) {
    std::fprintf(stderr, "; %s at byte %llu, found %lu", exc::hal::to_string(link.fault().error),
                 static_cast<unsigned long long>(link.fault().offset), static_cast<unsigned long>(link.fault().found));
  }
  std::fprintf(stderr, ")\n");
  std::exit(smoke::kLinkFailed);
}

// Misbehaves on purpose once `echoed` records have gone back, if asked to.
void misbehave_if_asked(const Options& o, long echoed) {
  if (echoed == o.exit_after) {
    std::fprintf(stderr, "smoke: exiting after %ld records, as asked\n", echoed);
    std::exit(smoke::kEarlyExit);
  }
  if (echoed == o.stall_after) {
    std::fprintf(stderr, "smoke: stalling after %ld records, as asked\n", echoed);
    std::fflush(stderr);
    for (;;) {
    }
  }
  if (echoed == o.fault_after) {
    std::fprintf(stderr, "smoke: faulting after %ld records, as asked\n", echoed);
    std::fflush(stderr);
    asm volatile("udf #0");
  }
}

TargetLink g_link;
// Where --allocate-after-start-up keeps what it allocated, so the compiler keeps the calls.
void* volatile g_allocated = nullptr;

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  if (o.rounds > 0) {
    const auto status = g_link.open_from_arguments(argc, argv);
    if (status != TargetLink::Status::ok) link_failed(g_link, status, "open");
  }

  // Start-up: the results printed in full (printf's first use allocates its buffers).
  const MathResult first = compute();
  std::printf("ldlt_x %.17g %.17g %.17g %.17g\n", first.x[0], first.x[1], first.x[2], first.x[3]);
  std::printf("atan2 %.17g\n", first.angle);
  std::printf("fpscr_fz %lu\n", static_cast<unsigned long>((fpscr() >> 24) & 1));
  std::fflush(stdout);
  mark_start_up_over();

  // The cycle's kind of work from here on: no heap call.
  known_loop_line(1000000);
  known_loop_line(2000000);
  check_clock_wraps();
  const MathResult again = compute();
  const bool same = again.x == first.x && again.angle == first.angle;

  long echoed = 0;
  const std::uint64_t echo_start = InstructionClock::instructions();
  for (long round = 0; round < o.rounds; ++round) {
    auto status = g_link.receive_until(smoke::kEchoEndRecord);
    if (status != TargetLink::Status::ok) link_failed(g_link, status, "receive");
    exc::hal::LinkRecordView record;
    while (g_link.next(record)) {
      misbehave_if_asked(o, echoed);
      status = g_link.send(record.type, record.payload, record.payload_bytes);
      if (status != TargetLink::Status::ok) link_failed(g_link, status, "send");
      ++echoed;
    }
    status = g_link.flush();
    if (status != TargetLink::Status::ok) link_failed(g_link, status, "flush");
  }
  const std::uint64_t echo_instructions = InstructionClock::instructions() - echo_start;

  if (o.allocate_after_start_up) {
    g_allocated = std::malloc(24);
    std::free(g_allocated);
    g_allocated = new int(3);
    delete static_cast<int*>(g_allocated);
  }
  const HeapCallCount after = heap_calls_after_start_up();
  const HeapCallCount total = heap_calls();

  std::printf("compute_repeat_equal %d\n", same ? 1 : 0);
  std::printf("echo_rounds %ld records %ld instructions %llu\n", o.rounds, echoed,
              static_cast<unsigned long long>(echo_instructions));
  std::printf("heap_calls_after_start_up %lu malloc %lu calloc %lu realloc %lu free %lu memalign %lu\n",
              static_cast<unsigned long>(after.total()), static_cast<unsigned long>(after.malloc),
              static_cast<unsigned long>(after.calloc), static_cast<unsigned long>(after.realloc),
              static_cast<unsigned long>(after.free), static_cast<unsigned long>(after.memalign));
  std::printf("heap_calls_total %lu heap_break_bytes %lu of %lu\n", static_cast<unsigned long>(total.total()),
              static_cast<unsigned long>(heap_break_bytes()), static_cast<unsigned long>(heap_capacity_bytes()));
  std::printf("stack_high_water %lu of %lu\n", static_cast<unsigned long>(stack_high_water_bytes()),
              static_cast<unsigned long>(stack_size_bytes()));
  if (!same) {
    std::fprintf(stderr, "smoke: the same computation after start-up gave other results\n");
    return smoke::kSelfCheckFailed;
  }
  return 0;
}
