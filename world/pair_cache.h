#pragma once
/// The pair cache: each pair's contacts kept in both bodies' frames and reused while the pair's
/// relative pose barely changes, so resting piles do not redo narrowphase every step. A reused
/// contact is re-posed and its depth measured again along its normal.
#include <cstdint>
#include <vector>

#include "collision/bricks/contact.h"
#include "collision/core/overwrite_vector.h"
#include "collision/core/rigid_transform.h"
#include "jobs/job_system.h"
#include "jobs/profiler.h"
#include "world/body_store.h"
#include "world/broadphase.h"

namespace bw {

class PairCache {
 public:
  /// Matches this substep's pairs with the entries made last time (a binary search per pair,
  /// in parallel chunks, zones at `stage`): hit(k) is then pair k's entry, or -1.
  void match(const std::vector<BodyPair>& pairs, JobSystem& jobs, Profiler& profiler, int stage);
  int32_t hit(uint32_t k) const { return hits_[k]; }

  /// If pair k has an entry and the relative pose of its bodies (poses of a and b) moved less
  /// than maxTranslation (m) and maxRotation (rad) since it was made: appends its contacts to
  /// `out` (normals as the pair's slot stores them), sets `flipped` and returns true.
  bool reuse(uint32_t k, const RigidTransform& poseA, const RigidTransform& poseB, double maxTranslation, float maxRotation,
             std::vector<Contact>& out, uint8_t& flipped) const;

  /// Keeps every pair's contacts for the next substep. reused[k]: pair k's contacts came from
  /// reuse(), so its entry keeps its original relative pose (slow creep is caught once it adds up).
  /// In parallel chunks: each chunk counts its entries and contacts (zones at `stage`), then
  /// writes them at its offsets (stage + 1): the same entries in pair order for any thread count.
  void update(const std::vector<BodyPair>& pairs, const std::vector<std::vector<Contact>>& contacts,
              const std::vector<uint8_t>& flipped, const std::vector<uint8_t>& reused, const BodyStore& bodies, JobSystem& jobs,
              Profiler& profiler, int stage);

  /// Forgets the entries of pairs for which pred(pair) holds (their contacts may be stale).
  template <class Pred>
  void forget(Pred pred) {
    std::erase_if(entries_, [&](const Entry& e) { return pred(e.pair); });
  }

 private:
  struct CachedContact {
    Vec3f onA, onB;   // contact points in body a's and body b's frames (a, b as in the pair)
    Vec3f normalB;    // normal in b's frame, oriented as the slot stores it
    uint32_t feature, material;
  };
  struct Entry {
    BodyPair pair;
    RigidTransform relative;   // b's pose in a's frame when the contacts were made
    uint8_t flipped;
    uint32_t first, count;     // range in contacts_
  };
  // The next ones are sized by update() and written whole by its jobs.
  OverwriteVector<Entry> entries_, nextEntries_;
  OverwriteVector<CachedContact> contacts_, nextContacts_;
  std::vector<int32_t> hits_;  // per pair of this substep: index into entries_ or -1
  std::vector<uint32_t> chunkEntries_, chunkContacts_;  // update(): per chunk counts, then offsets
};

}  // namespace bw
