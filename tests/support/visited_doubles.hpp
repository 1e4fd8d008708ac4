#pragma once
// Whether a state type's visit_state (control::StateVisitor's shape, docs/floating-point.md) shows
// every double the type holds, each once: the test sets each double of an object to its own
// subnormal (bit patterns 1, 2, 3, ...: exponent field zero), visits the object and compares what the
// visit showed with what was set (audit_visit). How the doubles are set depends on the type:
//  - made of doubles only (doubles, arrays of them, fixed-size Eigen matrices; no padding):
//    SubnormalFill::every_slot sets every 8 bytes of the object, with no list of members at all. A
//    member of another type added later leaves bytes no double visit covers, and the audit fails.
//  - mixed (integers, flags, nested structs beside the doubles): EXC_FILL_EVERY_MEMBER binds every
//    member with a structured binding, which does not compile once the type has a member more or
//    fewer than the test names, and sets each double member; integers, bools and enums stay as they
//    are; a member of a class type the fill does not know does not compile until the test says how
//    its doubles are set (a NestedFill<T> specialisation), or that none are visited and why.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "control/control_types.hpp"
#include "diagnostics/subnormal_scan.hpp"

namespace exc::test {

class SubnormalFill;

namespace detail {
template <typename Derived>
std::true_type plain_matrix_test(const Eigen::PlainObjectBase<Derived>*);
std::false_type plain_matrix_test(...);
// A dense Eigen matrix or array (its doubles are its storage), not a decomposition or an expression.
template <typename T>
inline constexpr bool is_plain_matrix = decltype(plain_matrix_test(std::declval<T*>()))::value;
}  // namespace detail

// How a member of class type T (a nested struct) has its doubles set: specialise with
// `static void fill(SubnormalFill&, T&)`. Left unspecialised, a member of type T does not compile.
template <typename T>
struct NestedFill;

class SubnormalFill {
 public:
  struct Member {
    std::string name;
    std::uint64_t first = 0, last = 0;  // fill numbers it took (none when last < first)
  };

  void operator()(double& x) { x = next(); }
  template <typename Derived>
  void operator()(Eigen::PlainObjectBase<Derived>& m) {
    static_assert(std::is_same_v<typename Derived::Scalar, double>, "a state visitor reads doubles");
    for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = next();
  }
  template <typename T, std::size_t N>
  void operator()(std::array<T, N>& a) {
    for (T& x : a) (*this)(x);
  }
  // Not a double: left as it is.
  template <typename T, std::enable_if_t<std::is_integral_v<T> || std::is_enum_v<T>, int> = 0>
  void operator()(T&) {}
  // A nested struct (or any class but a matrix: an Eigen decomposition too): its NestedFill.
  template <typename T, std::enable_if_t<std::is_class_v<T> && !detail::is_plain_matrix<T>, int> = 0>
  void operator()(T& x) {
    NestedFill<T>::fill(*this, x);
  }

  // Each member, named for the audit's messages (`names`: the members' names, comma-separated).
  template <typename... Members>
  void members(const char* names, Members&... m) {
    std::vector<std::string> split;
    std::string name;
    for (const char* c = names;; ++c) {
      if (*c == ',' || *c == 0) {
        split.push_back(name);
        name.clear();
        if (*c == 0) break;
      } else if (*c != ' ' && *c != '\n') {
        name += *c;
      }
    }
    std::size_t k = 0;
    ((one(split.at(k++), m)), ...);
  }

  // Every 8 bytes of an object made of doubles only.
  template <typename T>
  void every_slot(const char* name, T& object) {
    static_assert(sizeof(T) % sizeof(double) == 0, "every_slot: a type made of doubles only");
    auto* bytes = reinterpret_cast<unsigned char*>(static_cast<void*>(&object));
    for (std::size_t k = 0; k < sizeof(T) / sizeof(double); ++k) {
      const double d = next();
      std::memcpy(bytes + k * sizeof(double), &d, sizeof d);
      members_.push_back(Member{std::string(name) + " bytes " + std::to_string(k * sizeof d) + "-" + std::to_string((k + 1) * sizeof d - 1),
                                count_, count_});
    }
  }

  std::uint64_t count() const { return count_; }  // doubles set so far
  const std::vector<Member>& filled() const { return members_; }

 private:
  template <typename M>
  void one(const std::string& name, M& m) {
    const std::uint64_t first = count_ + 1;
    const std::size_t at = members_.size();
    (*this)(m);
    // A nested struct's members are listed after it; the member itself spans them all.
    members_.insert(members_.begin() + static_cast<std::ptrdiff_t>(at), Member{name, first, count_});
  }
  double next() {
    const std::uint64_t bits = ++count_;
    double d;
    std::memcpy(&d, &bits, sizeof d);
    return d;
  }
  std::uint64_t count_ = 0;
  std::vector<Member> members_;
};

// Binds every member of `object`, in declaration order, and sets its doubles. The names are the
// binding's: a type with a member more or fewer than named does not compile.
#define EXC_FILL_EVERY_MEMBER(fill, object, ...) \
  do {                                           \
    auto& [__VA_ARGS__] = (object);              \
    (fill).members(#__VA_ARGS__, __VA_ARGS__);   \
  } while (false)

// What a visit showed of an object whose doubles a SubnormalFill set.
struct VisitAudit {
  std::uint64_t set = 0;                 // doubles set
  std::uint64_t shown = 0;               // values the visit showed
  std::vector<std::string> missed;       // members (or parts) with a double set and not shown
  std::vector<std::string> repeated;     // names under which a double was shown again
  std::vector<std::string> foreign;      // names under which a value not set was shown (outside the
                                         // object, a copy, or not one of its doubles)
  std::uint64_t scan_found = 0, scan_scanned = 0;  // the same visit into diagnostics::SubnormalScan
  bool complete() const {
    return shown == set && missed.empty() && repeated.empty() && foreign.empty() && scan_found == set && scan_scanned == set;
  }
  std::string text() const {
    std::string t = std::to_string(set) + " doubles set, " + std::to_string(shown) + " values shown; the subnormal scan found " +
                    std::to_string(scan_found) + " of " + std::to_string(scan_scanned) + " scanned";
    for (const std::string& m : missed) t += "\n  not visited: " + m;
    for (const std::string& r : repeated) t += "\n  visited twice: " + r;
    for (const std::string& f : foreign) t += "\n  not a double of the object: " + f;
    return t;
  }
};

namespace detail {
// Records every value a visit shows, with its name.
struct VisitRecord final : control::StateVisitor {
  using StateVisitor::visit;
  void visit(const char* name, const double* values, std::size_t count) override {
    for (std::size_t i = 0; i < count; ++i) shown.push_back({name, values + i});
  }
  struct Shown {
    const char* name;
    const double* at;
  };
  std::vector<Shown> shown;
};
}  // namespace detail

template <typename T>
VisitAudit audit_visit(const T& object, const SubnormalFill& fill) {
  VisitAudit a;
  a.set = fill.count();
  detail::VisitRecord record;
  visit_state(object, record);
  a.shown = record.shown.size();
  const auto* begin = reinterpret_cast<const unsigned char*>(static_cast<const void*>(&object));
  const auto* end = begin + sizeof(T);
  std::vector<int> times(a.set + 1, 0);
  std::vector<const char*> shown_as(a.set + 1, nullptr);
  const auto note = [](std::vector<std::string>& list, const std::string& s) {
    if (std::find(list.begin(), list.end(), s) == list.end()) list.push_back(s);
  };
  for (const detail::VisitRecord::Shown& s : record.shown) {
    const auto* at = reinterpret_cast<const unsigned char*>(static_cast<const void*>(s.at));
    std::uint64_t bits = 0;
    std::memcpy(&bits, s.at, sizeof bits);
    if (at < begin || at + sizeof(double) > end || bits == 0 || bits > a.set) {
      note(a.foreign, s.name);
      continue;
    }
    if (++times[bits] > 1) note(a.repeated, s.name);
  }
  const std::vector<SubnormalFill::Member>& members = fill.filled();
  const auto missing_in = [&times](const SubnormalFill::Member& m) {
    std::uint64_t n = 0;
    for (std::uint64_t k = m.first; k <= m.last; ++k) n += times[k] == 0 ? 1 : 0;
    return n;
  };
  for (std::size_t i = 0; i < members.size(); ++i) {
    const SubnormalFill::Member& m = members[i];
    const std::uint64_t missing = missing_in(m);
    if (missing == 0) continue;
    // A nested struct is listed before its members: name the innermost member that misses doubles.
    const bool inner_misses = std::any_of(members.begin() + static_cast<std::ptrdiff_t>(i) + 1, members.end(), [&](const SubnormalFill::Member& inner) {
      return inner.first >= m.first && inner.last <= m.last && missing_in(inner) > 0;
    });
    if (!inner_misses)
      a.missed.push_back(m.name + " (" + std::to_string(missing) + " of its " + std::to_string(m.last - m.first + 1) + " doubles)");
  }
  diagnostics::SubnormalScan scan;
  visit_state(object, scan);
  a.scan_found = scan.found();
  a.scan_scanned = scan.scanned();
  return a;
}

}  // namespace exc::test
