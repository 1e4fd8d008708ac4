#include "instruction_clock.hpp"

namespace exc::target {
namespace {

// SysTick (ARMv7-M architecture reference, B3.3) and the interrupt control register's pending bit.
volatile std::uint32_t& reg(std::uintptr_t address) { return *reinterpret_cast<volatile std::uint32_t*>(address); }
constexpr std::uintptr_t kSysTickCtrl = 0xE000E010;     // SYST_CSR
constexpr std::uintptr_t kSysTickReload = 0xE000E014;   // SYST_RVR
constexpr std::uintptr_t kSysTickCurrent = 0xE000E018;  // SYST_CVR
constexpr std::uintptr_t kIcsr = 0xE000ED04;            // ICSR
constexpr std::uint32_t kEnable = 1u << 0, kTickInterrupt = 1u << 1, kProcessorClock = 1u << 2;
constexpr std::uint32_t kPendSysTick = 1u << 26;  // ICSR.PENDSTSET: a wrap not handled yet

// The interrupt counts the counter's 1 -> 0 steps; one period (reload + 1 ticks) later it reloads.
volatile std::uint64_t g_wraps = 0;
std::uint64_t g_period = std::uint64_t{InstructionClock::kFullReload} + 1;
volatile bool g_running = false;

std::uint32_t mask_interrupts() {
  std::uint32_t primask;
  asm volatile("mrs %0, primask\n cpsid i" : "=r"(primask)::"memory");
  return primask;
}
void restore_interrupts(std::uint32_t primask) { asm volatile("msr primask, %0" ::"r"(primask) : "memory"); }

}  // namespace

void InstructionClock::start(std::uint32_t reload) {
  if (reload == 0 || reload > kFullReload) reload = kFullReload;
  reg(kSysTickCtrl) = 0;
  reg(kSysTickReload) = reload;
  reg(kSysTickCurrent) = 0;  // any write clears the counter; it loads the reload on the next tick
  g_period = std::uint64_t{reload} + 1;
  g_wraps = 0;
  reg(kSysTickCtrl) = kEnable | kTickInterrupt | kProcessorClock;
  // Count from the first reload (at most one tick away), so the first reading is 0, not a period.
  while (reg(kSysTickCurrent) == 0) {
  }
  g_running = true;
}

bool InstructionClock::running() { return g_running; }

std::uint64_t InstructionClock::ticks() {
  // With interrupts masked the wrap count cannot change under us; a wrap since they were masked shows
  // as SysTick's pending bit. The counter was then read either just before that wrap or after it:
  // read it again, certainly after, and count the wrap.
  const std::uint32_t primask = mask_interrupts();
  std::uint64_t wraps = g_wraps;
  std::uint32_t current = reg(kSysTickCurrent);
  if (reg(kIcsr) & kPendSysTick) {
    current = reg(kSysTickCurrent);
    ++wraps;
  }
  restore_interrupts(primask);
  // In period k the counter runs reload .. 1 (wraps = k), then 0 (wraps = k + 1 once the 1 -> 0 step
  // is counted): reload - current ticks into the period, (k + 1) * period - 1 - current in all.
  const std::uint64_t completed = wraps + (current != 0 ? 1 : 0);
  return completed * g_period - 1 - current;
}

}  // namespace exc::target

extern "C" void exc_systick_handler() { exc::target::g_wraps = exc::target::g_wraps + 1; }
