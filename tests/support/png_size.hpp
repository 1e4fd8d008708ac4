#pragma once
// The pixel size of a PNG file, from its IHDR chunk: for tests of the figures plot-run writes.
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace exc::test {

// Width and height from a PNG's IHDR chunk; false if the file is not a PNG.
inline bool png_size(const std::filesystem::path& path, std::uint32_t* width, std::uint32_t* height) {
  std::ifstream in(path, std::ios::binary);
  unsigned char header[24] = {};
  if (!in.read(reinterpret_cast<char*>(header), sizeof header)) return false;
  const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (!std::equal(signature, signature + 8, header)) return false;
  if (std::string(reinterpret_cast<char*>(header + 12), 4) != "IHDR") return false;
  auto be32 = [&](int at) {
    return std::uint32_t(header[at]) << 24 | std::uint32_t(header[at + 1]) << 16 |
           std::uint32_t(header[at + 2]) << 8 | std::uint32_t(header[at + 3]);
  };
  *width = be32(16);
  *height = be32(20);
  return true;
}

}  // namespace exc::test
