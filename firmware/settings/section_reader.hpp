#pragma once
// The one way to read a section of a settings file. Each field is declared once, where it is read,
// with its type, unit, allowed range, default and a one-line description:
//
//   settings::SectionReader r(doc);                       // the file's top level
//   r.number("duration", s.duration, {1e-3, 28800}, "s", "how long the run lasts", Need::required);
//   settings::SectionReader c = r.section("controller", "the control law's settings");
//   c.numbers("kp", cfg.gains.kp, {1e-3, 1e6}, "1/s^2", "position gains");   // default: kp's value
//   c.choice("regressor_acceleration", cfg.regressor_acceleration, kRegressorAccelerations, "...");
//   c.finish();                                           // unknown keys: an error listing the declared ones
//
// A field's default is the value its destination holds when the key is absent (the struct's member
// initialiser), and it is range-checked like a given value. Every read records the effective value
// (given or default) into an output YAML tree at the same path, so the configuration dump comes from
// the same declarations that parse; reading a struct from an absent section dumps (and validates)
// it. Errors are SettingsErrors at the offending node's line and column: a bad value at the value,
// an unknown key at the key, a missing one at its section. Numbers are recorded in the shortest form
// that reads back to the same double. Reading a Document, each numeric or enumerated field's
// declaration (type, count, range, unit, description) is recorded in it (Document::declarations()).
// Start-up code: allocates, throws.
#include <algorithm>
#include <cstddef>
#include <initializer_list>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "settings/document.hpp"
#include "settings/enum_table.hpp"
#include "settings/settings_error.hpp"

namespace exc::settings {

enum class Need { optional, required };

// The shortest text that reads back to the same double (std::to_chars), plain unless the exponent
// form is more than 2 characters shorter: 0.001, 0.0003, 1000000, 34300000, 1e-06, 1e+09.
std::string format_number(double v);

// The node's number if it is a scalar that reads as a finite one, as every settings value is read
// (a sweep's values too, so the same text means the same number in both).
bool finite_number(const YAML::Node& n, double& v);

class SectionReader {
 public:
  // The top level of a document.
  explicit SectionReader(const Document& document);
  // A section given as a node (a parsed file's sub-tree): `path` is its dotted name ("" at the top
  // level), `file` what errors name.
  SectionReader(std::string file, std::string path, YAML::Node input);

  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  std::string field(const std::string& key) const;  // "controller" + "kp" -> "controller.kp"
  bool present() const;                             // the section is in the file and not empty
  bool has(const std::string& key) const;           // the key is given (and not null)
  // The key is given with a value; a key left without one (`key:`, `key: ~`) is refused rather than
  // read as absent: it would take the default silently. (A section may be empty: its defaults.)
  bool value_given(const std::string& key) const;
  // Declares a field that has no default and is read only when given (then with the reads below).
  bool given(const char* key) {
    declare(key);
    return value_given(key);
  }
  YAML::Node effective() const { return out_; }     // the values read, defaults filled in

  void number(const char* key, double& value, Bounds bounds, const char* unit, const char* what,
              Need need = Need::optional);
  template <typename Int>
  void whole(const char* key, Int& value, double lo, double hi, const char* unit, const char* what,
             Need need = Need::optional) {
    double v = static_cast<double>(value);
    read_whole(key, v, lo, hi, unit, what, need);
    value = static_cast<Int>(v);
  }
  void flag(const char* key, bool& value, const char* what);
  void text(const char* key, std::string& value, const char* what, Need need = Need::optional);
  // A list of at least `min` strings (file names, ...); the default is values'.
  void texts(const char* key, std::vector<std::string>& values, std::size_t min, const char* what);
  // A fixed-size list of numbers (Eigen vector, std::array: anything with size() and data()).
  template <typename V>
  void numbers(const char* key, V& values, Bounds bounds, const char* unit, const char* what,
               Need need = Need::optional) {
    read_list(key, values.data(), static_cast<int>(values.size()), &bounds.lo, &bounds.hi, 0, unit, what, need);
  }
  // The same with bounds per element.
  template <typename V>
  void numbers(const char* key, V& values, const V& lo, const V& hi, const char* unit, const char* what,
               Need need = Need::optional) {
    read_list(key, values.data(), static_cast<int>(values.size()), lo.data(), hi.data(), 1, unit, what, need);
  }
  // A list of min..max rows, each a fixed-size list of numbers with bounds per column.
  template <typename V>
  void rows(const char* key, std::vector<V>& rows, std::size_t min, std::size_t max, const V& lo, const V& hi,
            const char* unit, const char* what, Need need = Need::optional) {
    const std::size_t n = begin_rows(key, min, max, static_cast<int>(lo.size()), unit, what, need);
    if (n == kAbsent) {
      for (V& r : rows) record_row(key, r.data(), static_cast<int>(r.size()));
      return;
    }
    rows.assign(n, lo);
    for (std::size_t i = 0; i < n; ++i) read_row(key, i, rows[i].data(), static_cast<int>(rows[i].size()), lo.data(), hi.data(), unit);
  }
  // One of a table's names; the default is value's. The table is an EnumTable or a registry of
  // things added at start-up (control/controller_registry.hpp): named(name) -> optional<E>,
  // name_of(E), names() ("a, b, c").
  template <typename E, typename Table>
  void choice(const char* key, E& value, const Table& table, const char* what) {
    declare(key);
    std::string name = table.name_of(value);
    if (value_given(key)) {
      name = scalar(key, std::string("one of: ") + table.names() + " (" + what + ")");
      if (!table.named(name)) fail(key, "is '" + name + "'; allowed values: " + table.names());
      value = *table.named(name);
    }
    record(key, name);
    note(key, Declaration::Type::choice, 0, nullptr, nullptr, 0, "", table.names().c_str());
  }
  // The same without a default: `given` tells whether the file names one; recorded only then.
  template <typename E, typename Table>
  void choice(const char* key, E& value, bool& given, const Table& table, const char* what) {
    given = this->given(key);
    if (given) choice(key, value, table, what);
  }
  // A list of at least `min` names of a table (kept as names, each checked against the table, none
  // twice).
  template <typename Table>
  void choices(const char* key, std::vector<std::string>& names, const Table& table, std::size_t min,
               const char* what) {
    if (given(key)) {
      names = read_names(key, min, std::string("a list of names from: ") + table.names() + " (" + what + ")");
      for (std::size_t i = 0; i < names.size(); ++i) {
        if (!table.named(names[i])) fail(key, i, "is '" + names[i] + "'; allowed values: " + table.names());
        if (std::find(names.begin(), names.begin() + static_cast<std::ptrdiff_t>(i), names[i]) != names.begin() + static_cast<std::ptrdiff_t>(i))
          fail(key, i, "'" + names[i] + "' is listed twice; each name once");
      }
    }
    record_names(key, names);
  }
  // A sub-section (a mapping); absent or empty, each of its fields takes its default. Call finish()
  // on it when its fields are read.
  SectionReader section(const char* key, const char* what, Need need = Need::optional);
  // A list of min..max sub-sections: each(item_reader, index) reads one; finish() follows by itself.
  template <typename F>
  void sections(const char* key, std::size_t min, std::size_t max, const char* what, F&& each,
                Need need = Need::optional) {
    const std::size_t n = begin_sections(key, min, max, what, need);
    for (std::size_t i = 0; i < n; ++i) {
      SectionReader item = section_item(key, i);
      each(item, i);
      item.finish();
    }
  }
  // Keys another reader of the same file takes (the plant's sections, for the firmware): allowed
  // here, neither read nor recorded.
  // Free text kept only for people (a machine file's `frames:`) is declared the same way.
  void others(const std::vector<std::string>& keys);

  // Rejects keys that no read declared, listing the declared ones; one spelt nearly as a declared
  // key is named with it ("did you mean duration?"), a required key's misspelling included.
  void finish() const;

  // An error at the key's value (at the section when the key is absent), at an element of a list,
  // or at the section itself.
  [[noreturn]] void fail(const std::string& key, const std::string& reason) const;
  [[noreturn]] void fail(const std::string& key, std::size_t index, const std::string& reason) const;
  [[noreturn]] void fail_here(const std::string& reason) const;
  // An error raised without a place (a check of values already read, e.g. a path's inverse
  // kinematics naming "task.path[2]" or "task.path[2] -> task.path[3]"), rethrown at the line and
  // column of the node its field names in this section's input (as far as the field resolves).
  [[noreturn]] void rethrow_placed(const SettingsError& e) const;
  // Replaces the recorded value of a key (e.g. a path made absolute).
  void record(const char* key, const std::string& value);

 private:
  SectionReader(std::string file, std::string path, YAML::Node input, YAML::Mark mark, YAML::Node out,
                const Document* document);
  YAML::Node get(const std::string& key) const;
  // Records the field's declaration in the document read (nothing without one). Bounds: `count`
  // elements `stride` apart (stride 0: one for all).
  void note(const char* key, Declaration::Type type, int count, const double* lo, const double* hi, int stride,
            const char* unit, const char* what) const;
  YAML::Mark mark_of(const std::string& key) const;
  void declare(const char* key);
  [[noreturn]] void fail_at(const YAML::Mark& mark, const std::string& field, const std::string& reason) const;
  double to_number(const YAML::Node& n, const std::string& field, double lo, double hi, const char* unit) const;
  void read_whole(const char* key, double& value, double lo, double hi, const char* unit, const char* what, Need need);
  void read_list(const char* key, double* values, int n, const double* lo, const double* hi, int bound_stride,
                 const char* unit, const char* what, Need need);
  static constexpr std::size_t kAbsent = static_cast<std::size_t>(-1);
  std::size_t begin_rows(const char* key, std::size_t min, std::size_t max, int columns, const char* unit,
                         const char* what, Need need);
  void read_row(const char* key, std::size_t i, double* values, int n, const double* lo, const double* hi, const char* unit);
  void record_row(const char* key, const double* values, int n);
  std::string scalar(const char* key, const std::string& expected) const;
  std::vector<std::string> read_names(const char* key, std::size_t min, const std::string& expected) const;
  void record_names(const char* key, const std::vector<std::string>& names);
  std::size_t begin_sections(const char* key, std::size_t min, std::size_t max, const char* what, Need need);
  SectionReader section_item(const char* key, std::size_t i);

  std::string file_, path_;
  YAML::Node in_;
  YAML::Mark mark_;  // of the section, or of the nearest enclosing one present in the file
  YAML::Node out_;
  std::vector<std::string> declared_;
  // A required key found missing while the section holds keys not yet declared that are spelt
  // nearly as it: one of them may be its misspelling, or a field declared later. The error waits
  // until that is known: finish() names the misspelt key (did you mean ...?); the plain "missing"
  // follows once every such key is declared, and any other error of this section reports it first.
  struct PendingMissing {
    std::string key, reason;
    std::vector<std::string> lookalikes;
  };
  std::vector<PendingMissing> pending_;
  void missing(const char* key, const std::string& reason);
  void throw_pending() const;
  const Document* document_ = nullptr;  // the document read (null: a node given without one)
};

// Adds to `into` every key of `from` it does not have (recursively for mappings): the effective
// configuration of a file two readers share (the firmware's and the plant's sections of a scene).
void merge_effective(YAML::Node into, const YAML::Node& from);
// The effective tree as YAML text (block style, lists of numbers inline), ending in a newline.
std::string emit(const YAML::Node& effective);

}  // namespace exc::settings
