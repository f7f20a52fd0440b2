#pragma once
/// Terrain broadphase over dilated per-chunk bitmasks (article 001, "Bit broadphase").
///
///   BitmaskBroadphase bp(terrain.chunkGrid());
///   bp.rebuildAll(terrain);                      // at load
///   bp.rebuildAround(terrain, lo, hi);           // after editing voxels [lo, hi]
///   TerrainOverlap o = bp.overlap(localAabb, voxelSize);
///
/// Storage: a ChunkKeyMap from chunk key to either a mask index (a VirtualPool of 128-byte
/// ChunkBitmask) or a tag for all-solid / all-water chunks. All-air chunks have no entry.
/// Worst case 2 bits per voxel plus one 16-byte map slot per non-empty chunk.
/// Thread safety: queries are const and may run concurrently while no one rebuilds.
#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "collision/core/aabb.h"
#include "collision/core/virtual_pool.h"
#include "collision/terrain/chunk_bitmask.h"
#include "collision/terrain/chunk_key_map.h"

namespace bw {

/// Result of a terrain broadphase test: solid and water touch are reported separately.
struct TerrainOverlap {
  bool solid = false;  ///< the box may touch solid geometry (narrowphase needed)
  bool water = false;  ///< the box may touch water (buoyancy needed)
};

/// An inclusive voxel-index box.
struct VoxelRange {
  Int3 lo;  ///< first voxel per axis
  Int3 hi;  ///< last voxel per axis (inclusive)
};

class BitmaskBroadphase {
 public:
  /// An empty broadphase for a terrain of the given chunk grid.
  explicit BitmaskBroadphase(const Int3& chunkGrid, const Int3& sizeInVoxels);

  /// Rebuilds every chunk from scratch (every chunk within one chunk of stored voxels).
  void rebuildAll(const VoxelTerrain& terrain);
  /// Rebuilds the chunks whose 10^3 neighbourhood contains any voxel of [lo, hi] (inclusive,
  /// voxel indices): the edited chunks and their neighbours across borders.
  void rebuildAround(const VoxelTerrain& terrain, const Int3& lo, const Int3& hi);
  /// Rebuilds one chunk's entry.
  void rebuildChunk(const VoxelTerrain& terrain, const Int3& chunk);

  /// Voxel range a terrain-local box may touch geometry in: the box expanded by one voxel
  /// (geometry spills into neighbours), floored to voxel indices, clamped to the terrain.
  /// Returns false when the range is empty (box outside the terrain).
  bool voxelRangeOf(const Aabb& localBox, float voxelSize, VoxelRange& out) const;
  /// Tests a terrain-local box (units: terrain-local, voxel edge = voxelSize).
  TerrainOverlap overlap(const Aabb& localBox, float voxelSize) const;
  /// Tests an inclusive voxel range against the masks (no expansion).
  TerrainOverlap overlapRange(const VoxelRange& r) const;
  /// f(chunkCoord, TerrainOverlap) for every chunk whose masks the range touches.
  template <class F>
  void forEachTouchedChunk(const VoxelRange& r, F&& f) const;

  /// The entry kind of chunk c (Empty when it has no entry).
  ChunkMaskKind kind(const Int3& c) const;
  /// Masks of chunk c, or nullptr unless its kind is Masked.
  const ChunkBitmask* masks(const Int3& c) const;

  /// Chunks with an entry (masked + tagged).
  size_t entryCount() const { return entries_.size(); }
  /// Chunks that keep a 128-byte mask.
  size_t maskedCount() const { return masks_.size(); }
  /// Bytes held: map slots plus masks (logical, not page-rounded).
  size_t bytes() const { return entries_.bytes() + masks_.size() * sizeof(ChunkBitmask); }

 private:
  static constexpr uint32_t kTagAllSolid = 0xFFFFFFFEu;
  static constexpr uint32_t kTagAllWater = 0xFFFFFFFDu;

  /// Touch test of one chunk entry against a chunk-local voxel box.
  static TerrainOverlap testEntry(uint32_t entry, const ChunkBitmask* masks, const Int3& lo, const Int3& hi);
  void setEntry(const Int3& c, ChunkMaskKind kind, const ChunkBitmask& bits);

  Int3 chunkGrid_;
  Int3 size_;
  VirtualPool<ChunkBitmask> masks_;
  ChunkKeyMap entries_;
};

/// Lookup tables that turn an X range and a Z range into a slice mask with one AND.
struct SliceMaskTables {
  uint64_t xRange[kChunkSize][kChunkSize];  ///< bits x0..x1 set in every row byte
  uint64_t zRange[kChunkSize][kChunkSize];  ///< row bytes z0..z1 all ones
};
/// The tables, built at compile time.
const SliceMaskTables& sliceMaskTables();

template <class F>
void BitmaskBroadphase::forEachTouchedChunk(const VoxelRange& r, F&& f) const {
  for (int cy = r.lo.y >> kChunkShift; cy <= r.hi.y >> kChunkShift; ++cy) {
    for (int cz = r.lo.z >> kChunkShift; cz <= r.hi.z >> kChunkShift; ++cz) {
      for (int cx = r.lo.x >> kChunkShift; cx <= r.hi.x >> kChunkShift; ++cx) {
        const uint32_t e = entries_.find(chunkKey({cx, cy, cz}));
        if (e == kInvalidIndex) continue;
        const Int3 base{cx * kChunkSize, cy * kChunkSize, cz * kChunkSize};
        const Int3 lo{std::max(r.lo.x - base.x, 0), std::max(r.lo.y - base.y, 0), std::max(r.lo.z - base.z, 0)};
        const Int3 hi{std::min(r.hi.x - base.x, kChunkSize - 1), std::min(r.hi.y - base.y, kChunkSize - 1),
                      std::min(r.hi.z - base.z, kChunkSize - 1)};
        const ChunkBitmask* m = (e == kTagAllSolid || e == kTagAllWater) ? nullptr : &masks_[e];
        const TerrainOverlap o = testEntry(e, m, lo, hi);
        if (o.solid || o.water) f(Int3{cx, cy, cz}, o);
      }
    }
  }
}

}  // namespace bw
