#include "summary_moments.hpp"

#include <nlohmann/json.hpp>

#include <fstream>

namespace exc::log {

namespace {

// The longest run excavator-sim takes is 28,800 s; a summary's time beyond this is damaged.
constexpr double kLatestMoment = 1e6;

}  // namespace

bool read_summary_moments(const std::string& path, std::map<std::string, std::vector<double>>* moments,
                          std::string* error) {
  moments->clear();
  std::ifstream in(path);
  if (!in) {
    *error = path + ": cannot read the summary";
    return false;
  }
  nlohmann::json summary;
  try {
    in >> summary;
  } catch (const nlohmann::json::exception& e) {
    *error = path + ": not a JSON summary (" + e.what() + ")";
    return false;
  }
  if (!summary.is_object()) return true;
  for (const auto& [controller, run] : summary.items()) {
    if (!run.is_object() || !run.contains("phases") || !run["phases"].is_object()) continue;
    for (const auto& [phase, figures] : run["phases"].items()) {
      if (!figures.is_object() || !figures.contains("worst_time")) continue;  // null: the run was never in it
      const nlohmann::json& times = figures["worst_time"];
      if (!times.is_object()) {
        *error = path + ": " + controller + ".phases." + phase + ".worst_time: not an object of seconds per joint";
        return false;
      }
      for (const auto& [joint, t] : times.items()) {
        const std::string field = controller + ".phases." + phase + ".worst_time." + joint;
        if (!t.is_number()) {
          *error = path + ": " + field + ": not a number (s of the run, or -1 for none)";
          return false;
        }
        const double s = t.get<double>();
        if (s == -1.0) continue;
        if (!(s >= 0.0 && s <= kLatestMoment)) {
          *error = path + ": " + field + ": " + t.dump() + " is outside 0 .. 1e6 s (or -1 for none)";
          return false;
        }
        (*moments)[controller].push_back(s);
      }
    }
  }
  return true;
}

}  // namespace exc::log
