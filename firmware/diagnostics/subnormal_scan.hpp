#pragma once
// A look for subnormal numbers in a node's working state (docs/floating-point.md): a state visitor
// (the shape of control::StateVisitor: visit(name, values, count), one double, a std::array of
// doubles, a fixed-size Eigen matrix) that each state type's visit_state feeds, value by value and by
// name (FirmwareNode::scan_state, PlantNode::scan_state name only the nodes' members). It counts the
// subnormal ones and keeps the first it met, so a test can say which state decayed. Told by the
// values' bits (is_subnormal), so it sees them in the loop's mode too. Allocation-free.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include <Eigen/Core>


namespace exc::diagnostics {

// A subnormal, told by its bits (exponent field zero, fraction not): under DAZ a comparison reads a
// subnormal as zero, and std::fpclassify compiles to comparisons.
inline bool is_subnormal(double x) {
  std::uint64_t b = 0;
  std::memcpy(&b, &x, sizeof b);
  return (b & 0x7ff0000000000000ull) == 0 && (b & 0x000fffffffffffffull) != 0;
}


class SubnormalScan {
 public:
  void visit(const char* name, const double* values, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) {
      if (!is_subnormal(values[i])) continue;
      if (found_ == 0) first_ = Finding{name, i, values[i], 0, time_};
      ++found_;
      note(name, i, values[i]);
    }
    scanned_ += count;
  }
  void visit(const char* name, const double& value) { visit(name, &value, 1); }
  template <std::size_t N>
  void visit(const char* name, const std::array<double, N>& values) {
    visit(name, values.data(), N);
  }
  template <typename Derived>
  void visit(const char* name, const Eigen::PlainObjectBase<Derived>& values) {
    static_assert(std::is_same_v<typename Derived::Scalar, double>, "a scan reads doubles");
    visit(name, values.data(), static_cast<std::size_t>(values.size()));
  }

  struct Finding {
    const char* name = "";
    std::size_t index = 0;  // of the first subnormal under this name
    double value = 0;
    std::uint64_t count = 0;  // subnormal values met under this name
    double time = 0;          // the caller's time (set_time) when the first was met
  };
  // Stamps the findings from now on (e.g. with the run's time before each cycle's scan).
  void set_time(double t) { time_ = t; }
  static constexpr std::size_t kNames = 32;
  std::uint64_t found() const { return found_; }      // subnormal values met so far
  std::uint64_t scanned() const { return scanned_; }  // values looked at so far
  const Finding& first() const { return first_; }     // the first subnormal met (when found() > 0)
  // Each name under which subnormals were met, in the order first met (up to kNames of them).
  const Finding* names_begin() const { return names_.data(); }
  const Finding* names_end() const { return names_.data() + named_; }

 private:
  void note(const char* name, std::size_t index, double value) {
    for (std::size_t k = 0; k < named_; ++k)
      if (names_[k].name == name) return void(++names_[k].count);
    if (named_ < kNames) names_[named_++] = Finding{name, index, value, 1, time_};
  }

  std::uint64_t found_ = 0, scanned_ = 0;
  double time_ = 0;
  Finding first_;
  std::array<Finding, kNames> names_{};
  std::size_t named_ = 0;
};

}  // namespace exc::diagnostics
