#pragma once
// A settings file read and parsed once: its text, its YAML tree (every node knows its line and
// column), the directory its relative paths resolve against, and the declarations of the fields its
// readers have read from it. Errors (cannot open, YAML syntax) are SettingsErrors naming the file,
// and for syntax the line and column.
#include <memory>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "settings/declaration.hpp"
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
  // The same file with another tree (the file's settings with some values set: a sweep's case); its
  // text stays the file's, its declarations start empty.
  Document with_root(const YAML::Node& root) const;

  // Every field a reader has read from this document, as the reader declared it (the first of a field
  // read twice), in reading order.
  const std::vector<Declaration>& declarations() const { return *declarations_; }
  // Records a declaration (the settings reader does, as it reads).
  void declare(Declaration declaration) const;
  const Declaration* declaration(const std::string& field) const;  // null: never read

 private:
  std::string file_, directory_, text_;
  YAML::Node root_;
  std::shared_ptr<std::vector<Declaration>> declarations_ = std::make_shared<std::vector<Declaration>>();
};

}  // namespace exc::settings
