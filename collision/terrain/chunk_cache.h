#pragma once
/// Lazily built narrowphase data of terrain chunks (mesh + loose kD tree), kept in an LRU cache
/// with a byte budget (article 001, "Narrowphase: analysis & plan").
///
///   ChunkCache cache(32 << 20);
///   const ChunkCollision& c = cache.get(chunk, voxels, voxelSize);  // builds on a miss
///   cache.invalidate(chunk);                                        // after an edit near it
///
/// Nothing is meshed until a contact or a ray needs a chunk. Entries sit in one slot array
/// (indices, not pointers) linked into a most-recently-used list; going over the budget
/// evicts from the least-recently-used end, never the entry just returned.
/// The returned reference is valid until the next call that can build or evict (get,
/// invalidate*). Thread safety: none; one query thread at a time.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "collision/core/ids.h"
#include "collision/terrain/chunk_key_map.h"
#include "collision/terrain/loose_kd_tree.h"
#include "collision/terrain/voxel_terrain.h"

namespace bw {

/// Narrowphase data of one chunk, chunk-local coordinates.
struct ChunkCollision {
  ChunkMesh mesh;    ///< triangles with materials
  LooseKdTree tree;  ///< tree over mesh
  /// Bytes held by mesh and tree.
  size_t bytes() const { return mesh.bytes() + tree.bytes(); }
};

/// Counters of a ChunkCache since construction (or resetStats).
struct ChunkCacheStats {
  uint64_t hits = 0;           ///< get() found a current entry
  uint64_t misses = 0;         ///< get() had to mesh and build
  uint64_t evictions = 0;      ///< entries dropped to stay within budget
  uint64_t invalidations = 0;  ///< entries dropped because voxels changed
  /// hits / (hits + misses), 0 when nothing was asked.
  double hitRate() const { return hits + misses ? double(hits) / double(hits + misses) : 0.0; }
};

class ChunkCache {
 public:
  /// A cache holding at most `budgetBytes` of meshes and trees (at least one entry is kept
  /// even if it alone exceeds the budget).
  explicit ChunkCache(size_t budgetBytes);

  /// The chunk's collision data, meshed and built now if not cached.
  const ChunkCollision& get(const Int3& chunk, const VoxelTerrain& voxels, float voxelSize);
  /// The chunk's data if cached, else nullptr. Reads only (no LRU update, no counters): safe on
  /// many threads at once while nothing calls the mutating functions.
  const ChunkCollision* find(const Int3& chunk) const {
    const uint32_t e = index_.find(chunkKey(chunk));
    return e == kInvalidIndex ? nullptr : &entries_[e].data;
  }
  /// True if the chunk's data is cached (does not touch the LRU order).
  bool contains(const Int3& chunk) const { return index_.find(chunkKey(chunk)) != kInvalidIndex; }
  /// Drops the chunk's data (voxels in its 10^3 neighbourhood changed).
  void invalidate(const Int3& chunk);
  /// Drops every chunk whose 10^3 neighbourhood contains a voxel of [lo, hi] (inclusive).
  void invalidateAround(const Int3& lo, const Int3& hi);
  /// Drops everything.
  void invalidateAll();

  /// Changes the budget, evicting as needed.
  void setBudget(size_t budgetBytes);
  /// The byte budget.
  size_t budget() const { return budget_; }
  /// Bytes of meshes and trees currently held.
  size_t bytes() const { return bytes_; }
  /// Number of cached chunks.
  size_t size() const { return index_.size(); }
  /// Counters.
  const ChunkCacheStats& stats() const { return stats_; }
  /// Zeroes the counters.
  void resetStats() { stats_ = {}; }

 private:
  struct Entry {
    ChunkCollision data;
    uint64_t key = 0;
    size_t bytes = 0;
    uint32_t prev = kInvalidIndex;  // towards most recently used
    uint32_t next = kInvalidIndex;  // towards least recently used; free-list link when unused
  };

  void unlink(uint32_t e);
  void pushFront(uint32_t e);
  void drop(uint32_t e);
  void evictToBudget(uint32_t keep);

  std::vector<Entry> entries_;
  ChunkKeyMap index_;
  uint32_t head_ = kInvalidIndex, tail_ = kInvalidIndex, freeHead_ = kInvalidIndex;
  size_t budget_;
  size_t bytes_ = 0;
  ChunkCacheStats stats_;
  KdTreeBuilder builder_;
  ChunkNeighbourhood neighbourhood_;
};

}  // namespace bw
