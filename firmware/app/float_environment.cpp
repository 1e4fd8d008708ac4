#include "app/float_environment.hpp"

#if defined(__x86_64__)
#include <xmmintrin.h>
#endif

namespace exc::app {
namespace {

#if defined(__x86_64__)
constexpr unsigned kFlushToZero = 1u << 15;      // MXCSR FTZ: tiny results become zero
constexpr unsigned kDenormalsAreZero = 1u << 6;  // MXCSR DAZ: subnormal operands read as zero
constexpr unsigned kUnderflowFlag = 1u << 4;     // MXCSR UE (sticky)
constexpr unsigned kMode = kFlushToZero | kDenormalsAreZero;
#elif defined(__aarch64__)
constexpr unsigned kFlushToZero = 1u << 24;  // FPCR.FZ: tiny results and subnormal operands to zero
constexpr unsigned kUnderflowFlag = 1u << 3;  // FPSR.UFC (sticky)
unsigned read_fpcr() { return __builtin_aarch64_get_fpcr(); }
void write_fpcr(unsigned v) { __builtin_aarch64_set_fpcr(v); }
#endif

}  // namespace

FloatControl set_loop_float_mode(FloatMode mode) {
  FloatControl saved;
#if defined(__x86_64__)
  const unsigned csr = _mm_getcsr();
  saved.bits = csr;
  _mm_setcsr(mode == FloatMode::flush_subnormals ? (csr | kMode) : (csr & ~kMode));
#elif defined(__aarch64__)
  const unsigned fpcr = read_fpcr();
  saved.bits = fpcr;
  write_fpcr(mode == FloatMode::flush_subnormals ? (fpcr | kFlushToZero) : (fpcr & ~kFlushToZero));
#else
  (void)mode;
#endif
  return saved;
}

void restore_float_control(FloatControl saved) {
#if defined(__x86_64__)
  // The control bits only: the sticky flags stay the thread's own.
  const unsigned flags = _mm_getcsr() & 0x3fu;
  _mm_setcsr((static_cast<unsigned>(saved.bits) & ~0x3fu) | flags);
#elif defined(__aarch64__)
  write_fpcr(static_cast<unsigned>(saved.bits));
#else
  (void)saved;
#endif
}

FloatMode float_mode_of_thread() {
#if defined(__x86_64__)
  return (_mm_getcsr() & kMode) == kMode ? FloatMode::flush_subnormals : FloatMode::ieee;
#elif defined(__aarch64__)
  return (read_fpcr() & kFlushToZero) != 0 ? FloatMode::flush_subnormals : FloatMode::ieee;
#else
  return FloatMode::ieee;
#endif
}

bool take_underflow_flag() {
#if defined(__x86_64__)
  const unsigned csr = _mm_getcsr();
  _mm_setcsr(csr & ~kUnderflowFlag);
  return (csr & kUnderflowFlag) != 0;
#elif defined(__aarch64__)
  const unsigned fpsr = __builtin_aarch64_get_fpsr();
  __builtin_aarch64_set_fpsr(fpsr & ~kUnderflowFlag);
  return (fpsr & kUnderflowFlag) != 0;
#else
  return false;
#endif
}

}  // namespace exc::app
