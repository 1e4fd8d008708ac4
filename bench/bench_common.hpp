#pragma once
// What every chart of excavator-bench shares: the integrators it sweeps, their names and settings,
// progress lines, and small statistics.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sim_plant/integration_methods.hpp"

namespace exc::bench {

using nlohmann::json;

// Numbers that may be absent (a failed run, a skipped peer) go to JSON as null, never NaN.
inline json number_or_null(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

inline double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// Calls timed together in thread CPU time (a clock read costs ~0.3 us).
constexpr int kBatch = 10;

inline void progress(const char* format, const std::string& a, const std::string& b = "") {
  std::fprintf(stderr, format, a.c_str(), b.c_str());
  std::fflush(stderr);
}

inline std::string step_label(double h) {
  char buf[32];
  if (h >= 1e-3) std::snprintf(buf, sizeof buf, "%g ms", h * 1e3);
  else std::snprintf(buf, sizeof buf, "%g us", h * 1e6);
  return buf;
}

// The methods swept: every registered one (a method added is charted by itself).
inline std::vector<std::string> bench_methods() { return plant::integration_methods().name_list(); }
constexpr plant::Formulation kFormulations[] = {plant::Formulation::independent,
                                                plant::Formulation::augmented_baumgarte,
                                                plant::Formulation::augmented_projection};

inline std::string method_name(const std::string& m, plant::Formulation f) { return m + "/" + plant::to_string(f); }

inline plant::IntegratorSettings settings_of(const std::string& m, plant::Formulation f, double h) {
  plant::IntegratorSettings s;
  s.method = m;
  s.formulation = f;
  s.step = h;
  return s;
}

}  // namespace exc::bench
