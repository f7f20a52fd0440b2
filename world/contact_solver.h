#pragma once
/// The sequential-impulse contact solver: friction (Coulomb, two tangents), restitution above
/// a speed threshold, Baumgarte push-out with slop and a speed cap, speculative gaps, warm
/// starting matched by pair, feature and position, optional shock propagation, and a relax
/// pass without push-out. Islands are solved in parallel; a large island colour by colour on
/// every thread. The result does not depend on the thread count.
///
///   solver.prepare(bodies, pairs, pairContacts, flipped, settings, dt, jobs, profiler, stage);
///   islands.build(solver.contacts(), bodies.motion);
///   solver.loadBodies(bodies, jobs, prof); solver.solve(islands, false, ...); solver.storeBodies(bodies, jobs, prof);
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include <oneapi/tbb/cache_aligned_allocator.h>

#include "collision/bricks/contact.h"
#include "collision/core/overwrite_vector.h"
#include "jobs/job_system.h"
#include "jobs/parallel_sort.h"
#include "jobs/profiler.h"
#include "world/body_store.h"
#include "world/broadphase.h"
#include "world/island_lanes.h"
#include "world/islands.h"
#include "world/scene_description.h"
#include "world/solver_contact.h"

namespace bw {

/// Figures of one solve().
struct SolveStats {
  uint32_t largestIsland = 0;  ///< contacts in the largest island
  uint32_t splitIslands = 0;   ///< islands solved colour by colour on every thread
};

class ContactSolver {
 public:
  /// This substep's solver contacts from the pairs' contacts (pair k's normals point from the
  /// pair's a side to its b side unless flipped[k]), with effective masses, biases and the
  /// warm-start impulses of the previous substep. Parallel on jobs (zones at stage: world
  /// inertia per body, stage + 1: contacts per pair, each pair writing its own range;
  /// offsetsStage and offsetsStage + 1, by default stage + 2 and + 3: the pairs' contact
  /// offsets counted and placed per chunk of pairs), the same list in the same order for any
  /// thread count.
  void prepare(const BodyStore& bodies, const std::vector<BodyPair>& pairs, const std::vector<std::vector<Contact>>& pairContacts,
               const std::vector<uint8_t>& flipped, const SceneSettings& settings, float dt, JobSystem& jobs, Profiler& profiler,
               int stage, int offsetsStage = -1);
  std::span<const SolverContact> contacts() const { return contacts_; }
  /// The rest of each contact (warm-start key and point, shock and rolling data), same index.
  std::span<const SolverContactExtras> contactExtras() const { return extras_; }

  /// Copies the bodies' velocities into the solver's compact records, and back (dynamic only).
  /// Copies the bodies' velocities in (and the solved ones back out), in parallel chunks with
  /// zones at `stage`.
  void loadBodies(const BodyStore& bodies, JobSystem& jobs, Profiler& profiler, int stage = -1);
  void storeBodies(BodyStore& bodies, JobSystem& jobs, Profiler& profiler, int stage = -1) const;

  /// Warm start (not when relaxing) and iterate every island: islands above kSplitContacts
  /// first, one at a time, colour by colour on every thread; then the others whole, in
  /// parallel. `relax`: the pass after integration, without push-out; it reuses the colourings
  /// of the solve before it (same islands, same contacts). `stage` is the profiling stage id.
  SolveStats solve(const Islands& islands, const std::vector<MotionType>& motion, bool relax, const SceneSettings& settings,
                   JobSystem& jobs, Profiler& profiler, int stage);

  /// Keeps the contacts' final impulses for the next substep's warm start (after the relax
  /// pass), sorted by pair and feature in parallel: zones at stages `stage` (the copy, with
  /// each pair's contacts sorted when the pairs came in key order) and `stage` + 1 .. `stage` + 4
  /// (the sort of the whole's four steps, when they did not).
  void keepImpulses(JobSystem& jobs, Profiler& profiler, int stage);

 private:
  /// Fewest pairs per job of keepImpulses(): a pair's few contacts copied and sorted.
  static constexpr uint32_t kMinPrepareGrain = 16;
  /// Fewest weight (pairs + contacts) per job of prepare(): a contact costs ~100 ns, so 32 are a
  /// few microseconds; jobs of 32 pairs made crates_on_grid's ~365 pairs 11 jobs of ~12 us
  /// (traced), the stage's span at 16 threads.
  static constexpr uint32_t kMinPrepareWeight = 32;
  /// Fewest contacts per job of islands solved whole: one job per island made city_rain's ~280
  /// islands a frame ~280 jobs of ~1.6 us each (traced), a tenth of the stage's wall time in
  /// job overhead on one thread.
  static constexpr uint32_t kMinIslandJobContacts = 32;
  /// Fewest bodies per job copying a split island's bodies to its slots and back (~64 bytes each).
  static constexpr uint32_t kMinSlotCopyGrain = 256;
  using CacheRange = std::pair<OverwriteVector<CachedImpulse>::const_iterator, OverwriteVector<CachedImpulse>::const_iterator>;
  void makeContact(const BodyStore& bodies, const BodyPair& pair, uint32_t a, uint32_t b, const Contact& c, CacheRange cached,
                   const SceneSettings& settings, float dt, SolverContact& s, SolverContactExtras& x) const;
  // On the bodies' records (bodies_), or on the given records (a coloured island's slots).
  void warmStart(const SolverContact& s) { warmStart(s, bodies_[s.a], bodies_[s.b]); }
  void warmStart(const SolverContact& s, SolverBody& a, SolverBody& b);
  void solveContact(uint32_t k, bool relax) { solveContact(k, relax, bodies_[contacts_[k].a], bodies_[contacts_[k].b]); }
  void solveContact(uint32_t k, bool relax, SolverBody& a, SolverBody& b);
  void solveContactShock(uint32_t k);
  void shockSweep(std::vector<uint32_t>& contacts);
  void solveIsland(std::span<const uint32_t> island, bool relax, const SceneSettings& settings);
  void solveIslandsInLanes(const Islands& islands, std::span<const uint32_t> which, bool relax, const SceneSettings& settings);
  // `wave` numbers the island's waves (colours and serial steps, each a dependent step of
  // the solve) across the islands of one solve, for their profiling stages.
  // `colouring` is the island's colouring, made here unless `coloured` (the relax pass reuses
  // the solve's).
  void solveIslandInColours(std::span<const uint32_t> island, uint32_t split, bool coloured,
                            const std::vector<MotionType>& motion, bool relax, const SceneSettings& settings,
                            JobSystem& jobs, Profiler& profiler, int stage, uint32_t& wave);
  // The islands solve() splits by colour, and the jobs of the others (splitIslands_ ...).
  void planIslands(const Islands& islands);
  // Contact i's impulses as the cache keeps them.
  CachedImpulse cachedImpulse(uint32_t i) const;

  // A cached impulse's pair against a pair key (the cache's first order).
  struct PairOrder {
    bool operator()(const CachedImpulse& x, uint64_t key) const { return x.pairKey < key; }
    bool operator()(uint64_t key, const CachedImpulse& x) const { return key < x.pairKey; }
  };
  // The cache's order: pair, feature, then the contact's index (what a stable sort by pair and
  // feature gives, as a strict total order the parallel sort needs).
  struct CacheOrder {
    bool operator()(const CachedImpulse& x, const CachedImpulse& y) const {
      return x < y || (!(y < x) && x.contact < y.contact);
    }
  };

  // Sized by prepare() and written whole by its jobs (collision/core/overwrite_vector.h).
  OverwriteVector<SolverContact> contacts_;
  OverwriteVector<SolverContactExtras> extras_;  // beside contacts_, same index
  std::vector<SolverBody> bodies_;
  // A coloured island's bodies in its colouring's slots while its waves run (on line pairs of
  // their own: IslandColouring::kSlotsApart).
  std::vector<SolverBody, tbb::cache_aligned_allocator<SolverBody>> slots_;
  std::vector<Mat3f> inverseInertiaWorld_;  // per body, this substep
  std::vector<uint32_t> first_;             // prepare(): pair k's contacts start at first_[k]
  bool pairsInKeyOrder_ = false;            // prepare(): its pairs with contacts in strictly increasing key order
  OverwriteVector<CachedImpulse> cache_, nextCache_;  // nextCache_ written whole by keepImpulses()
  // planIslands(): the islands split by colour (in island order), those solved whole in
  // parallel, the largest island's contacts; solve() makes the plan, its relax pass reuses it.
  std::vector<uint32_t> splitIslands_;
  std::vector<uint32_t> smallIslands_;
  uint32_t largestIsland_ = 0;
  std::vector<uint32_t> islandJobStart_;    // where each job's run of smallIslands_ starts (and the end)
  std::vector<uint32_t> prepareJobStart_;   // prepare(): the first pair of each job (and the end)
  /// prepare()'s offsets per chunk of pairs: their contacts (once summed, the chunk's first
  /// contact), whether the chunk's pairs with contacts are in strictly increasing key order, its
  /// first and last such key.
  struct OffsetChunk {
    uint32_t contacts = 0;
    bool inOrder = true, any = false;
    uint64_t firstKey = 0, lastKey = 0;
  };
  std::vector<OffsetChunk> offsetChunks_;
  // The colourings of this substep's split islands, in solve order; valid for the relax pass
  // once the solve has made them (coloured_; prepare() resets it).
  std::vector<IslandColouring> colourings_;
  // Their colours in rows of IslandLanes (a row: kLanes contacts of one colour), same index; where
  // each colour's rows start (the serial group has none).
  std::vector<IslandLanes::Rows> colourRows_;
  std::vector<std::vector<uint32_t>> colourRowStart_;
  // A split island's waves (kept from call to call: no allocation in a steady state).
  struct ColourWave {
    uint32_t colour;
    int32_t stageId;
    bool warmStart;
    uint32_t chunkSize;    // contacts per chunk
    bool fill, writeBack;  // lanes: the colour's rows laid out before the wave, its impulses back after
  };
  std::vector<ColourWave> waves_;
  std::vector<uint32_t> waveChunks_;
  bool coloured_ = false;
  ParallelSorter<CachedImpulse, CacheOrder> cacheSorter_;
  std::vector<uint8_t> cacheChunkSorted_;  // keepImpulses: per copy chunk, already in order
};

}  // namespace bw
