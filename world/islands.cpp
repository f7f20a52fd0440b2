#include "world/islands.h"

#include <algorithm>
#include <atomic>
#include <bit>

#include "collision/core/ids.h"
#include "collision/core/morton.h"
#include "world/world_tuning.h"

namespace bw {

uint32_t Islands::find(uint32_t x) {
  while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
  return x;
}

namespace {

uint32_t loadParent(std::vector<uint32_t>& parent, uint32_t x) {
  return std::atomic_ref<uint32_t>(parent[x]).load(std::memory_order_relaxed);
}

// The root of x while other threads link roots (every link goes from a root to a smaller root,
// so the walk ends).
uint32_t findConcurrent(std::vector<uint32_t>& parent, uint32_t x) {
  for (uint32_t p = loadParent(parent, x); p != x; p = loadParent(parent, x)) x = p;
  return x;
}

// The same, halving the path as it goes: each body on it is pointed at its grandparent, which
// stays one of its ancestors whatever other threads link (links only hang a root under a
// smaller root, and only roots are linked, never a body written here).
uint32_t findHalving(std::vector<uint32_t>& parent, uint32_t x) {
  for (;;) {
    const uint32_t p = loadParent(parent, x);
    if (p == x) return x;
    const uint32_t g = loadParent(parent, p);
    if (g != p) std::atomic_ref<uint32_t>(parent[x]).store(g, std::memory_order_relaxed);
    x = g;
  }
}

}  // namespace

void Islands::build(std::span<const SolverContact> contacts, const std::vector<MotionType>& motion, JobSystem& jobs,
                    Profiler& profiler, int stage) {
  const uint32_t n = uint32_t(motion.size());
  parent_.resize(n);
  for (uint32_t i = 0; i < n; ++i) parent_[i] = i;
  contactBody_.resize(contacts.size());
  // Union-find over the contacts in parallel: a link always hangs the larger of two roots under
  // the smaller (compare-and-swap on the larger, which must still be a root), so every island's
  // root is its smallest body id whatever the order the links were made in: the grouping is a
  // pure function of the contact list, for any thread count. The finds halve their paths
  // (crate_pile's one big pile: the stage's work -33% on one thread).
  jobs.parallelFor(0, uint32_t(contacts.size()), tuning::grainFor(uint32_t(contacts.size()), tuning::kMinIslandGrain), [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler, "islands: union", stage);
    for (uint32_t k = begin; k < end; ++k) {
      const SolverContact& c = contacts[k];
      contactBody_[k] = motion[c.a] == MotionType::Dynamic ? c.a : c.b;
      if (motion[c.a] != MotionType::Dynamic || motion[c.b] != MotionType::Dynamic) continue;
      for (;;) {
        uint32_t ra = findHalving(parent_, c.a), rb = findHalving(parent_, c.b);
        if (ra == rb) break;
        if (ra > rb) std::swap(ra, rb);
        uint32_t expected = rb;
        if (std::atomic_ref<uint32_t>(parent_[rb]).compare_exchange_strong(expected, ra, std::memory_order_relaxed)) break;
      }
    }
  });
  // Every body points straight at its root (after the join, so no link is still being made).
  jobs.parallelFor(0, n, tuning::bodyGrain(n), [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler, "islands: flatten", stage + 1);
    for (uint32_t i = begin; i < end; ++i) std::atomic_ref<uint32_t>(parent_[i]).store(findConcurrent(parent_, i), std::memory_order_relaxed);
  });
}

void Islands::groupContacts(JobSystem& jobs, Profiler& profiler, int stage) {
  // Contacts grouped by the island of their dynamic body, islands ordered by root id, contacts
  // in contact order within one (CSR): a sort of (root, contact) keys, which are unique, so
  // the grouping is the same for any thread count. After build(), every body points straight
  // at its root, and contactBody_ holds each contact's dynamic body.
  const uint32_t m = uint32_t(contactBody_.size());
  if (m < ParallelSorter<uint64_t>::kSerialBelow) return groupFewContacts(profiler, stage);
  keys_.resize(m);
  jobs.parallelFor(0, m, tuning::grainFor(m, tuning::kMinIslandGrain), [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler, "islands: keys", stage);
    for (uint32_t k = begin; k < end; ++k) keys_[k] = uint64_t(parent_[contactBody_[k]]) << 32 | k;
  });
  keySorter_.sort(keys_, false, jobs, &profiler, "islands: group contacts", stage + 1);
  ProfileZone z(profiler, "islands: ranges", stage + 5);
  contacts_.resize(m);
  start_.clear();
  for (uint32_t k = 0; k < m; ++k) {
    if (k == 0 || keys_[k] >> 32 != keys_[k - 1] >> 32) start_.push_back(k);
    contacts_[k] = uint32_t(keys_[k]);
  }
  start_.push_back(m);
}

// note: what the sort of (root, contact) keys gives, without comparing keys: the distinct roots
// (stamped, so nothing is cleared per step) sorted, then the contacts counted into them in
// contact order. The serial sort of monument's ~220 keys was a single job of 8 us a step, a
// thirtieth of its work/span bound at 8 threads.
void Islands::groupFewContacts(Profiler& profiler, int stage) {
  ProfileZone z(profiler, "islands: group contacts", stage + 1);
  const uint32_t m = uint32_t(contactBody_.size());
  const uint32_t n = uint32_t(parent_.size());
  if (rootSlot_.size() < n) {
    rootSlot_.resize(n);
    rootStamp_.resize(n, 0);
  }
  if (++stamp_ == 0) {  // wrapped: clear the stamps once
    std::fill(rootStamp_.begin(), rootStamp_.end(), 0u);
    stamp_ = 1;
  }
  contactRoot_.resize(m);
  roots_.clear();
  for (uint32_t k = 0; k < m; ++k) {
    const uint32_t r = parent_[contactBody_[k]];
    contactRoot_[k] = r;
    if (rootStamp_[r] != stamp_) {
      rootStamp_[r] = stamp_;
      roots_.push_back(r);
    }
  }
  std::sort(roots_.begin(), roots_.end());
  const uint32_t islands = uint32_t(roots_.size());
  start_.assign(islands + 1, 0);
  for (uint32_t i = 0; i < islands; ++i) rootSlot_[roots_[i]] = i;
  for (uint32_t k = 0; k < m; ++k) ++start_[rootSlot_[contactRoot_[k]] + 1];
  for (uint32_t i = 0; i < islands; ++i) start_[i + 1] += start_[i];
  fill_.assign(start_.begin(), start_.end() - 1);
  contacts_.resize(m);
  for (uint32_t k = 0; k < m; ++k) contacts_[fill_[rootSlot_[contactRoot_[k]]]++] = k;
}

void IslandColouring::cellsOf(std::span<const uint32_t> island, std::span<const SolverContactExtras> points, JobSystem& jobs,
                              Profiler& profiler, int32_t pointsStage, int32_t cellsStage) {
  const uint32_t n = uint32_t(island.size());
  cellOf_.resize(n);
  if (n == 0) return;
  // Each point relative to the first (small, so float keeps it to well under a cell far from
  // the origin too), and each job's bounds (min and max: exact in any grouping, so the bounds
  // are the serial pass's). Both passes read every contact's record, scattered over the
  // contact list: jobs of their own (one thread's pass was the largest single job of
  // crate_pile's frame).
  const Vec3d origin = points[island[0]].point;
  relative_.resize(n);
  const uint32_t grain = tuning::grainFor(n, tuning::kMinIslandGrain);
  jobBounds_.resize(JobSystem::chunkCount(0, n, grain));
  jobs.parallelFor(0, n, grain, [&](uint32_t begin, uint32_t end) {
    ProfileZone zone(profiler, "colouring: points", pointsStage);
    Vec3f lo = Vec3f::Zero(), hi = Vec3f::Zero();
    for (uint32_t j = begin; j < end; ++j) {
      const Vec3f p = (points[island[j]].point - origin).cast<float>();
      relative_[j] = p;
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    jobBounds_[begin / grain] = {lo, hi};
  });
  Vec3f lo = Vec3f::Zero(), hi = Vec3f::Zero();
  for (const Aabb& b : jobBounds_) {
    lo = lo.cwiseMin(b.min);
    hi = hi.cwiseMax(b.max);
  }
  constexpr int kCells = 16;
  float scale[3];
  for (int a = 0; a < 3; ++a) scale[a] = hi[a] > lo[a] ? float(kCells) / (hi[a] - lo[a]) : 0.f;
  jobs.parallelFor(0, n, grain, [&](uint32_t begin, uint32_t end) {
    ProfileZone zone(profiler, "colouring: cells", cellsStage);
    for (uint32_t j = begin; j < end; ++j) {
      uint32_t q[3];
      for (int a = 0; a < 3; ++a) q[a] = uint32_t(std::clamp(int((relative_[j][a] - lo[a]) * scale[a]), 0, kCells - 1));
      // note: x highest, so the code's top bit halves the island across x, not z: a pile is
      // wider than tall, and a vertical cut between two threads' slices meets fewer bodies.
      cellOf_[j] = uint16_t(mortonCode(q[0], q[1], q[2]));
    }
  });
}

void IslandColouring::sortByCell() {
  // Island positions by cell, island order within a cell.
  const uint32_t n = uint32_t(cellOf_.size());
  constexpr uint32_t kCellCount = 16 * 16 * 16;
  cellStart_.assign(kCellCount + 1, 0);
  for (uint32_t j = 0; j < n; ++j) ++cellStart_[cellOf_[j] + 1];
  for (size_t c = 1; c < cellStart_.size(); ++c) cellStart_[c] += cellStart_[c - 1];
  byCell_.resize(n);
  for (uint32_t j = 0; j < n; ++j) byCell_[cellStart_[cellOf_[j]]++] = j;
}

void IslandColouring::colour(std::span<const uint32_t> island, std::span<const SolverContact> contacts,
                             const std::vector<MotionType>& motion, std::span<const SolverContactExtras> points,
                             JobSystem& jobs, Profiler& profiler, const char* name, const ColouringStages& stages) {
  cellsOf(island, points, jobs, profiler, stages.points, stages.cells);
  // The colours and the cells' order do not depend on each other: side by side on two threads.
  jobs.parallelFor(0, 2, 1, [&](uint32_t task, uint32_t) {
    if (task == 0) {
      ProfileZone zone(profiler, name, stages.colours);
      colourGroups(island, contacts, motion);
    } else {
      ProfileZone zone(profiler, "colouring: cell order", stages.colours);
      sortByCell();
    }
  });
  placeInSlots(island, uint32_t(motion.size()), jobs, profiler, stages);
}

// The serial steps this replaced (slots in the order the cells first meet the bodies, then each
// colour's contacts placed in cell order) were crate_pile's longest single job after the cells.
// In passes of parallel jobs over the island positions, with the same result:
//   seen:   each body's first meeting in cell order (a position's key 2p + end, the smallest
//           kept by compare-and-swap in slotOf_, kInvalidIndex between calls); per job, how
//           many of each colour its cell-order positions hold and of the serial group its
//           island-order positions;
//   owners: per job, the fixed and the moving bodies whose first meeting it holds;
//   lists:  those bodies written in order at their job's offsets (slotBody_);
//   slots:  each listed body's slot into slotOf_;
//   place:  each contact at its colour's offset for its job (solveOrder_, slotPairs_);
//   and then slotOf_ back to kInvalidIndex.
void IslandColouring::placeInSlots(std::span<const uint32_t> island, uint32_t bodies, JobSystem& jobs, Profiler& profiler,
                                   const ColouringStages& stages) {
  const uint32_t n = uint32_t(island.size());
  const uint32_t groups = colours();
  const uint32_t serial = tuning::kMaxColours;  // the serial group's colour (last group when used)
  const bool hasSerial = groups == serial + 1;
  const uint32_t grain = tuning::grainFor(n, tuning::kMinIslandGrain);
  const uint32_t jobCount = JobSystem::chunkCount(0, n, grain);
  slotOf_.resize(bodies, kInvalidIndex);
  jobCounts_.assign(size_t(jobCount) * (groups + 2), 0);  // per job: its groups' counts, then fixed and moving owners
  const auto counts = [&](uint32_t begin) { return jobCounts_.data() + size_t(begin / grain) * (groups + 2); };
  const auto end = [&](uint32_t j, int k) { return k ? ends_[j].b : ends_[j].a; };
  jobs.parallelFor(0, n, grain, [&](uint32_t begin, uint32_t stop) {
    ProfileZone zone(profiler, "colouring: first meetings", stages.seen);
    uint32_t* count = counts(begin);
    for (uint32_t p = begin; p < stop; ++p) {
      const uint32_t j = byCell_[p];
      for (int k = 0; k < 2; ++k) {
        std::atomic_ref<uint32_t> first(slotOf_[end(j, k)]);
        const uint32_t key = 2 * p + uint32_t(k);
        uint32_t seen = first.load(std::memory_order_relaxed);
        while (key < seen && !first.compare_exchange_weak(seen, key, std::memory_order_relaxed)) {
        }
      }
      if (colourOf_[j] != serial) ++count[colourOf_[j]];
      if (hasSerial && colourOf_[p] == serial) ++count[serial];  // (island order)
    }
  });
  const auto owns = [&](uint32_t p, int k) { return slotOf_[end(byCell_[p], k)] == 2 * p + uint32_t(k); };
  jobs.parallelFor(0, n, grain, [&](uint32_t begin, uint32_t stop) {
    ProfileZone zone(profiler, "colouring: owners", stages.owners);
    uint32_t* count = counts(begin);
    for (uint32_t p = begin; p < stop; ++p)
      for (int k = 0; k < 2; ++k)
        if (owns(p, k)) ++count[groups + ((k ? ends_[byCell_[p]].dynamicB : ends_[byCell_[p]].dynamicA) ? 1 : 0)];
  });
  // Counts to offsets, job by job (a few dozen jobs of at most 67 counts).
  std::vector<uint32_t>& at = fill_;
  at.assign(start_.begin(), start_.end() - 1);
  at.push_back(0);  // fixed
  at.push_back(0);  // moving
  for (uint32_t c = 0; c < jobCount; ++c) {
    uint32_t* count = jobCounts_.data() + size_t(c) * (groups + 2);
    for (uint32_t g = 0; g < groups + 2; ++g) {
      const uint32_t here = count[g];
      count[g] = at[g];
      at[g] += here;
    }
  }
  // Static and kinematic bodies first, then dynamic ones from a multiple of kSlotsApart.
  const uint32_t fixedCount = at[groups], movingCount = at[groups + 1];
  const uint32_t firstMoving = (fixedCount + kSlotsApart - 1) / kSlotsApart * kSlotsApart;
  const uint32_t slots = firstMoving + movingCount;
  slotBody_.assign(slots, kInvalidIndex);
  jobs.parallelFor(0, n, grain, [&](uint32_t begin, uint32_t stop) {
    ProfileZone zone(profiler, "colouring: slot lists", stages.lists);
    uint32_t* count = counts(begin);
    for (uint32_t p = begin; p < stop; ++p)
      for (int k = 0; k < 2; ++k) {
        if (!owns(p, k)) continue;
        const Ends& e = ends_[byCell_[p]];
        if (k ? e.dynamicB : e.dynamicA) slotBody_[firstMoving + count[groups + 1]++] = end(byCell_[p], k);
        else slotBody_[count[groups]++] = end(byCell_[p], k);
      }
  });
  jobs.parallelFor(0, slots, tuning::grainFor(slots, tuning::kMinBodyGrain), [&](uint32_t begin, uint32_t stop) {
    ProfileZone zone(profiler, "colouring: slots", stages.slots);
    for (uint32_t i = begin; i < stop; ++i)
      if (slotBody_[i] != kInvalidIndex) slotOf_[slotBody_[i]] = i;
  });
  solveOrder_.resize(n);
  slotPairs_.resize(n);
  jobs.parallelFor(0, n, grain, [&](uint32_t begin, uint32_t stop) {
    ProfileZone zone(profiler, "colouring: place", stages.place);
    uint32_t* count = counts(begin);
    const auto place = [&](uint32_t j, uint32_t q) {
      solveOrder_[q] = island[j];
      slotPairs_[q] = {slotOf_[ends_[j].a], slotOf_[ends_[j].b]};
    };
    for (uint32_t p = begin; p < stop; ++p) {
      const uint32_t j = byCell_[p];
      if (colourOf_[j] != serial) place(j, count[colourOf_[j]]++);
      if (hasSerial && colourOf_[p] == serial) place(p, count[serial]++);  // (island order)
    }
  });
  jobs.parallelFor(0, slots, tuning::grainFor(slots, tuning::kMinBodyGrain), [&](uint32_t begin, uint32_t stop) {
    ProfileZone zone(profiler, "colouring: slots cleared", stages.cleared);
    for (uint32_t i = begin; i < stop; ++i)
      if (slotBody_[i] != kInvalidIndex) slotOf_[slotBody_[i]] = kInvalidIndex;
  });
}

void IslandColouring::colourGroups(std::span<const uint32_t> island, std::span<const SolverContact> contacts,
                                   const std::vector<MotionType>& motion) {
  const uint32_t n = uint32_t(island.size());
  ends_.resize(n);
  for (uint32_t j = 0; j < n; ++j) {
    const SolverContact& s = contacts[island[j]];
    ends_[j] = {s.a, s.b, motion[s.a] == MotionType::Dynamic, motion[s.b] == MotionType::Dynamic};
  }
  bodyColours_.resize(motion.size(), 0);
  colourOf_.resize(n);
  uint32_t used = 0;
  for (uint32_t j = 0; j < n; ++j) {
    const Ends& e = ends_[j];
    const uint64_t taken = (e.dynamicA ? bodyColours_[e.a] : 0) | (e.dynamicB ? bodyColours_[e.b] : 0);
    const uint32_t colour = taken == ~uint64_t(0) ? tuning::kMaxColours : uint32_t(std::countr_one(taken));
    if (colour < tuning::kMaxColours) {
      if (e.dynamicA) bodyColours_[e.a] |= uint64_t(1) << colour;
      if (e.dynamicB) bodyColours_[e.b] |= uint64_t(1) << colour;
    }
    colourOf_[j] = colour;
    used = std::max(used, colour + 1);
  }
  // Counting sort into colour groups, island order kept within a group.
  start_.assign(used + 1, 0);
  for (uint32_t c : colourOf_) ++start_[c + 1];
  for (uint32_t c = 0; c < used; ++c) start_[c + 1] += start_[c];
  contacts_.resize(n);
  fill_.assign(start_.begin(), start_.end() - 1);
  for (uint32_t j = 0; j < n; ++j) contacts_[fill_[colourOf_[j]]++] = island[j];
  for (const Ends& e : ends_) bodyColours_[e.a] = bodyColours_[e.b] = 0;  // clean for the next island
}

}  // namespace bw
