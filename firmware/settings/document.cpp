#include "settings/document.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace exc::settings {

Document Document::load(const std::string& path) {
  // A directory opens as a stream that reads nothing: it would pass for an empty file.
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw SettingsError(path, 0, 0, "", "is a directory, not a file");
  std::ifstream in(path);
  if (!in) throw SettingsError(path, 0, 0, "", "cannot open the file");
  std::ostringstream text;
  text << in.rdbuf();
  const auto slash = path.find_last_of('/');
  return parse(text.str(), path, slash == std::string::npos ? "." : path.substr(0, slash));
}

Document Document::parse(const std::string& text, const std::string& file, const std::string& directory) {
  Document d;
  d.file_ = file;
  d.directory_ = directory;
  d.text_ = text;
  try {
    d.root_ = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw SettingsError(file, e.mark.line + 1, e.mark.column + 1, "", "not valid YAML: " + e.msg);
  }
  return d;
}

std::string Document::resolve(const std::string& path) const {
  namespace fs = std::filesystem;
  const fs::path p(path);
  return (p.is_absolute() ? p : fs::absolute(fs::path(directory_) / p)).lexically_normal().string();
}

Document Document::with_root(const YAML::Node& root) const {
  Document d = *this;
  d.root_.reset(root);  // rebinds the copy's handle (assigning would overwrite this document's tree)
  d.declarations_ = std::make_shared<std::vector<Declaration>>();
  return d;
}

void Document::declare(Declaration d) const {
  if (declaration(d.field) == nullptr) declarations_->push_back(std::move(d));
}

const Declaration* Document::declaration(const std::string& field) const {
  for (const Declaration& d : *declarations_)
    if (d.field == field) return &d;
  return nullptr;
}

}  // namespace exc::settings
