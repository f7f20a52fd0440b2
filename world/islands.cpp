#include "world/islands.h"

#include <algorithm>
#include <atomic>
#include <bit>

#include "collision/core/ids.h"
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

}  // namespace

void Islands::build(const std::vector<SolverContact>& contacts, const std::vector<MotionType>& motion, JobSystem& jobs,
                    Profiler& profiler, int stage) {
  const uint32_t n = uint32_t(motion.size());
  parent_.resize(n);
  for (uint32_t i = 0; i < n; ++i) parent_[i] = i;
  // Union-find over the contacts in parallel: a link always hangs the larger of two roots under
  // the smaller (compare-and-swap on the larger, which must still be a root), so every island's
  // root is its smallest body id whatever the order the links were made in: the grouping is a
  // pure function of the contact list, for any thread count.
  jobs.parallelFor(0, uint32_t(contacts.size()), tuning::grainFor(uint32_t(contacts.size()), tuning::kMinIslandGrain), [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler, "islands: union", stage);
    for (uint32_t k = begin; k < end; ++k) {
      const SolverContact& c = contacts[k];
      if (motion[c.a] != MotionType::Dynamic || motion[c.b] != MotionType::Dynamic) continue;
      for (;;) {
        uint32_t ra = findConcurrent(parent_, c.a), rb = findConcurrent(parent_, c.b);
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

void Islands::groupContacts(const std::vector<SolverContact>& contacts, const std::vector<MotionType>& motion, JobSystem& jobs,
                            Profiler& profiler, int stage) {
  // Contacts grouped by the island of their dynamic body, islands ordered by root id, contacts
  // in contact order within one (CSR): a sort of (root, contact) keys, which are unique, so
  // the grouping is the same for any thread count. After build(), every body points straight
  // at its root.
  const uint32_t m = uint32_t(contacts.size());
  keys_.resize(m);
  jobs.parallelFor(0, m, tuning::grainFor(m, tuning::kMinIslandGrain), [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler, "islands: keys", stage);
    for (uint32_t k = begin; k < end; ++k) {
      const SolverContact& c = contacts[k];
      keys_[k] = uint64_t(parent_[motion[c.a] == MotionType::Dynamic ? c.a : c.b]) << 32 | k;
    }
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

void IslandColouring::colour(std::span<const uint32_t> island, const std::vector<SolverContact>& contacts,
                             const std::vector<MotionType>& motion) {
  bodyColours_.resize(motion.size(), 0);
  const uint32_t n = uint32_t(island.size());
  colourOf_.resize(n);
  uint32_t used = 0;
  for (uint32_t j = 0; j < n; ++j) {
    const SolverContact& s = contacts[island[j]];
    uint64_t taken = 0;
    for (uint32_t x : {s.a, s.b})
      if (motion[x] == MotionType::Dynamic) taken |= bodyColours_[x];
    const uint32_t colour = taken == ~uint64_t(0) ? tuning::kMaxColours : uint32_t(std::countr_one(taken));
    if (colour < tuning::kMaxColours)
      for (uint32_t x : {s.a, s.b})
        if (motion[x] == MotionType::Dynamic) bodyColours_[x] |= uint64_t(1) << colour;
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
  for (uint32_t j = 0; j < n; ++j) {
    const SolverContact& s = contacts[island[j]];
    bodyColours_[s.a] = bodyColours_[s.b] = 0;  // clean for the next island
  }
}

}  // namespace bw
