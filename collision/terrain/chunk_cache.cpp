#include "collision/terrain/chunk_cache.h"

#include <algorithm>
#include <utility>

#include "collision/terrain/chunk_mesher.h"

namespace bw {

ChunkCache::ChunkCache(size_t budgetBytes) : budget_(budgetBytes) {}

void ChunkCache::unlink(uint32_t e) {
  Entry& x = entries_[e];
  if (x.prev != kInvalidIndex) entries_[x.prev].next = x.next;
  else head_ = x.next;
  if (x.next != kInvalidIndex) entries_[x.next].prev = x.prev;
  else tail_ = x.prev;
  x.prev = x.next = kInvalidIndex;
}

void ChunkCache::pushFront(uint32_t e) {
  Entry& x = entries_[e];
  x.prev = kInvalidIndex;
  x.next = head_;
  if (head_ != kInvalidIndex) entries_[head_].prev = e;
  head_ = e;
  if (tail_ == kInvalidIndex) tail_ = e;
}

void ChunkCache::drop(uint32_t e) {
  unlink(e);
  Entry& x = entries_[e];
  index_.erase(x.key);
  bytes_ -= x.bytes;
  // note: swap with empty containers so the memory really goes back, not just the sizes.
  x.data = ChunkCollision{};
  x.bytes = 0;
  x.next = freeHead_;
  freeHead_ = e;
}

void ChunkCache::evictToBudget(uint32_t keep) {
  while (bytes_ > budget_ && tail_ != kInvalidIndex && tail_ != keep) {
    drop(tail_);
    ++stats_.evictions;
  }
}

const ChunkCollision& ChunkCache::get(const Int3& chunk, const VoxelTerrain& voxels, float voxelSize) {
  const uint64_t key = chunkKey(chunk);
  uint32_t e = index_.find(key);
  if (e != kInvalidIndex) {
    ++stats_.hits;
    if (head_ != e) {
      unlink(e);
      pushFront(e);
    }
    return entries_[e].data;
  }
  ++stats_.misses;
  if (freeHead_ != kInvalidIndex) {
    e = freeHead_;
    freeHead_ = entries_[e].next;
  } else {
    e = uint32_t(entries_.size());
    entries_.emplace_back();
  }
  Entry& x = entries_[e];
  x.key = key;
  voxels.gatherNeighbourhood(chunk, neighbourhood_);
  meshChunk(neighbourhood_, voxelSize, x.data.mesh);
  x.data.mesh.vertices.shrink_to_fit();
  x.data.mesh.indices.shrink_to_fit();
  x.data.mesh.materials.shrink_to_fit();
  x.data.tree.build(x.data.mesh.view(), builder_);
  x.bytes = x.data.bytes();
  bytes_ += x.bytes;
  index_.insert(key, e);
  pushFront(e);
  evictToBudget(e);
  return entries_[e].data;
}

void ChunkCache::invalidate(const Int3& chunk) {
  const uint32_t e = index_.find(chunkKey(chunk));
  if (e == kInvalidIndex) return;
  drop(e);
  ++stats_.invalidations;
}

void ChunkCache::invalidateAround(const Int3& lo, const Int3& hi) {
  if (index_.size() == 0) return;
  const Int3 clo{std::max((lo.x - 1) >> kChunkShift, 0), std::max((lo.y - 1) >> kChunkShift, 0),
                 std::max((lo.z - 1) >> kChunkShift, 0)};
  const Int3 chi{(hi.x + 1) >> kChunkShift, (hi.y + 1) >> kChunkShift, (hi.z + 1) >> kChunkShift};
  const uint64_t range = uint64_t(chi.x - clo.x + 1) * uint64_t(chi.y - clo.y + 1) * uint64_t(chi.z - clo.z + 1);
  if (range > index_.size()) {
    // A big edit: walk the cached entries instead of the chunk range.
    for (uint32_t e = head_; e != kInvalidIndex;) {
      const uint32_t next = entries_[e].next;
      const Int3 c = chunkCoordFromKey(entries_[e].key);
      if (c.x >= clo.x && c.x <= chi.x && c.y >= clo.y && c.y <= chi.y && c.z >= clo.z && c.z <= chi.z) {
        drop(e);
        ++stats_.invalidations;
      }
      e = next;
    }
    return;
  }
  for (int y = clo.y; y <= chi.y; ++y)
    for (int z = clo.z; z <= chi.z; ++z)
      for (int x = clo.x; x <= chi.x; ++x) invalidate({x, y, z});
}

void ChunkCache::invalidateAll() {
  while (head_ != kInvalidIndex) {
    drop(head_);
    ++stats_.invalidations;
  }
}

void ChunkCache::setBudget(size_t budgetBytes) {
  budget_ = budgetBytes;
  evictToBudget(kInvalidIndex);
}

}  // namespace bw
