#include "settings/section_reader.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace exc::settings {

std::string format_number(double v) {
  // Both forms are the shortest that read back to v; the plain one unless it is much longer.
  char f[400], e[64];
  const auto rf = std::to_chars(f, f + sizeof f, v, std::chars_format::fixed);
  const auto re = std::to_chars(e, e + sizeof e, v, std::chars_format::scientific);
  if (rf.ec == std::errc() && rf.ptr - f <= re.ptr - e + 2) return std::string(f, rf.ptr);
  return std::string(e, re.ptr);
}

namespace {

std::string range_text(double lo, double hi, const char* unit) {
  std::string s = "[" + format_number(lo) + ", " + format_number(hi) + "]";
  if (unit != nullptr && unit[0] != '\0') s += std::string(" ") + unit;
  return s;
}

std::string with_unit(double v, const char* unit) {
  return format_number(v) + (unit != nullptr && unit[0] != '\0' ? std::string(" ") + unit : "");
}

std::string index_field(const std::string& field, std::size_t i) { return field + "[" + std::to_string(i) + "]"; }

// The node's number, if it is a scalar that reads as one.
bool scalar_number(const YAML::Node& n, double& v) {
  if (!n.IsScalar()) return false;
  try {
    v = n.as<double>();
  } catch (const YAML::Exception&) {
    return false;
  }
  return true;
}

YAML::Node flow_sequence() {
  YAML::Node s(YAML::NodeType::Sequence);
  s.SetStyle(YAML::EmitterStyle::Flow);
  return s;
}

}  // namespace

SectionReader::SectionReader(const Document& document)
    : SectionReader(document.file(), "", document.root(),
                    document.root().IsDefined() ? document.root().Mark() : YAML::Mark::null_mark(),
                    YAML::Node(YAML::NodeType::Map), &document) {
  if (present() && !in_.IsMap()) fail_here("the file must be a YAML mapping");
  if (!present()) fail_here("the file is empty: a YAML mapping is required");
}

SectionReader::SectionReader(std::string file, std::string path, YAML::Node input)
    : SectionReader(std::move(file), std::move(path), input,
                    input.IsDefined() ? input.Mark() : YAML::Mark::null_mark(), YAML::Node(YAML::NodeType::Map), nullptr) {
  if (present() && !in_.IsMap()) fail_here("must be a mapping");
}

SectionReader::SectionReader(std::string file, std::string path, YAML::Node input, YAML::Mark mark, YAML::Node out,
                             const Document* document)
    : file_(std::move(file)), path_(std::move(path)), in_(input), mark_(mark), out_(out), document_(document) {}

void SectionReader::note(const char* key, Declaration::Type type, int count, const double* lo, const double* hi,
                         int stride, const char* unit, const char* what) const {
  if (document_ == nullptr) return;
  Declaration d;
  d.field = field(key);
  d.type = type;
  d.count = count;
  for (int i = 0; i < (stride == 0 ? std::min(count, 1) : count); ++i) d.bounds.push_back({lo[i * stride], hi[i * stride]});
  d.unit = unit;
  d.what = what;
  document_->declare(std::move(d));
}

std::string SectionReader::field(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

bool SectionReader::present() const { return in_.IsDefined() && !in_.IsNull(); }

YAML::Node SectionReader::get(const std::string& key) const {
  if (!present() || !in_.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
  const YAML::Node& in = in_;
  return in[key];
}

bool SectionReader::has(const std::string& key) const {
  const YAML::Node n = get(key);
  return n.IsDefined() && !n.IsNull();
}

bool SectionReader::value_given(const std::string& key) const {
  const YAML::Node n = get(key);
  if (n.IsDefined() && n.IsNull()) {
    // At the key: an empty value's own mark is where the parser found the next token (the next line).
    YAML::Mark mark = mark_of(key);
    for (const auto& kv : in_)
      if (kv.first.IsScalar() && kv.first.Scalar() == key) mark = kv.first.Mark();
    fail_at(mark, field(key), "has no value (empty or ~); give one");
  }
  return n.IsDefined();
}

YAML::Mark SectionReader::mark_of(const std::string& key) const {
  const YAML::Node n = get(key);
  return n.IsDefined() ? n.Mark() : mark_;
}

void SectionReader::declare(const char* key) {
  for (const std::string& d : declared_)
    if (d == key) return;
  declared_.emplace_back(key);
  // A key the section declares is no misspelling: a missing key whose every lookalike is declared
  // is plainly missing.
  for (PendingMissing& p : pending_) {
    p.lookalikes.erase(std::remove(p.lookalikes.begin(), p.lookalikes.end(), key), p.lookalikes.end());
    if (p.lookalikes.empty()) fail_at(mark_of(p.key), field(p.key), p.reason);
  }
}

void SectionReader::fail_at(const YAML::Mark& mark, const std::string& field, const std::string& reason) const {
  throw_pending();
  const bool known = !mark.is_null();
  throw SettingsError(file_, known ? mark.line + 1 : 0, known ? mark.column + 1 : 0, field, reason);
}

namespace {

// Edits (insert, delete, replace, swap two neighbours) from a to b: how far a misspelling is.
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1, 0));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i)
    for (std::size_t j = 1; j <= b.size(); ++j) {
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[a.size()][b.size()];
}

// Whether `word` is spelt nearly as `c`: at most 2 edits, and fewer than half its letters.
bool misspelling(const std::string& word, const std::string& c) {
  const std::size_t e = edit_distance(word, c);
  return e > 0 && e <= 2 && 2 * e < std::max(word.size(), c.size());
}

// A word close enough to `word` to be its misspelling, the closest of `candidates`; "" when none is.
std::string closest(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_distance = 3;
  for (const std::string& c : candidates) {
    const std::size_t e = edit_distance(word, c);
    if (misspelling(word, c) && e < best_distance) {
      best = c;
      best_distance = e;
    }
  }
  return best;
}

}  // namespace

void SectionReader::fail(const std::string& key, const std::string& reason) const {
  fail_at(mark_of(key), field(key), reason);
}

void SectionReader::missing(const char* key, const std::string& reason) {
  PendingMissing p{key, reason, {}};
  if (present() && in_.IsMap())
    for (const auto& kv : in_) {
      const std::string k = kv.first.Scalar();
      if (std::find(declared_.begin(), declared_.end(), k) == declared_.end() && misspelling(k, key))
        p.lookalikes.push_back(k);
    }
  if (p.lookalikes.empty()) fail(key, reason);
  pending_.push_back(std::move(p));
}

void SectionReader::throw_pending() const {
  if (pending_.empty()) return;
  const PendingMissing& p = pending_.front();
  const YAML::Mark mark = mark_of(p.key);
  const bool known = !mark.is_null();
  throw SettingsError(file_, known ? mark.line + 1 : 0, known ? mark.column + 1 : 0, field(p.key), p.reason);
}

void SectionReader::fail(const std::string& key, std::size_t index, const std::string& reason) const {
  const YAML::Node n = get(key);
  const YAML::Mark mark = n.IsSequence() && index < n.size() ? n[index].Mark() : mark_of(key);
  fail_at(mark, index_field(field(key), index), reason);
}

void SectionReader::fail_here(const std::string& reason) const { fail_at(mark_, path_, reason); }

void SectionReader::rethrow_placed(const SettingsError& e) const {
  if (e.line() > 0 || e.file() != file_) throw e;
  // The field up to its first blank ("task.path[2] -> ..."), relative to this section.
  std::string rest = e.field().substr(0, e.field().find(' '));
  if (path_.empty()) {
    rest = "." + rest;
  } else {
    if (rest.compare(0, path_.size(), path_) != 0) throw e;
    rest = rest.substr(path_.size());
  }
  YAML::Mark mark = mark_;
  if (!in_.IsDefined()) fail_at(mark, e.field(), e.reason());  // an absent section: at its parent's line
  // (Node::reset rebinds a handle; assigning one would overwrite the document's node.)
  YAML::Node node;
  node.reset(in_);
  while (!rest.empty() && node.IsDefined() && !node.IsNull()) {
    YAML::Node next;
    if (rest[0] == '.') {
      const std::size_t end = rest.find_first_of(".[", 1);
      const std::string key = rest.substr(1, end == std::string::npos ? std::string::npos : end - 1);
      if (!node.IsMap()) break;
      const YAML::Node& map = node;
      // A key the file does not have (a generated field such as task.cycle) gives an invalid node,
      // which reset() refuses with yaml-cpp's own exception: stop at the section's line instead.
      const YAML::Node child = map[key];
      if (!child.IsDefined()) break;
      next.reset(child);
      rest = end == std::string::npos ? "" : rest.substr(end);
    } else if (rest[0] == '[') {
      const std::size_t end = rest.find(']');
      if (end == std::string::npos || !node.IsSequence()) break;
      const std::size_t i = std::stoul(rest.substr(1, end - 1));
      if (i >= node.size()) break;
      const YAML::Node& list = node;
      next.reset(list[i]);
      rest = rest.substr(end + 1);
    } else {
      break;
    }
    if (!next.IsDefined()) break;
    node.reset(next);
    mark = node.Mark();
  }
  fail_at(mark, e.field(), e.reason());
}

void SectionReader::record(const char* key, const std::string& value) { out_[key] = value; }

double SectionReader::to_number(const YAML::Node& n, const std::string& name, double lo, double hi,
                                const char* unit) const {
  double v = 0;
  if (!scalar_number(n, v))
    fail_at(n.Mark(), name,
            (n.IsScalar() ? "'" + n.Scalar() + "' is not a number" : std::string("must be a number")) +
                "; allowed range " + range_text(lo, hi, unit));
  if (!std::isfinite(v) || v < lo || v > hi)
    fail_at(n.Mark(), name, "is " + with_unit(v, unit) + "; allowed range " + range_text(lo, hi, unit));
  return v;
}

void SectionReader::number(const char* key, double& value, Bounds b, const char* unit, const char* what, Need need) {
  declare(key);
  note(key, Declaration::Type::number, 1, &b.lo, &b.hi, 0, unit, what);
  if (value_given(key)) {
    value = to_number(get(key), field(key), b.lo, b.hi, unit);
  } else if (need == Need::required) {
    missing(key, std::string("missing: ") + what + "; a number in " + range_text(b.lo, b.hi, unit));
  } else if (!std::isfinite(value) || value < b.lo || value > b.hi) {
    fail(key, "is " + with_unit(value, unit) + " (not from the file); allowed range " + range_text(b.lo, b.hi, unit));
  }
  out_[key] = format_number(value);
}

void SectionReader::read_whole(const char* key, double& value, double lo, double hi, const char* unit,
                               const char* what, Need need) {
  const std::string allowed = "a whole number in " + range_text(lo, hi, unit);
  declare(key);
  note(key, Declaration::Type::whole, 1, &lo, &hi, 0, unit, what);
  if (value_given(key)) {
    const YAML::Node n = get(key);
    double v = 0;
    if (!scalar_number(n, v) || !std::isfinite(v) || v != std::floor(v) || v < lo || v > hi)
      fail(key, "is " + (n.IsScalar() ? n.Scalar() : std::string("not a scalar")) + "; allowed: " + allowed);
    value = v;
  } else if (need == Need::required) {
    missing(key, std::string("missing: ") + what + "; " + allowed);
  } else if (value != std::floor(value) || value < lo || value > hi) {
    fail(key, "is " + format_number(value) + " (not from the file); allowed: " + allowed);
  }
  out_[key] = format_number(value);
}

void SectionReader::flag(const char* key, bool& value, const char* /*what*/) {
  declare(key);
  if (value_given(key)) {
    const YAML::Node n = get(key);
    bool v = false;
    if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v))
      fail(key, "is '" + (n.IsScalar() ? n.Scalar() : std::string("not a scalar")) + "'; allowed values: true, false");
    value = v;
  }
  out_[key] = value ? "true" : "false";
  // A choice of two names, so that a sweep sets it as it sets any named setting.
  note(key, Declaration::Type::choice, 0, nullptr, nullptr, 0, "", "true, false");
}

void SectionReader::text(const char* key, std::string& value, const char* what, Need need) {
  declare(key);
  if (value_given(key)) {
    const YAML::Node n = get(key);
    if (!n.IsScalar()) fail(key, std::string("must be a string: ") + what);
    value = n.Scalar();
  } else if (need == Need::required) {
    missing(key, std::string("missing: ") + what + "; a string");
  }
  out_[key] = value;
}

void SectionReader::texts(const char* key, std::vector<std::string>& values, std::size_t min, const char* what) {
  if (given(key)) values = read_names(key, min, "a list of at least " + std::to_string(min) + " strings (" + what + ")");
  record_names(key, values);
}

void SectionReader::read_list(const char* key, double* values, int n, const double* lo, const double* hi,
                              int stride, const char* unit, const char* what, Need need) {
  declare(key);
  note(key, Declaration::Type::numbers, n, lo, hi, stride, unit, what);
  const bool scalar_bounds = stride == 0;
  const std::string shape = "a list of " + std::to_string(n) + " numbers" +
                            (scalar_bounds ? " in " + range_text(lo[0], hi[0], unit) : std::string());
  if (value_given(key)) {
    const YAML::Node list = get(key);
    if (!list.IsSequence() || static_cast<int>(list.size()) != n) fail(key, "must be " + shape);
    for (int i = 0; i < n; ++i)
      values[i] = to_number(list[i], index_field(field(key), static_cast<std::size_t>(i)), lo[i * stride], hi[i * stride], unit);
  } else if (need == Need::required) {
    missing(key, std::string("missing: ") + what + "; " + shape);
  } else {
    for (int i = 0; i < n; ++i)
      if (!std::isfinite(values[i]) || values[i] < lo[i * stride] || values[i] > hi[i * stride])
        fail_at(mark_of(key), index_field(field(key), static_cast<std::size_t>(i)),
                "is " + with_unit(values[i], unit) + " (not from the file); allowed range " +
                    range_text(lo[i * stride], hi[i * stride], unit));
  }
  YAML::Node seq = flow_sequence();
  for (int i = 0; i < n; ++i) seq.push_back(format_number(values[i]));
  out_[key] = seq;
}

std::size_t SectionReader::begin_rows(const char* key, std::size_t min, std::size_t max, int columns,
                                      const char* /*unit*/, const char* what, Need need) {
  declare(key);
  const std::string shape = "a list of " + std::to_string(min) + ".." + std::to_string(max) + " rows of " +
                            std::to_string(columns) + " numbers";
  out_[key] = YAML::Node(YAML::NodeType::Sequence);
  if (!value_given(key)) {
    if (need == Need::required) missing(key, std::string("missing: ") + what + "; " + shape);
    return kAbsent;
  }
  const YAML::Node list = get(key);
  if (!list.IsSequence() || list.size() < min || list.size() > max) fail(key, "must be " + shape);
  for (std::size_t i = 0; i < list.size(); ++i)
    if (!list[i].IsSequence() || static_cast<int>(list[i].size()) != columns)
      fail(key, i, "must be a list of " + std::to_string(columns) + " numbers");
  return list.size();
}

void SectionReader::read_row(const char* key, std::size_t i, double* values, int n, const double* lo,
                             const double* hi, const char* unit) {
  const YAML::Node row = get(key)[i];
  const std::string name = index_field(field(key), i);
  for (int j = 0; j < n; ++j) values[j] = to_number(row[j], index_field(name, static_cast<std::size_t>(j)), lo[j], hi[j], unit);
  record_row(key, values, n);
}

void SectionReader::record_row(const char* key, const double* values, int n) {
  YAML::Node seq = flow_sequence();
  for (int j = 0; j < n; ++j) seq.push_back(format_number(values[j]));
  YAML::Node list = out_[key];
  list.push_back(seq);
}

std::string SectionReader::scalar(const char* key, const std::string& expected) const {
  const YAML::Node n = get(key);
  if (!n.IsScalar()) fail(key, "must be " + expected);
  return n.Scalar();
}

std::vector<std::string> SectionReader::read_names(const char* key, std::size_t min, const std::string& expected) const {
  const YAML::Node list = get(key);
  if (!list.IsSequence() || list.size() < min) fail(key, "must be " + expected);
  std::vector<std::string> names;
  for (std::size_t i = 0; i < list.size(); ++i) {
    if (!list[i].IsScalar()) fail(key, i, "must be a name");
    names.push_back(list[i].Scalar());
  }
  return names;
}

void SectionReader::record_names(const char* key, const std::vector<std::string>& names) {
  YAML::Node seq = flow_sequence();
  for (const std::string& n : names) seq.push_back(n);
  out_[key] = seq;
}

SectionReader SectionReader::section(const char* key, const char* what, Need need) {
  declare(key);
  const YAML::Node n = get(key);
  if (has(key) && !n.IsMap()) fail(key, std::string("must be a mapping: ") + what);
  if (!has(key) && need == Need::required) fail(key, std::string("missing: ") + what);
  YAML::Node out(YAML::NodeType::Map);
  out_[key] = out;
  return SectionReader(file_, field(key), n, n.IsDefined() ? n.Mark() : mark_, out, document_);
}

std::size_t SectionReader::begin_sections(const char* key, std::size_t min, std::size_t max, const char* what,
                                          Need need) {
  declare(key);
  out_[key] = YAML::Node(YAML::NodeType::Sequence);
  const std::string shape = max == min ? "a list of " + std::to_string(min)
                                       : "a list of " + std::to_string(min) + ".." + std::to_string(max);
  if (!value_given(key)) {
    if (need == Need::required) fail(key, std::string("missing: ") + what + "; " + shape + " entries");
    return 0;
  }
  const YAML::Node list = get(key);
  if (!list.IsSequence() || list.size() < min || list.size() > max) fail(key, "must be " + shape + " entries: " + what);
  return list.size();
}

SectionReader SectionReader::section_item(const char* key, std::size_t i) {
  const YAML::Node n = get(key)[i];
  if (!n.IsMap()) fail(key, i, "must be a mapping");
  YAML::Node out(YAML::NodeType::Map);
  YAML::Node list = out_[key];
  list.push_back(out);
  return SectionReader(file_, index_field(field(key), i), n, n.Mark(), out, document_);
}

void SectionReader::others(const std::vector<std::string>& keys) {
  for (const std::string& k : keys) declare(k.c_str());
}

void SectionReader::finish() const {
  if (!present() || !in_.IsMap()) return;
  std::vector<std::string> seen;
  for (const auto& kv : in_) {
    const std::string key = kv.first.Scalar();
    // YAML forbids a key twice in a mapping; the parser keeps both and a lookup finds the first.
    if (std::find(seen.begin(), seen.end(), key) != seen.end())
      fail_at(kv.first.Mark(), field(key), "given twice in this mapping");
    seen.push_back(key);
    bool known = false;
    for (const std::string& d : declared_) known = known || d == key;
    if (known) continue;
    std::string list;
    for (const std::string& d : declared_) list += (list.empty() ? "" : ", ") + d;
    const std::string near = closest(key, declared_);
    bool near_missing = false;
    for (const PendingMissing& p : pending_) near_missing = near_missing || p.key == near;
    // Thrown here directly: a required key this one misspells is named with it, not as missing.
    const YAML::Mark mark = kv.first.Mark();
    throw SettingsError(file_, mark.line + 1, mark.column + 1, field(key),
                        "unknown key; " +
                            (near.empty() ? std::string()
                                          : "did you mean " + near + "?" +
                                                (near_missing ? " (" + near + " is required and not given)" : "") + " ") +
                            "allowed keys: " + list);
  }
  throw_pending();
}

void merge_effective(YAML::Node into, const YAML::Node& from) {
  if (!from.IsMap()) return;
  for (const auto& kv : from) {
    const std::string key = kv.first.Scalar();
    YAML::Node mine = into[key];
    if (!mine.IsDefined() || mine.IsNull()) {
      into[key] = kv.second;
    } else if (mine.IsMap() && kv.second.IsMap()) {
      merge_effective(mine, kv.second);
    }
  }
}

std::string emit(const YAML::Node& effective) {
  YAML::Emitter out;
  out.SetIndent(2);
  out << effective;
  return std::string(out.c_str()) + "\n";
}

bool finite_number(const YAML::Node& n, double& v) { return scalar_number(n, v) && std::isfinite(v); }

}  // namespace exc::settings
