#pragma once
/// The world's body-level broadphase: pairs kept from frame to frame over fattened boxes, found
/// anew only for the proxies that moved (box2d v3's move buffer, with a deterministic merge).
///
/// Each moving proxy (dynamic, kinematic or asleep) owns a fat box: its bounds grown by
/// tuning::kFatMargin and stretched ahead along its last displacement (tuning::kFatPrediction).
/// While its bounds stay inside, the proxy costs one containment test a frame. One that leaves
/// (or is new, or whose box is far looser than its motion now needs) gets a new fat box; its
/// leaf in a DynamicBoundsTree keeps its place when a couple of ancestors grown can hold the new
/// box, else is moved; when many proxies moved (tuning::kFatRebuildShare), or the ancestors grown
/// since the last build outnumber the leaves, the tree is built again in bulk and its pairs with
/// a moved proxy found by the tree against itself. Moved proxies query the tree and the static
/// proxies' StaticBoundsTree in parallel chunks. The kept pair lists, sorted, drop the pairs of
/// proxies that moved and take the new ones in a merge. Every frame the kept pairs are filtered
/// by the proxies' current bounds, so the output is exactly the overlapping pairs, the same as
/// SweepAndPrune's (which the bench and tests compare it with).
///
/// Why, measured in bench_world Broadphase/* at 1k-1M bodies against Bullet's tuned
/// btDbvtBroadphase and the previous SweepAndPrune (profiles/RESULTS.md, session 17): a sweep
/// and prune finds every pair every frame, where most proxies in a scene rest or move less than
/// their margin; the dbvt, which keeps its pairs, beat the sweep at 1k and 10k.
///
/// Identity: a moving proxy is known across frames by its owner (owner[i], or i without
/// owners), so each owner may have one moving proxy; static proxies (any number per owner: a
/// grid's cover boxes) are compared with the last frame's bit for bit, and any change rebuilds
/// the static tree and the static pairs.
/// Determinism: the output is sorted by (a, b) with a < b, without repeats, and depends only on
/// the bounds; the trees depend on the sequence of updates, never on the thread count.
/// Thread safety: one update() at a time (its stages run on a JobSystem when given one).
#include <cstdint>
#include <memory>
#include <vector>

#include "jobs/job_system.h"
#include "jobs/parallel_sort.h"
#include "jobs/profiler.h"
#include "world/broadphase.h"
#include "world/dynamic_bounds_tree.h"

namespace bw {

class IncrementalBroadphase {
 public:
  /// Profiler stages update() uses, from its `stage` argument on.
  static constexpr int kStages = 23 + DynamicBoundsTree::kBuildStages + DynamicBoundsTree::kSelfPairStages;

  IncrementalBroadphase();
  ~IncrementalBroadphase();
  IncrementalBroadphase(IncrementalBroadphase&&) noexcept;
  IncrementalBroadphase& operator=(IncrementalBroadphase&&) noexcept;

  /// Finds overlapping pairs among proxies (bounds[i] belongs to proxy i; isStatic[i] proxies
  /// never pair with each other). Replaces `pairs`. With `owner` (one entry per proxy), the
  /// pairs are of owners: (owner[i], owner[j]) for overlapping proxies i and j of different
  /// owners, each pair once. Throws InvalidInput, nothing changed, for non-finite or inverted
  /// bounds (naming the proxy), mismatched lengths, an owner with two moving proxies, or an
  /// owner id of 2^26 or more (per-owner state is kept in arrays indexed by it).
  /// With jobs, the stages run in chunks on it (the same pairs for any thread count); with a
  /// profiler, zones at stage .. stage + kStages - 1.
  void update(const std::vector<WorldAabb>& bounds, const std::vector<uint8_t>& isStatic, std::vector<BodyPair>& pairs,
              JobSystem* jobs = nullptr, Profiler* profiler = nullptr, int stage = -1,
              const std::vector<uint32_t>* owner = nullptr);

  /// Box tests of the last update: tree queries (or a bulk frame's tree against itself) and the
  /// kept pairs' bounds tests.
  uint64_t lastTests() const { return tests_; }
  /// Moving proxies that got a new fat box in the last update (left it, new, or far too loose).
  uint32_t lastMoved() const { return movedCount_; }
  /// Pairs of fat boxes kept after the last update (moving-moving and moving-static proxies).
  uint64_t fatPairs() const { return mm_.size() + ms_.size(); }
  /// Times the static tree was built (first update, and after static boxes changed).
  uint64_t staticBuilds() const { return staticBuilds_; }
  /// Times the moving proxies' tree was built in bulk (first update, and many moves at once).
  uint64_t movingBuilds() const { return movingBuilds_; }
  /// The moving proxies' tree (tests check its structure).
  const DynamicBoundsTree& movingTree() const { return tree_; }

 private:
  /// A moving proxy's fat box against a static proxy, filed under the pair of owners it makes,
  /// so the static pairs come out of the bounds filter in the output's order.
  struct StaticPair {
    BodyPair owners;  // the moving key and the static slot's owner, smaller first
    uint32_t key;     // the moving proxy's key
    uint32_t slot;    // the static proxy's slot
    bool operator<(const StaticPair& o) const { return owners < o.owners || (owners == o.owners && slot < o.slot); }
  };

  template <class F>
  void forChunks(uint32_t n, uint32_t grain, int stage, const char* zone, F&& body);
  void gather(const std::vector<WorldAabb>& bounds, const std::vector<uint8_t>& isStatic, const std::vector<uint32_t>* owner);
  bool rebuildStatics(const std::vector<WorldAabb>& bounds, const std::vector<uint32_t>* owner);
  void fatten(const std::vector<WorldAabb>& bounds);
  bool editTree(bool staticChanged);
  bool moveLeaves();
  void findNewPairs(bool staticChanged, bool bulk);
  void keepPairs(bool staticChanged);
  void tightPairs(const std::vector<WorldAabb>& bounds, std::vector<BodyPair>& pairs);
  // Concatenates per-chunk lists in chunk order into `out`, in parallel.
  template <class T>
  void join(std::vector<std::vector<T>>& chunks, uint32_t count, std::vector<T>& out, int stage, const char* zone);

  JobSystem* jobs_ = nullptr;     // of the running update
  Profiler* profiler_ = nullptr;  // of the running update
  int stage_ = -1;
  uint64_t tests_ = 0;
  uint32_t movedCount_ = 0;
  uint64_t staticBuilds_ = 0, movingBuilds_ = 0, grownSinceBuild_ = 0;

  // Per key (a moving proxy's owner): the proxy this frame, the frame it was last seen, its
  // leaf in tree_, its fat box, its bounds' centre last frame, whether it moved this frame.
  std::vector<uint32_t> proxy_, seen_, leaf_;
  std::vector<WorldAabb> fat_;
  std::vector<Vec3d> centre_;
  std::vector<uint8_t> moved_;
  uint32_t frame_ = 0;
  std::vector<uint32_t> keys_, lastKeys_, removed_, movedKeys_;
  // gather()'s chunks: (key, proxy) of each moving proxy, and what the scan found.
  struct ChunkScan {
    uint32_t largest = 0;
    bool ascending = true, bad = false, staticChanged = false;
  };
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> chunkKeys_;
  std::vector<std::vector<uint32_t>> chunkStatics_;  // the static proxies of each chunk
  std::vector<uint32_t> staticStart_;                // each chunk's first static slot
  std::vector<std::pair<uint32_t, uint32_t>> sortedKeys_;
  std::vector<ChunkScan> chunkScan_;
  bool mixedOwners_ = false;
  std::vector<uint32_t> spatial_, movedOrder_;  // keys in leaf order: all of them, the moved ones
  std::vector<uint64_t> byLeaf_;
  std::vector<std::vector<uint32_t>> chunkMoved_;
  DynamicBoundsTree tree_;
  std::vector<WorldAabb> buildBoxes_;
  std::vector<uint32_t> buildLeaves_;

  // Static proxies: their ids, boxes and owners, by slot (the static tree's payload).
  std::vector<uint32_t> staticIds_, staticOwner_, slots_;
  std::vector<WorldAabb> staticBoxes_;
  std::unique_ptr<StaticBoundsTree> staticTree_;

  // Fat pairs, sorted: of moving keys (a < b), and of a moving key with a static slot.
  std::vector<BodyPair> mm_, newMm_, keptMm_, mergedMm_, outMm_, outMs_;
  std::vector<StaticPair> ms_, newMs_, keptMs_, mergedMs_;
  std::vector<std::vector<BodyPair>> chunkA_, chunkB_;
  std::vector<std::vector<StaticPair>> chunkS_;
  std::vector<uint64_t> chunkTests_;
  std::vector<size_t> chunkOffset_;
  ParallelSorter<BodyPair> sorter_;
  ParallelSorter<StaticPair> staticSorter_;
};

}  // namespace bw
