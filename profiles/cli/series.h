#pragma once
// Per-frame figures of a run and their quantiles (shared by the run, sweep and render reports).
#include <algorithm>
#include <vector>

#include <nlohmann/json.hpp>

namespace bw::cli {

/// One value per frame.
struct Series {
  std::vector<double> v;
  double quantile(double q) const {
    if (v.empty()) return 0;
    std::vector<double> s = v;
    std::sort(s.begin(), s.end());
    return s[std::min(s.size() - 1, size_t(q * double(s.size() - 1) + 0.5))];
  }
  double max() const { return v.empty() ? 0 : *std::max_element(v.begin(), v.end()); }
  double sum() const {
    double t = 0;
    for (double x : v) t += x;
    return t;
  }
  /// {"median_ms", "p95_ms", "max_ms"}.
  nlohmann::json json() const { return {{"median_ms", quantile(0.5)}, {"p95_ms", quantile(0.95)}, {"max_ms", max()}}; }
};

}  // namespace bw::cli
