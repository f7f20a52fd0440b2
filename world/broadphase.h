#pragma once
/// Body-level broadphase: which bodies' world bounds overlap.
///
/// Choice: sweep and prune on the axis of largest spread, with the sorted order kept from
/// frame to frame (insertion sort is near-linear when bodies move a little per step); the
/// first frame, and any frame whose insertion sort would exceed ~8 moves per body, sorts in
/// bulk instead (O(n log n): no quadratic first frame). Bodies
/// are few (thousands) next to the bricks inside grids, which never pay a per-frame index
/// update here: a grid is one box in this list. Pairs of two static bodies are skipped.
///
/// Determinism: the output is sorted by (a, b) with a < b, and does not depend on the previous
/// order or on thread count.
/// Thread safety: one update() at a time (it may run its chunks on a JobSystem).
#include <cstdint>
#include <utility>
#include <vector>

#include "collision/core/math_types.h"
#include "jobs/job_system.h"
#include "jobs/profiler.h"

namespace bw {

/// World-space bounds of a body (double, per the precision rule).
struct WorldAabb {
  Vec3d min;
  Vec3d max;
  bool overlaps(const WorldAabb& o) const {
    return min.x() <= o.max.x() && o.min.x() <= max.x() && min.y() <= o.max.y() && o.min.y() <= max.y() &&
           min.z() <= o.max.z() && o.min.z() <= max.z();
  }
};

/// A candidate pair of bodies, a < b.
struct BodyPair {
  uint32_t a, b;
  bool operator<(const BodyPair& o) const { return a < o.a || (a == o.a && b < o.b); }
  bool operator==(const BodyPair& o) const = default;
};

class SweepAndPrune {
 public:
  /// Finds overlapping pairs among bodies (bounds[i] belongs to body i; isStatic[i] bodies never
  /// pair with each other). Replaces `pairs`. Throws InvalidInput for non-finite or inverted
  /// bounds, naming the body.
  /// With jobs, the sorted copy and the sweep run in chunks on it (the same pairs for any thread
  /// count); with a profiler, zones at stage (sort, serial), stage + 1 (sorted copy), stage + 2
  /// (sweep) and stage + 3 (pairs joined and sorted, serial).
  void update(const std::vector<WorldAabb>& bounds, const std::vector<uint8_t>& isStatic, std::vector<BodyPair>& pairs,
              JobSystem* jobs = nullptr, Profiler* profiler = nullptr, int stage = -1);
  /// Interval comparisons made by the last update (machine-independent cost).
  uint64_t lastTests() const { return tests_; }

 private:
  void sortInBulk(const std::vector<WorldAabb>& bounds);
  template <class F>
  void forChunks(uint32_t n, int stage, const char* zone, F&& body);

  /// Bodies per chunk of the sorted copy and the sweep.
  static constexpr uint32_t kSweepGrain = 1024;
  JobSystem* jobs_ = nullptr;      // of the running update
  Profiler* profiler_ = nullptr;   // of the running update
  std::vector<std::vector<BodyPair>> chunkPairs_;  // the sweep's pairs per chunk, reused
  std::vector<uint64_t> chunkTests_;

  std::vector<uint32_t> order_;  // body ids sorted by min on axis_, kept between frames
  std::vector<std::pair<double, uint32_t>> keys_;  // sortInBulk scratch
  // The bounds in that order, copied each update: the sweep then reads memory in order instead
  // of jumping through order_ (the pile of a landing rain overlaps dozens of bodies per body).
  struct Sorted {
    double lo, hi;                // on axis_
    double lo1, hi1, lo2, hi2;    // on the two other axes
    uint32_t body;
    uint8_t isStatic;
  };
  std::vector<Sorted> sorted_;
  int axis_ = 0;
  uint64_t tests_ = 0;
};

}  // namespace bw
