#pragma once
/// Sparse voxel storage of one terrain: chunks of 8^3 voxels, only where something is.
///
///   VoxelTerrain t({4096, 256, 4096});          // no memory per empty chunk
///   t.fillBox({0, 0, 0}, {4095, 9, 4095}, Voxel::make(kMaterialFirstSolid));
///   Voxel v = t.get({10, 3, 10});
///
/// Chunks live in a VirtualPool (stable indices, pages given back when chunks are freed) and
/// are found through a ChunkKeyMap. A chunk whose last non-air voxel is erased is freed.
/// Coordinates are voxel indices in [0, size) per axis; everything outside reads as air.
/// Thread safety: none; edit only while no query runs.
#include <cstddef>
#include <cstdint>

#include "collision/core/virtual_pool.h"
#include "collision/terrain/chunk_key_map.h"
#include "collision/terrain/voxel_chunk.h"

namespace bw {

/// The 10^3 voxels around a chunk (the chunk plus a one-voxel border), indexed [y][z][x]
/// with the chunk's voxel (0,0,0) at [1][1][1]. Input of the bitmask builder and the mesher.
struct ChunkNeighbourhood {
  static constexpr int kSize = kChunkSize + 2;  ///< 10 voxels per edge
  Voxel v[kSize][kSize][kSize];                  ///< [y][z][x]
};

class VoxelTerrain {
 public:
  /// Largest size per axis in voxels (chunk keys hold 21 bits per axis).
  static constexpr int32_t kMaxSize = 1 << 24;

  /// An all-air terrain of `sizeInVoxels` (each axis in [1, kMaxSize]). Throws InvalidInput.
  explicit VoxelTerrain(const Int3& sizeInVoxels);

  /// Size in voxels.
  const Int3& size() const { return size_; }
  /// Number of chunks per axis (size rounded up to whole chunks).
  const Int3& chunkGrid() const { return chunkGrid_; }
  /// True when v lies inside the terrain.
  bool contains(const Int3& v) const {
    return v.x >= 0 && v.y >= 0 && v.z >= 0 && v.x < size_.x && v.y < size_.y && v.z < size_.z;
  }

  /// The voxel at v; air outside the terrain or in a chunk that stores nothing.
  Voxel get(const Int3& v) const;
  /// Writes one voxel. Throws InvalidInput when v is outside the terrain.
  void set(const Int3& v, Voxel voxel);
  /// Writes every voxel of the inclusive box [lo, hi]. Throws InvalidInput if the box is
  /// inverted or leaves the terrain.
  void fillBox(const Int3& lo, const Int3& hi, Voxel voxel);

  /// The stored chunk at chunk coordinates c, or nullptr when it is all air.
  const VoxelChunk* chunk(const Int3& c) const;
  /// Copies the 10^3 neighbourhood of chunk c (air outside the terrain).
  void gatherNeighbourhood(const Int3& c, ChunkNeighbourhood& out) const;

  /// Number of chunks holding at least one non-air voxel.
  uint32_t storedChunkCount() const { return pool_.size(); }
  /// f(chunkCoord, chunk) for every stored chunk.
  template <class F>
  void forEachChunk(F&& f) const {
    keys_.forEach([&](uint64_t key, uint32_t index) { f(chunkCoordFromKey(key), pool_[index]); });
  }
  /// Resident bytes of voxel storage (pool pages touched + key map).
  size_t residentBytes() const { return pool_.residentBytes() + keys_.bytes(); }

 private:
  /// Writes v inside an already-validated range; creates/frees the chunk as needed.
  void writeVoxel(const Int3& v, Voxel voxel);

  Int3 size_;
  Int3 chunkGrid_;
  VirtualPool<VoxelChunk> pool_;
  ChunkKeyMap keys_;
};

}  // namespace bw
