#pragma once
// The settings blob: everything the firmware's node needs to run a scene, made on the host (where the
// scene is read and validated: firmware_settings.hpp) and decoded where YAML is not, the firmware's
// image on its Cortex-M7, which checks it at boot and refuses a bad one instead of running it.
//
//   offset  size  what
//   0       4     magic "EXSB"
//   4       4     format version (kSettingsBlobVersion): the framing below
//   8       4     total length in bytes, the CRC included
//   12      8     layout fingerprint: FNV-1a 64 over every visited field's name and type, in order
//   20      n     the fields of FirmwareImageSettings in visit order (visit_fields)
//   20 + n  4     CRC-32 (IEEE 802.3, the zlib one) over everything before it
//
// Little-endian throughout; a double is its IEEE-754 bits (u64), an int i32, a count u32, a flag and an
// enumeration one byte; a fixed-size vector or array is its elements; a string or a vector is its
// count, then its elements, the count at most the maximum its visit_fields states.
//
// The field lists: one visit_fields(Visitor&, Struct&) beside each struct's definition (Machine,
// ControllerConfig, Task, Terrain, ...), read by all three visitors here (layout, encoder, decoder),
// so an image built from other sources (a field added, removed, renamed or retyped) has another
// fingerprint and refuses the blob. A visitor is called as
//   v(name, value)              double, bool, int, std::int64_t, a fixed-size Eigen vector of
//                               doubles, a std::array of any of these or of a struct, a struct
//   v(name, value, max)         std::string, std::vector of doubles or of fixed-size Eigen vectors
//   v.counted(name, array, n)   the first n elements of a std::array (n an int field, 0..size)
//   v.choice(name, e, table)    an enumeration, by a settings::EnumTable of its values
//   v.decoding(), v.refuse(name, reason)   a field list that builds something from what it read
//                                          (a spline through its knots) refuses what builds nothing
// Start-up code: allocates (the structs hold strings and vectors), throws nothing but what the
// allocator does (the encoder also std::length_error, on the host).
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Core>

#include "app/firmware_node_config.hpp"
#include "control/task/task.hpp"
#include "model/machine.hpp"

namespace exc::app {

// What the firmware's image runs a scene from: its own struct rather than FirmwareSettings, which also
// carries what only the host uses (the reader's effective YAML tree, the files' paths, the task's
// source waypoints and effort check, the scene's duration before it was stretched) and not the node's
// configuration; this is what FirmwareNode is built from (build_model(machine), task, node) and how
// long it runs, no more.
struct FirmwareImageSettings {
  std::string scene;         // the scene's name: what identifies the run
  Machine machine;           // the nominal machine the firmware's model is built from
  control::Task task;        // the trajectory, its work cycles and timing scale
  FirmwareNodeConfig node;   // the controller's settings (its law by name), the site map, the extras
  std::int64_t cycles = 0;   // control cycles the run lasts: its duration over controller.period
};

inline constexpr std::size_t kMaxSceneName = 256;

template <typename Visitor>
void visit_fields(Visitor& v, FirmwareImageSettings& s) {
  v("scene", s.scene, kMaxSceneName);
  v("machine", s.machine);
  v("task", s.task);
  v("node", s.node);
  v("cycles", s.cycles);
}

inline constexpr std::uint32_t kSettingsBlobMagic = 0x42535845;  // "EXSB" as little-endian bytes
inline constexpr std::uint32_t kSettingsBlobVersion = 1;
inline constexpr std::size_t kSettingsBlobHeaderSize = 20;
inline constexpr std::size_t kSettingsBlobCrcSize = 4;

// The blob of `settings` (host; throws std::length_error naming a string or vector above its maximum).
std::vector<std::uint8_t> encode_settings_blob(const FirmwareImageSettings& settings);
// Decodes and checks a blob: true and `out` replaced, or false, `out` untouched and `error` saying
// what is wrong (its size, magic, version, length, CRC, fingerprint, a field's value and its path,
// a count above its maximum, bytes after the last field, a law this image does not have).
bool decode_settings_blob(const std::uint8_t* data, std::size_t size, FirmwareImageSettings& out, std::string& error);

// CRC-32 of the IEEE 802.3 polynomial (reflected 0xEDB88320, initial and final 0xFFFFFFFF).
std::uint32_t crc32(const std::uint8_t* data, std::size_t size);

namespace blob_detail {

template <typename T>
struct IsStdArray : std::false_type {};
template <typename T, std::size_t N>
struct IsStdArray<std::array<T, N>> : std::true_type {};

template <typename T>
struct IsColumnVector : std::false_type {};
template <int R>
struct IsColumnVector<Eigen::Matrix<double, R, 1>> : std::true_type {};

}  // namespace blob_detail

// A struct's layout as text ("machine{gravity:f64;C:f64[2];...}"): the names and types its
// visit_fields visits, in order; the fingerprint hashes it.
class LayoutDescription {
 public:
  template <typename T>
  void operator()(const char* name, T& value) {
    text_ += name;
    text_ += ':';
    describe(value);
    text_ += ';';
  }
  void operator()(const char* name, std::string&, std::size_t max) {
    text_ += std::string(name) + ":str<=" + std::to_string(max) + ';';
  }
  template <typename T>
  void operator()(const char* name, std::vector<T>&, std::size_t max) {
    text_ += std::string(name) + ":vec<=" + std::to_string(max) + '<';
    T element{};
    describe(element);
    text_ += ">;";
  }
  template <typename T, std::size_t N>
  void counted(const char* name, std::array<T, N>& values, int&) {
    text_ += std::string(name) + ":counted<=" + std::to_string(N) + '<';
    describe(values[0]);
    text_ += ">;";
  }
  template <typename E, typename Table>
  void choice(const char* name, E&, const Table& table) {
    text_ += std::string(name) + ":u8{";
    for (const auto& e : table.entries)
      text_ += std::string(e.name) + '=' + std::to_string(static_cast<unsigned>(e.value)) + ',';
    text_ += "};";
  }
  static bool decoding() { return false; }
  void refuse(const char*, const char*) {}
  const std::string& text() const { return text_; }

 private:
  template <typename T>
  void describe(T& value) {
    if constexpr (std::is_same_v<T, double>) {
      text_ += "f64";
    } else if constexpr (std::is_same_v<T, bool>) {
      text_ += "bool";
    } else if constexpr (std::is_same_v<T, int>) {
      text_ += "i32";
    } else if constexpr (std::is_same_v<T, std::int64_t>) {
      text_ += "i64";
    } else if constexpr (blob_detail::IsColumnVector<T>::value) {
      text_ += "f64[" + std::to_string(T::RowsAtCompileTime) + ']';
    } else if constexpr (blob_detail::IsStdArray<T>::value) {
      text_ += '[' + std::to_string(value.size()) + ']';
      describe(value[0]);
    } else {
      text_ += '{';
      visit_fields(*this, value);
      text_ += '}';
    }
  }

  std::string text_;
};

// FNV-1a 64 of the layout description of S.
std::uint64_t layout_fingerprint_of_text(const std::string& text);
template <typename S>
std::uint64_t layout_fingerprint() {
  S s{};
  LayoutDescription d;
  visit_fields(d, s);
  return layout_fingerprint_of_text(d.text());
}

}  // namespace exc::app
