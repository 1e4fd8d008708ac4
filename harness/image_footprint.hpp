#pragma once
// What a bare-metal image takes of the board's memories, read on the host from the ELF's section
// headers (as arm-none-eabi-size -A lists them): flash is every allocated section with contents (code,
// read-only data, tables, and .data's initial values, which the reset handler copies to RAM); RAM is
// every allocated section placed in RAM, with or without contents, the heap and the stack reserved
// by the linker script included.
#include <cstdint>
#include <string>
#include <vector>

namespace exc::sim {

struct ImageSection {
  std::string name;
  std::uint32_t address = 0;
  std::uint32_t bytes = 0;
  bool has_contents = false;  // false: NOBITS (.bss, .heap, .stack)
};

struct ImageFootprint {
  std::vector<ImageSection> sections;  // allocated sections, in file order
  std::uint64_t flash_bytes = 0;
  std::uint64_t ram_bytes = 0;         // everything in RAM, heap and stack included
  std::uint64_t ram_static_bytes = 0;  // .data and .bss: RAM the program's own variables take
  std::uint64_t heap_bytes = 0;        // the .heap section
  std::uint64_t stack_bytes = 0;       // the .stack section
};

// The mps2-an500's RAM (ZBT SSRAM2/3, docs/target.md): a section whose address falls in it is in RAM.
inline constexpr std::uint32_t kMps2An500RamStart = 0x20000000;
inline constexpr std::uint32_t kMps2An500RamBytes = 4u << 20;
inline constexpr std::uint32_t kMps2An500FlashBytes = 4u << 20;  // ZBT SSRAM1 at 0, the image's flash

// Reads a 32-bit little-endian ARM ELF. Throws std::runtime_error naming the file and what is wrong
// with it (unreadable, not ELF, not 32-bit ARM, headers cut short).
ImageFootprint read_image_footprint(const std::string& elf_path, std::uint32_t ram_start = kMps2An500RamStart,
                                    std::uint32_t ram_bytes = kMps2An500RamBytes);

}  // namespace exc::sim
