#pragma once
/// Body-level broadphase types (bounds, pairs, the input check) and SweepAndPrune, the world's
/// broadphase until session 17, kept as the reference every frame of IncrementalBroadphase (the
/// world's now) is checked against in bench_world and the tests, and as a bench row.
///
/// SweepAndPrune: moving proxies (dynamic and kinematic) sit in a sweep and prune on the axis
/// of largest spread, the sorted order kept from frame to frame (insertion sort is near-linear
/// when bodies move a little per step; the first frame, a changed set of moving proxies, or a
/// frame whose insertion sort would exceed ~8 moves per body sorts in bulk, in parallel: no
/// quadratic first frame). Static proxies never enter the sweep: they sit in a tree built in
/// bulk (StaticBoundsTree), rebuilt only when a static box changes, and every moving proxy
/// queries it. Every pair is found anew every frame, per moving proxy in parallel chunks, each
/// chunk writing its own list; the lists are joined in chunk order and sorted.
///
/// Why it was replaced, measured in bench_world Broadphase/* (profiles/RESULTS.md, sessions 7
/// and 17): it beat Bullet's tuned btDbvtBroadphase on first frames and at 1M, but lost steady
/// frames at 1k and 10k (2.4x and 1.6x), where the dbvt keeps its pairs between frames.
///
/// Determinism: the output is sorted by (a, b) with a < b, without repeats, and does not depend
/// on the previous order or on thread count.
/// Thread safety: one update() at a time (it runs its chunks on a JobSystem when given one).
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "collision/core/math_types.h"
#include "jobs/job_system.h"
#include "jobs/parallel_sort.h"
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

class StaticBoundsTree;

/// Checks a broadphase's input: one static flag (and owner) per proxy, finite bounds with
/// min <= max. Throws InvalidInput naming `who` and the proxy.
void validateProxies(const std::vector<WorldAabb>& bounds, const std::vector<uint8_t>& isStatic, const std::vector<uint32_t>* owner,
                     const char* who);

class SweepAndPrune {
 public:
  /// Profiler stages update() uses, from its `stage` argument on.
  static constexpr int kStages = 13;

  SweepAndPrune();
  ~SweepAndPrune();
  SweepAndPrune(SweepAndPrune&&) noexcept;
  SweepAndPrune& operator=(SweepAndPrune&&) noexcept;

  /// Finds overlapping pairs among proxies (bounds[i] belongs to proxy i; isStatic[i] proxies
  /// never pair with each other). Replaces `pairs`. With `owner` (one entry per proxy), the
  /// pairs are of owners: (owner[i], owner[j]) for overlapping proxies i and j of different
  /// owners, each pair once. Throws InvalidInput for non-finite or inverted bounds, naming the
  /// proxy, or mismatched lengths.
  /// With jobs, the stages run in chunks on it (the same pairs for any thread count); with a
  /// profiler, zones at stage (order, serial), stage + 1..4 (bulk sort, when it runs),
  /// stage + 5 (sorted copy), stage + 6 (sweep costs), stage + 7 (sweep and static queries),
  /// stage + 8 (join) and stage + 9..12 (pairs sorted).
  void update(const std::vector<WorldAabb>& bounds, const std::vector<uint8_t>& isStatic, std::vector<BodyPair>& pairs,
              JobSystem* jobs = nullptr, Profiler* profiler = nullptr, int stage = -1,
              const std::vector<uint32_t>* owner = nullptr);
  /// Interval and box comparisons made by the last update (machine-independent cost).
  uint64_t lastTests() const { return tests_; }
  /// Times the static tree was built (first update, and after static boxes changed).
  uint64_t staticBuilds() const { return staticBuilds_; }

 private:
  bool staticSetChanged(const std::vector<WorldAabb>& bounds, const std::vector<uint8_t>& isStatic);
  bool insertionSort(const std::vector<WorldAabb>& bounds, const std::vector<uint8_t>& isStatic);
  void sortInBulk(const std::vector<WorldAabb>& bounds, int stage);
  template <class F>
  void forChunks(uint32_t n, uint32_t grain, int stage, const char* zone, F&& body);
  void sortPairs(std::vector<BodyPair>& pairs, int stage);

  /// Fewest moving proxies per chunk of the sorted copy and the sweep costs.
  static constexpr uint32_t kMinSweepGrain = 128;
  /// The sweep's cost model, in interval tests: a job gets at least kMinSweepJobCost (a test is
  /// about a nanosecond, a job's scheduling about a microsecond).
  static constexpr uint64_t kMinSweepJobCost = 1024;
  JobSystem* jobs_ = nullptr;      // of the running update
  Profiler* profiler_ = nullptr;   // of the running update
  std::vector<std::vector<BodyPair>> chunkPairs_;  // the sweep's pairs per chunk, reused
  std::vector<uint64_t> chunkTests_, chunkTreeTests_;
  uint64_t queryTestsPerProxy_ = 8;  // static tree box tests per moving proxy, last update
  std::vector<uint32_t> chunkOffset_;
  std::vector<uint64_t> costPrefix_, chunkCost_;  // sweep costs: per proxy (prefix within its chunk), per chunk
  std::vector<uint32_t> jobBegin_;                // first sorted proxy of each sweep job

  std::vector<uint32_t> moving_;  // moving proxy ids, ascending (scratch)
  std::vector<uint32_t> order_;   // moving proxy ids sorted by (min on axis_, id), kept between frames
  std::vector<std::pair<double, uint32_t>> keys_;  // bulk sort: (min on the axis, id)
  ParallelSorter<std::pair<double, uint32_t>> keySorter_;
  ParallelSorter<BodyPair> pairSorter_;
  // The bounds in that order, copied each update: the sweep then reads memory in order instead
  // of jumping through order_ (the pile of a landing rain overlaps dozens of bodies per body).
  struct Sorted {
    double lo, hi;                // on axis_
    double lo1, hi1, lo2, hi2;    // on the two other axes
    uint32_t proxy;
  };
  std::vector<Sorted> sorted_;
  int axis_ = 0;
  uint64_t tests_ = 0;

  // The static proxies the tree was built over (ids and boxes), to see when they change.
  std::vector<uint32_t> staticIds_, staticScratch_;
  std::vector<WorldAabb> staticBoxes_;
  std::unique_ptr<StaticBoundsTree> staticTree_;
  uint64_t staticBuilds_ = 0;
};

}  // namespace bw
