#pragma once
// A field as the code that reads it declared it: its type, how many numbers, its range, unit and
// description. The settings reader records one for every field it reads from a Document
// (Document::declarations()), so a setting named elsewhere (a sweep's knob) takes its type and range
// from the one declaration instead of repeating them.
#include <cstdint>
#include <string>
#include <vector>

namespace exc::settings {

struct Bounds {
  double lo, hi;  // inclusive
};

struct Declaration {
  enum class Type : std::uint8_t { number, whole, numbers, choice };
  std::string field;           // dotted path, e.g. "sensors.latency_cycles"
  Type type = Type::number;
  int count = 1;               // numbers: the list's length
  std::vector<Bounds> bounds;  // one for every element, or one per element (none for a choice)
  std::string unit;
  std::string what;            // its description; a choice's allowed names
  const Bounds& bounds_of(int element) const { return bounds[bounds.size() == 1 ? 0 : static_cast<std::size_t>(element)]; }
};

}  // namespace exc::settings
