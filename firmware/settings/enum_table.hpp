#pragma once
// An enumeration's names, declared once: the table a settings parser, a command line's option check
// and its --help, and the docs' test all read, so a value added here is accepted everywhere and
// nowhere else.
//   inline constexpr EnumTable<Method, 2> kMethods{{{{Method::a, "a", "what a is"}, {Method::b, "b", "..."}}}};
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace exc::settings {

template <typename E>
struct EnumName {
  E value;
  const char* name;
  const char* what;  // one line, for --help and the docs
};

template <typename E, std::size_t N>
struct EnumTable {
  std::array<EnumName<E>, N> entries;

  std::optional<E> named(std::string_view name) const {
    for (const EnumName<E>& e : entries)
      if (name == e.name) return e.value;
    return std::nullopt;
  }
  // The value's name ("?" for a value not in the table).
  const char* name_of(E value) const {
    for (const EnumName<E>& e : entries)
      if (e.value == value) return e.name;
    return "?";
  }
  // "a, b, c": for error messages and --help.
  std::string names() const {
    std::string s;
    for (const EnumName<E>& e : entries) s += (s.empty() ? "" : ", ") + std::string(e.name);
    return s;
  }
  std::vector<std::string> name_list() const {
    std::vector<std::string> v;
    for (const EnumName<E>& e : entries) v.emplace_back(e.name);
    return v;
  }
};

}  // namespace exc::settings
