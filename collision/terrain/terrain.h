#pragma once
/// One voxel terrain placed in the world: voxel storage, bitmask broadphase and the lazily
/// built narrowphase cache, kept consistent under edits.
///
///   Terrain terrain({4096, 256, 4096}, /*voxelSize=*/1.0f, placement, /*cacheBudget=*/64 << 20);
///   terrain.fillBox({0, 0, 0}, {4095, 20, 4095}, Voxel::make(kMaterialFirstSolid));
///   TerrainOverlap o = terrain.overlapLocal(box);              // bitmask broadphase
///   raycastTerrain(terrain, origin, dir, 100.0, hit);          // terrain_queries.h
///   terrainContacts(terrain, shape, 0.01f, contacts);          // terrain_contacts.h
///
/// Frames: world (double) -> terrain-local (float, voxel (i,j,k) spans [i,i+1)*voxelSize) ->
/// chunk-local (float, origin at the chunk's min corner). Chunk meshes and trees live in
/// chunk-local coordinates; chunkTransform() composes the placement with the chunk offset so
/// that RigidTransform stays the one place where world values become local floats.
/// Edits rebuild the masks of the affected chunks (neighbours included) and drop their
/// cached meshes. Thread safety: none; edit and query from one thread (queries fill the cache).
#include <cstddef>

#include "collision/core/rigid_transform.h"
#include "collision/terrain/bitmask_broadphase.h"
#include "collision/terrain/chunk_cache.h"
#include "collision/terrain/voxel_terrain.h"

namespace bw {

class Terrain {
 public:
  /// Default narrowphase cache budget (bytes of meshes + trees).
  static constexpr size_t kDefaultCacheBudget = size_t(64) << 20;

  /// An all-air terrain. Throws InvalidInput for a bad size, a voxelSize outside
  /// [1e-3, 1e3] or an invalid placement.
  Terrain(const Int3& sizeInVoxels, float voxelSize, const RigidTransform& placement = {},
          size_t cacheBudgetBytes = kDefaultCacheBudget);

  /// Writes one voxel and updates broadphase and cache. Throws InvalidInput outside the terrain.
  void setVoxel(const Int3& v, Voxel voxel);
  /// Fills the inclusive box [lo, hi] and updates broadphase and cache once for the box.
  void fillBox(const Int3& lo, const Int3& hi, Voxel voxel);
  /// Writes many voxels through `write(VoxelTerrain&)` touching only [lo, hi], then updates
  /// broadphase and cache once (bulk loading, generators).
  template <class F>
  void edit(const Int3& lo, const Int3& hi, F&& write) {
    write(voxels_);
    afterEdit(lo, hi);
  }

  /// Voxel storage.
  const VoxelTerrain& voxels() const { return voxels_; }
  /// Broadphase masks.
  const BitmaskBroadphase& broadphase() const { return broadphase_; }
  /// Narrowphase cache (mutable: queries fill it).
  ChunkCache& cache() { return cache_; }
  /// Narrowphase data of a chunk, built on demand.
  const ChunkCollision& chunkCollision(const Int3& chunk) { return cache_.get(chunk, voxels_, voxelSize_); }
  /// The chunk's collision data if the cache holds it, else nullptr (reads only: thread-safe).
  const ChunkCollision* cachedChunkCollision(const Int3& chunk) const { return cache_.find(chunk); }

  /// Edge length of a voxel in terrain-local units.
  float voxelSize() const { return voxelSize_; }
  /// Terrain-local -> world transform.
  const RigidTransform& placement() const { return placement_; }
  /// Moves the terrain (no rebuild: all data is local).
  void setPlacement(const RigidTransform& placement);
  /// Edits and moves so far: changes whenever a voxel is written or the terrain is moved.
  uint64_t changeCount() const { return changes_; }
  /// Chunk-local -> world transform of a chunk.
  RigidTransform chunkTransform(const Int3& chunk) const;

  /// Broadphase test of a terrain-local box.
  TerrainOverlap overlapLocal(const Aabb& localBox) const { return broadphase_.overlap(localBox, voxelSize_); }
  /// Broadphase test of a world box given by its corners (double). Throws InvalidInput on NaN.
  TerrainOverlap overlapWorld(const Vec3d& worldMin, const Vec3d& worldMax) const;
  /// Terrain-local bounds of a world box.
  Aabb worldBoxToLocal(const Vec3d& worldMin, const Vec3d& worldMax) const;

 private:
  void afterEdit(const Int3& lo, const Int3& hi);

  VoxelTerrain voxels_;
  BitmaskBroadphase broadphase_;
  ChunkCache cache_;
  float voxelSize_;
  RigidTransform placement_;
  uint64_t changes_ = 0;
};

}  // namespace bw
