#pragma once
// A settings file read and parsed once: its text, its YAML tree (every node knows its line and
// column) and the directory its relative paths resolve against. Errors (cannot open, YAML syntax)
// are SettingsErrors naming the file, and for syntax the line and column.
#include <string>

#include <yaml-cpp/yaml.h>

#include "settings/settings_error.hpp"

namespace exc::settings {

class Document {
 public:
  // Opens and parses the file (once).
  static Document load(const std::string& path);
  // Parses text; `file` is what errors name, `directory` where relative paths resolve.
  static Document parse(const std::string& text, const std::string& file, const std::string& directory = ".");

  const std::string& file() const { return file_; }
  const std::string& directory() const { return directory_; }
  const std::string& text() const { return text_; }
  const YAML::Node& root() const { return root_; }
  // A path named in the file, made absolute against the file's directory (an absolute one as it is).
  std::string resolve(const std::string& path) const;

 private:
  std::string file_, directory_, text_;
  YAML::Node root_;
};

}  // namespace exc::settings
