#include "app/settings_blob.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <utility>

#include "control/controller_registry.hpp"

namespace exc::app {
namespace {

static_assert(sizeof(int) == 4, "an int field is carried as 32 bits");
static_assert(sizeof(double) == 8 && std::numeric_limits<double>::is_iec559, "a double is carried as IEEE-754 binary64");

std::string hex(std::uint64_t v) {
  char text[24];
  std::snprintf(text, sizeof text, "0x%llx", static_cast<unsigned long long>(v));
  return text;
}

std::uint64_t bits_of(double v) {
  std::uint64_t u = 0;
  std::memcpy(&u, &v, sizeof u);
  return u;
}

// Appends the fields, little-endian, in visit order.
class BlobWriter {
 public:
  explicit BlobWriter(std::vector<std::uint8_t>& out) : out_(out) {}

  template <typename T>
  void operator()(const char* name, T& value) {
    path_.push_back(name);
    put(value);
    path_.pop_back();
  }
  void operator()(const char* name, std::string& s, std::size_t max) {
    check_count(name, s.size(), max);
    put_u32(static_cast<std::uint32_t>(s.size()));
    out_.insert(out_.end(), s.begin(), s.end());
  }
  template <typename T>
  void operator()(const char* name, std::vector<T>& values, std::size_t max) {
    check_count(name, values.size(), max);
    put_u32(static_cast<std::uint32_t>(values.size()));
    path_.push_back(name);
    for (T& v : values) put(v);
    path_.pop_back();
  }
  template <typename T, std::size_t N>
  void counted(const char* name, std::array<T, N>& values, int& count) {
    check_count(name, static_cast<std::size_t>(count < 0 ? N + 1 : count), N);
    put_u32(static_cast<std::uint32_t>(count));
    path_.push_back(name);
    for (int i = 0; i < count; ++i) put(values[static_cast<std::size_t>(i)]);
    path_.pop_back();
  }
  template <typename E, typename Table>
  void choice(const char*, E& value, const Table&) {
    out_.push_back(static_cast<std::uint8_t>(value));
  }
  static bool decoding() { return false; }
  void refuse(const char*, const char*) {}

  void put_u32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void put_u64(std::uint64_t v) {
    for (int i = 0; i < 8; ++i) out_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }

 private:
  template <typename T>
  void put(T& value) {
    if constexpr (std::is_same_v<T, double>) {
      put_u64(bits_of(value));
    } else if constexpr (std::is_same_v<T, bool>) {
      out_.push_back(value ? 1 : 0);
    } else if constexpr (std::is_same_v<T, int>) {
      put_u32(static_cast<std::uint32_t>(value));
    } else if constexpr (std::is_same_v<T, std::int64_t>) {
      put_u64(static_cast<std::uint64_t>(value));
    } else if constexpr (blob_detail::IsColumnVector<T>::value) {
      for (int i = 0; i < T::RowsAtCompileTime; ++i) put_u64(bits_of(value[i]));
    } else if constexpr (blob_detail::IsStdArray<T>::value) {
      for (auto& element : value) put(element);
    } else {
      visit_fields(*this, value);
    }
  }
  void check_count(const char* name, std::size_t count, std::size_t max) {
    if (count <= max) return;
    std::string where;
    for (const char* p : path_) where += std::string(p) + '.';
    throw std::length_error("settings blob: " + where + name + " has " + std::to_string(count) +
                            " entries, more than the blob carries (" + std::to_string(max) + ")");
  }

  std::vector<std::uint8_t>& out_;
  std::vector<const char*> path_;
};

// Reads the fields in visit order; the first error stops it (every later read leaves its field as it
// is) and names the field by its path.
class BlobReader {
 public:
  BlobReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  template <typename T>
  void operator()(const char* name, T& value) {
    if (failed()) return;
    path_.push_back(name);
    get(value);
    path_.pop_back();
  }
  void operator()(const char* name, std::string& s, std::size_t max) {
    std::uint32_t n = 0;
    if (!get_count(name, max, 1, n)) return;
    s.assign(reinterpret_cast<const char*>(data_ + pos_), n);
    pos_ += n;
  }
  template <typename T>
  void operator()(const char* name, std::vector<T>& values, std::size_t max) {
    std::uint32_t n = 0;
    if (!get_count(name, max, element_size<T>(), n)) return;
    values.clear();
    values.resize(n);  // every element is read below
    path_.push_back(name);
    for (std::size_t i = 0; i < values.size() && !failed(); ++i) element(i, values[i]);
    path_.pop_back();
  }
  template <typename T, std::size_t N>
  void counted(const char* name, std::array<T, N>& values, int& count) {
    std::uint32_t n = 0;
    if (!get_count(name, N, element_size<T>(), n)) return;
    count = static_cast<int>(n);
    path_.push_back(name);
    for (std::size_t i = 0; i < n && !failed(); ++i) element(i, values[i]);
    path_.pop_back();
  }
  template <typename E, typename Table>
  void choice(const char* name, E& value, const Table& table) {
    if (failed() || !have(1, name)) return;
    const std::uint8_t b = data_[pos_++];
    for (const auto& e : table.entries) {
      if (static_cast<std::uint8_t>(e.value) == b) {
        value = e.value;
        return;
      }
    }
    fail(name, "is " + std::to_string(b) + ", not one of the values of " + table.names());
  }
  bool decoding() const { return !failed(); }
  void refuse(const char* name, const char* reason) {
    if (!failed()) fail(name, reason);
  }

  bool failed() const { return !error_.empty(); }
  const std::string& error() const { return error_; }
  std::size_t position() const { return pos_; }

 private:
  template <typename T>
  static constexpr std::size_t element_size() {
    if constexpr (blob_detail::IsColumnVector<T>::value) return 8 * static_cast<std::size_t>(T::RowsAtCompileTime);
    else return sizeof(T);
  }
  bool have(std::size_t n, const char* name) {
    if (n <= size_ - pos_) return true;
    fail(name, "runs past the fields' end (" + std::to_string(size_ - pos_) + " bytes left, " + std::to_string(n) +
                   " needed)");
    return false;
  }
  std::uint64_t take(int bytes) {
    std::uint64_t v = 0;
    for (int i = 0; i < bytes; ++i) v |= static_cast<std::uint64_t>(data_[pos_ + static_cast<std::size_t>(i)]) << (8 * i);
    pos_ += static_cast<std::size_t>(bytes);
    return v;
  }
  bool get_count(const char* name, std::size_t max, std::size_t element, std::uint32_t& n) {
    if (failed() || !have(4, name)) return false;
    n = static_cast<std::uint32_t>(take(4));
    if (n > max) {
      fail(name, "count " + std::to_string(n) + " above its maximum " + std::to_string(max));
      return false;
    }
    return have(static_cast<std::size_t>(n) * element, name);
  }
  void get_double(double& value) {
    const std::uint64_t u = take(8);
    double v = 0;
    std::memcpy(&v, &u, sizeof v);
    // Every setting is finite (the readers' ranges): anything else is damage the CRC missed or a
    // broken encoder, and would poison the cycle.
    if (!std::isfinite(v)) return fail("", "is not a finite number (bits " + hex(u) + ")");
    value = v;
  }
  template <typename T>
  void get(T& value) {
    if (failed()) return;
    if constexpr (std::is_same_v<T, double>) {
      if (have(8, "")) get_double(value);
    } else if constexpr (std::is_same_v<T, bool>) {
      if (!have(1, "")) return;
      const std::uint8_t b = data_[pos_++];
      if (b > 1) return fail("", "is " + std::to_string(b) + "; a flag is 0 or 1");
      value = b == 1;
    } else if constexpr (std::is_same_v<T, int>) {
      if (have(4, "")) value = static_cast<int>(static_cast<std::int32_t>(static_cast<std::uint32_t>(take(4))));
    } else if constexpr (std::is_same_v<T, std::int64_t>) {
      if (have(8, "")) value = static_cast<std::int64_t>(take(8));
    } else if constexpr (blob_detail::IsColumnVector<T>::value) {
      if (!have(element_size<T>(), "")) return;
      for (int i = 0; i < T::RowsAtCompileTime && !failed(); ++i) get_double(value[i]);
    } else if constexpr (blob_detail::IsStdArray<T>::value) {
      for (std::size_t i = 0; i < value.size() && !failed(); ++i) element(i, value[i]);
    } else {
      visit_fields(*this, value);
    }
  }
  // Element i of a list: "[i]" in the path while it is read (its index, cheap: no text until an error).
  template <typename T>
  void element(std::size_t i, T& value) {
    index_.push_back({path_.size(), i});
    get(value);
    index_.pop_back();
  }
  void fail(const char* name, const std::string& reason) {
    std::string where;
    std::size_t next_index = 0;
    for (std::size_t level = 0; level < path_.size(); ++level) {
      where += (where.empty() ? "" : ".") + std::string(path_[level]);
      while (next_index < index_.size() && index_[next_index].first == level + 1)
        where += "[" + std::to_string(index_[next_index++].second) + "]";
    }
    if (name[0] != '\0') where += (where.empty() ? "" : ".") + std::string(name);
    error_ = "field " + where + " (at byte " + std::to_string(kSettingsBlobHeaderSize + pos_) + "): " + reason;
  }

  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
  std::vector<const char*> path_;
  // The list elements being read: (the path's depth when entered, the index).
  std::vector<std::pair<std::size_t, std::size_t>> index_;
  std::string error_;
};

std::uint32_t read_u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 | static_cast<std::uint32_t>(p[2]) << 16 |
         static_cast<std::uint32_t>(p[3]) << 24;
}

std::uint64_t read_u64(const std::uint8_t* p) {
  return static_cast<std::uint64_t>(read_u32(p)) | static_cast<std::uint64_t>(read_u32(p + 4)) << 32;
}

// What the node needs of the values beyond their types: checks cheap enough to make at boot, each
// naming the field. "" when they hold.
std::string check_decoded(const FirmwareImageSettings& s) {
  const control::ControllerConfig& c = s.node.controller;
  if (s.cycles < 1) return "field cycles: " + std::to_string(s.cycles) + "; a run lasts at least 1 cycle";
  if (!(c.period > 0 && c.period <= 1)) return "field node.controller.period: must lie in (0, 1] s";
  const control::ControllerEntry* law = control::controller_registry().find(c.law);
  if (law == nullptr)
    return "field node.controller.law: '" + c.law + "' is not a control law of this image (" +
           control::controller_registry().names() + ")";
  if (const std::string why = control::interface_misfit(*law, c.command_interface); !why.empty())
    return "field node.controller.law: " + why;
  const Terrain& map = s.node.site_map;
  for (int i = 1; i < map.num_points; ++i)
    if (!(map.profile[static_cast<std::size_t>(i)].x() > map.profile[static_cast<std::size_t>(i - 1)].x()))
      return "field node.site_map.profile[" + std::to_string(i) + "]: x must increase strictly along the profile";
  return "";
}

}  // namespace

std::uint32_t crc32(const std::uint8_t* data, std::size_t size) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < size; ++i) {
    crc ^= data[i];
    for (int b = 0; b < 8; ++b) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

std::uint64_t layout_fingerprint_of_text(const std::string& text) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (const char c : text) {
    h ^= static_cast<std::uint8_t>(c);
    h *= 0x100000001b3ull;
  }
  return h;
}

std::vector<std::uint8_t> encode_settings_blob(const FirmwareImageSettings& settings) {
  FirmwareImageSettings copy = settings;  // the field lists take their structs by reference
  std::vector<std::uint8_t> out;
  BlobWriter w(out);
  w.put_u32(kSettingsBlobMagic);
  w.put_u32(kSettingsBlobVersion);
  w.put_u32(0);  // the length, below
  w.put_u64(layout_fingerprint<FirmwareImageSettings>());
  visit_fields(w, copy);
  const std::size_t total = out.size() + kSettingsBlobCrcSize;
  if (total > 0xFFFFFFFFu) throw std::length_error("settings blob: " + std::to_string(total) + " bytes, more than 4 GiB");
  for (int i = 0; i < 4; ++i) out[8 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(total >> (8 * i));
  w.put_u32(crc32(out.data(), out.size()));
  return out;
}

bool decode_settings_blob(const std::uint8_t* data, std::size_t size, FirmwareImageSettings& out, std::string& error) {
  const std::size_t framing = kSettingsBlobHeaderSize + kSettingsBlobCrcSize;
  if (data == nullptr || size < framing) {
    error = "the blob is " + std::to_string(size) + " bytes, shorter than its header and CRC (" + std::to_string(framing) + ")";
    return false;
  }
  const std::uint32_t magic = read_u32(data);
  if (magic != kSettingsBlobMagic) {
    error = "bad magic " + hex(magic) + " (a settings blob starts with 'EXSB', " + hex(kSettingsBlobMagic) + ")";
    return false;
  }
  const std::uint32_t version = read_u32(data + 4);
  if (version != kSettingsBlobVersion) {
    error = "format version " + std::to_string(version) + ", this image reads version " + std::to_string(kSettingsBlobVersion);
    return false;
  }
  const std::uint32_t length = read_u32(data + 8);
  if (length != size) {
    error = "length: the header says " + std::to_string(length) + " bytes, the blob has " + std::to_string(size) +
            (size < length ? " (truncated)" : " (bytes after its end)");
    return false;
  }
  const std::uint32_t stored_crc = read_u32(data + size - kSettingsBlobCrcSize);
  const std::uint32_t crc = crc32(data, size - kSettingsBlobCrcSize);
  if (stored_crc != crc) {
    error = "CRC-32 " + hex(stored_crc) + " in the blob, " + hex(crc) + " computed: the blob is damaged";
    return false;
  }
  const std::uint64_t fingerprint = read_u64(data + 12);
  const std::uint64_t own = layout_fingerprint<FirmwareImageSettings>();
  if (fingerprint != own) {
    error = "layout fingerprint " + hex(fingerprint) + " differs from this image's " + hex(own) +
            ": the blob was made from other sources (a settings struct's fields differ)";
    return false;
  }
  FirmwareImageSettings decoded;
  BlobReader r(data + kSettingsBlobHeaderSize, size - framing);
  visit_fields(r, decoded);
  if (r.failed()) {
    error = r.error();
    return false;
  }
  if (r.position() != size - framing) {
    error = std::to_string(size - framing - r.position()) + " bytes after the last field";
    return false;
  }
  if (const std::string why = check_decoded(decoded); !why.empty()) {
    error = why;
    return false;
  }
  out = std::move(decoded);
  return true;
}

}  // namespace exc::app
