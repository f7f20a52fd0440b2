#pragma once
/// A small, fully specified random generator (splitmix64) so workloads are identical on every
/// platform and standard library (std:: distributions are implementation-defined).
#include <cmath>
#include <cstdint>

#include "collision/core/hash.h"

namespace bw {

class SeededRandom {
 public:
  explicit SeededRandom(uint64_t seed) : state_(seed * kGoldenGamma + 0x632BE59BD9B4E019ull) {}
  uint64_t next() {
    const uint64_t out = splitmix64(state_);
    state_ += kGoldenGamma;
    return out;
  }
  /// Uniform in [0, 1).
  double unit() { return double(next() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * unit(); }
  /// Log-uniform in [lo, hi): as many small values per decade as large ones.
  double logUniform(double lo, double hi) { return lo * std::exp(std::log(hi / lo) * unit()); }
  /// Uniform integer in [0, n).
  uint32_t below(uint32_t n) { return uint32_t((next() >> 32) * n >> 32); }
  /// Standard normal (Box-Muller).
  double normal() {
    const double u = unit() + 1e-300, v = unit();
    return std::sqrt(-2.0 * std::log(u)) * std::cos(6.283185307179586 * v);
  }

 private:
  uint64_t state_;
};

}  // namespace bw
