#include "world/pair_cache.h"

#include <algorithm>

#include "world/world_tuning.h"

namespace bw {

namespace {

// Fewest pairs per job of match() and update(): a pair is tens of nanoseconds to a microsecond.
constexpr uint32_t kMinPairCacheGrain = 64;

}  // namespace

void PairCache::match(const std::vector<BodyPair>& pairs, JobSystem& jobs, Profiler& profiler, int stage) {
  const uint32_t n = uint32_t(pairs.size());
  hits_.resize(n);
  jobs.parallelFor(0, n, tuning::grainFor(n, kMinPairCacheGrain), [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler, "pair cache: match", stage);
    // Entries are sorted by pair (made from sorted pairs, erased from in place).
    for (uint32_t k = begin; k < end; ++k) {
      const auto it = std::lower_bound(entries_.begin(), entries_.end(), pairs[k], [](const Entry& e, const BodyPair& p) { return e.pair < p; });
      hits_[k] = it != entries_.end() && it->pair == pairs[k] ? int32_t(it - entries_.begin()) : -1;
    }
  });
}

bool PairCache::reuse(uint32_t k, const RigidTransform& poseA, const RigidTransform& poseB, double maxTranslation,
                      float maxRotation, std::vector<Contact>& out, uint8_t& flipped) const {
  if (hits_[k] < 0) return false;
  const Entry& e = entries_[size_t(hits_[k])];
  const RigidTransform rel = poseA.inverse() * poseB;
  const bool still = (rel.translation - e.relative.translation).norm() < maxTranslation &&
                     e.relative.rotation.angularDistance(rel.rotation) < maxRotation;
  if (!still) return false;
  for (uint32_t i = 0; i < e.count; ++i) {
    const CachedContact& c = contacts_[e.first + i];
    const Vec3d onA = poseA.pointToWorld(c.onA), onB = poseB.pointToWorld(c.onB);
    const Vec3f nrm = poseB.directionToWorld(c.normalB);
    // The slot's normal points from its "b side" towards its "a side" (flipped swaps them).
    const float depth = e.flipped ? float((onA - onB).dot(nrm.cast<double>())) : float((onB - onA).dot(nrm.cast<double>()));
    // The slot's point lies on the surface its normal leaves: b's (or a's when flipped).
    out.push_back({e.flipped ? onA : onB, nrm, depth, c.feature, c.material});
  }
  flipped = e.flipped;
  return true;
}

void PairCache::update(const std::vector<BodyPair>& pairs, const std::vector<std::vector<Contact>>& contacts,
                       const std::vector<uint8_t>& flipped, const std::vector<uint8_t>& reused, const BodyStore& bodies, JobSystem& jobs,
                       Profiler& profiler, int stage) {
  const uint32_t n = uint32_t(pairs.size());
  const uint32_t grain = tuning::grainFor(n, kMinPairCacheGrain);
  const uint32_t chunks = JobSystem::chunkCount(0, n, grain);
  chunkEntries_.assign(chunks + 1, 0);
  chunkContacts_.assign(chunks + 1, 0);
  jobs.parallelFor(0, n, grain, [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler, "pair cache: count", stage);
    uint32_t entries = 0, cached = 0;
    for (uint32_t k = begin; k < end; ++k) {
      entries += contacts[k].empty() ? 0 : 1;
      cached += uint32_t(contacts[k].size());
    }
    chunkEntries_[begin / grain + 1] = entries;
    chunkContacts_[begin / grain + 1] = cached;
  });
  for (uint32_t c = 0; c < chunks; ++c) {
    chunkEntries_[c + 1] += chunkEntries_[c];
    chunkContacts_[c + 1] += chunkContacts_[c];
  }
  resizeForOverwrite(nextEntries_, chunkEntries_[chunks]);
  resizeForOverwrite(nextContacts_, chunkContacts_[chunks]);
  jobs.parallelFor(0, n, grain, [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler, "pair cache: update", stage + 1);
    uint32_t entry = chunkEntries_[begin / grain], slot = chunkContacts_[begin / grain];
    for (uint32_t k = begin; k < end; ++k) {
      if (contacts[k].empty()) continue;
      const uint32_t a = pairs[k].a, b = pairs[k].b;
      const RigidTransform poseA{bodies.position[a], bodies.rotation[a]}, poseB{bodies.position[b], bodies.rotation[b]};
      Entry e{pairs[k], poseA.inverse() * poseB, flipped[k], slot, uint32_t(contacts[k].size())};
      if (reused[k]) e.relative = entries_[size_t(hits_[k])].relative;
      for (const Contact& c : contacts[k]) {
        // The point lies on the slot's "b side" surface; the "a side" point is depth along -normal.
        const Vec3d onSideB = c.position, onSideA = c.position - c.normal.cast<double>() * double(c.depth);
        const Vec3d onB = flipped[k] ? onSideA : onSideB, onA = flipped[k] ? onSideB : onSideA;
        nextContacts_[slot++] = {poseA.pointToLocal(onA), poseB.pointToLocal(onB), poseB.directionToLocal(c.normal), c.featureB,
                                 c.material};
      }
      nextEntries_[entry++] = e;
    }
  });
  std::swap(entries_, nextEntries_);
  std::swap(contacts_, nextContacts_);
}

}  // namespace bw
