#include "harness/image_footprint.hpp"

#include <elf.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>

namespace exc::sim {

ImageFootprint read_image_footprint(const std::string& elf_path, std::uint32_t ram_start, std::uint32_t ram_bytes) {
  std::ifstream in(elf_path, std::ios::binary);
  if (!in) throw std::runtime_error(elf_path + ": cannot be read: " + std::strerror(errno));
  const std::string file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto refuse = [&](const std::string& why) { throw std::runtime_error(elf_path + ": " + why); };

  Elf32_Ehdr header;
  if (file.size() < sizeof header) refuse("shorter than an ELF header");
  std::memcpy(&header, file.data(), sizeof header);
  if (std::memcmp(header.e_ident, ELFMAG, SELFMAG) != 0) refuse("not an ELF file");
  if (header.e_ident[EI_CLASS] != ELFCLASS32 || header.e_ident[EI_DATA] != ELFDATA2LSB || header.e_machine != EM_ARM) {
    refuse("not a 32-bit little-endian ARM ELF");
  }
  if (header.e_shentsize != sizeof(Elf32_Shdr)) refuse("section header size " + std::to_string(header.e_shentsize));
  const std::uint64_t headers_end = std::uint64_t{header.e_shoff} + std::uint64_t{header.e_shnum} * sizeof(Elf32_Shdr);
  if (headers_end > file.size()) refuse("section headers run past the end of the file");
  auto section = [&](unsigned i) {
    Elf32_Shdr s;
    std::memcpy(&s, file.data() + header.e_shoff + i * sizeof(Elf32_Shdr), sizeof s);
    return s;
  };
  if (header.e_shstrndx >= header.e_shnum) refuse("no section name table");
  const Elf32_Shdr names = section(header.e_shstrndx);
  if (std::uint64_t{names.sh_offset} + names.sh_size > file.size()) refuse("the section name table runs past the end");

  ImageFootprint f;
  for (unsigned i = 0; i < header.e_shnum; ++i) {
    const Elf32_Shdr s = section(i);
    if (!(s.sh_flags & SHF_ALLOC) || s.sh_size == 0) continue;
    if (s.sh_name >= names.sh_size) refuse("a section name outside the name table");
    ImageSection entry;
    const char* name = file.data() + names.sh_offset + s.sh_name;
    entry.name.assign(name, strnlen(name, names.sh_size - s.sh_name));
    entry.address = s.sh_addr;
    entry.bytes = s.sh_size;
    entry.has_contents = s.sh_type != SHT_NOBITS;
    if (entry.has_contents) f.flash_bytes += s.sh_size;
    if (s.sh_addr >= ram_start && s.sh_addr - ram_start < ram_bytes) {
      f.ram_bytes += s.sh_size;
      if (entry.name == ".heap") {
        f.heap_bytes += s.sh_size;
      } else if (entry.name == ".stack") {
        f.stack_bytes += s.sh_size;
      } else {
        f.ram_static_bytes += s.sh_size;
      }
    }
    f.sections.push_back(entry);
  }
  return f;
}

}  // namespace exc::sim
