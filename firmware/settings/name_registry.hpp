#pragma once
// Things a program may add to at start-up (control laws, integration methods), each an entry with a
// name and a one-line description: the settings reader takes it as it takes an EnumTable (named,
// name_of, names), the command lines check against name_list() and print help(). Entries keep
// their order of registration. Start-up code: allocates, throws.
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace exc::settings {

// Entry: any struct with `std::string name, what`.
template <typename Entry>
class NameRegistry {
 public:
  // `thing` names an entry in errors: "controller", "integration method".
  explicit NameRegistry(std::string thing) : thing_(std::move(thing)) {}

  // Throws std::invalid_argument for an empty or taken name.
  void add(Entry entry) {
    if (entry.name.empty()) throw std::invalid_argument("a " + thing_ + " needs a name");
    if (find(entry.name)) throw std::invalid_argument(thing_ + " '" + entry.name + "' is registered twice");
    entries_.push_back(std::move(entry));
  }

  const std::vector<Entry>& entries() const { return entries_; }
  const Entry* find(std::string_view name) const {
    for (const Entry& e : entries_)
      if (e.name == name) return &e;
    return nullptr;
  }
  // The entry of a name; std::invalid_argument naming the allowed ones when none has it.
  const Entry& at(std::string_view name) const {
    if (const Entry* e = find(name)) return *e;
    throw std::invalid_argument("unknown " + thing_ + " '" + std::string(name) + "' (allowed: " + names() + ")");
  }
  // Its place in the order of registration.
  std::size_t index_of(std::string_view name) const { return static_cast<std::size_t>(&at(name) - entries_.data()); }

  // EnumTable's interface, a value being its name.
  std::optional<std::string> named(std::string_view name) const {
    if (find(name)) return std::string(name);
    return std::nullopt;
  }
  const std::string& name_of(const std::string& name) const { return name; }
  std::string names() const {  // "a, b, c"
    std::string s;
    for (const Entry& e : entries_) s += (s.empty() ? "" : ", ") + e.name;
    return s;
  }
  std::vector<std::string> name_list() const {
    std::vector<std::string> v;
    for (const Entry& e : entries_) v.push_back(e.name);
    return v;
  }
  // One line an entry, "  name: what", for --help.
  std::string help() const {
    std::string s;
    for (const Entry& e : entries_) s += (s.empty() ? "  " : "\n  ") + e.name + ": " + e.what;
    return s;
  }

 private:
  std::string thing_;
  std::vector<Entry> entries_;
};

}  // namespace exc::settings
