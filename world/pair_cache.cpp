#include "world/pair_cache.h"

namespace bw {

void PairCache::match(const std::vector<BodyPair>& pairs) {
  // Both lists are sorted by pair: one merge.
  const uint32_t n = uint32_t(pairs.size());
  hits_.assign(n, -1);
  for (uint32_t k = 0, c = 0; k < n; ++k) {
    while (c < entries_.size() && entries_[c].pair < pairs[k]) ++c;
    if (c < entries_.size() && entries_[c].pair == pairs[k]) hits_[k] = int32_t(c);
  }
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
                       const std::vector<uint8_t>& flipped, const std::vector<uint8_t>& reused, const BodyStore& bodies) {
  nextEntries_.clear();
  nextContacts_.clear();
  for (uint32_t k = 0; k < pairs.size(); ++k) {
    if (contacts[k].empty()) continue;
    const uint32_t a = pairs[k].a, b = pairs[k].b;
    const RigidTransform poseA{bodies.position[a], bodies.rotation[a]}, poseB{bodies.position[b], bodies.rotation[b]};
    Entry e{pairs[k], poseA.inverse() * poseB, flipped[k], uint32_t(nextContacts_.size()), uint32_t(contacts[k].size())};
    if (reused[k]) e.relative = entries_[size_t(hits_[k])].relative;
    for (const Contact& c : contacts[k]) {
      // The point lies on the slot's "b side" surface; the "a side" point is depth along -normal.
      const Vec3d onSideB = c.position, onSideA = c.position - c.normal.cast<double>() * double(c.depth);
      const Vec3d onB = flipped[k] ? onSideA : onSideB, onA = flipped[k] ? onSideB : onSideA;
      nextContacts_.push_back({poseA.pointToLocal(onA), poseB.pointToLocal(onB), poseB.directionToLocal(c.normal), c.featureB,
                               c.material});
    }
    nextEntries_.push_back(e);
  }
  std::swap(entries_, nextEntries_);
  std::swap(contacts_, nextContacts_);
}

}  // namespace bw
