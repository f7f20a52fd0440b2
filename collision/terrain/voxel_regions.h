#pragma once
/// Solid voxel regions that an edit cut off from a terrain's anchored voxels, and the boxes
/// that rebuild such a region as bricks (article 001's prototype: disjoint regions after an
/// edit become free bodies).
///
/// A voxel is anchored when its z is below the terrain's anchor height (the model's bottom
/// layer, or everything below a height, as the scene says). Regions are 6-connected (faces).
///
///   DetachedVoxelSearch search;
///   search.find(terrain.voxels(), anchorZ, seedsBesideTheEdit, regions);
///   for (auto& r : regions) bricks = voxelRegionBricks(terrain.voxels(), r, voxelSize);
///
/// Incremental as BrickConnectivity is for grids: a search starts at a solid voxel beside the
/// edit and expands lowest voxel first (a priority queue on z, then on position for a fixed
/// order), so a region still standing on the ground reaches the anchor after about its
/// height's worth of voxels and stops; only a region that is really cut off is walked whole.
/// Voxels shown connected stay known for the rest of the call, so the other seeds of the same
/// edit stop as soon as they touch one.
#include <cstdint>
#include <span>
#include <unordered_set>
#include <vector>

#include "collision/bricks/brick.h"
#include "collision/terrain/voxel_terrain.h"

namespace bw {

class DetachedVoxelSearch {
 public:
  /// The regions (each sorted by z, y, x) of the seeds' solid components that reach no voxel
  /// with z < anchorZ. Seeds that are not solid or are anchored are skipped. A component whose
  /// walk passes `maxVoxels` is taken as anchored (left in place; counted in gaveUp()).
  void find(const VoxelTerrain& voxels, int32_t anchorZ, std::span<const Int3> seeds, std::vector<std::vector<Int3>>& regions,
            uint64_t maxVoxels = uint64_t(1) << 22);
  /// Voxels the last find() visited (its work).
  uint64_t visited() const { return visited_; }
  /// Components the last find() gave up on (walk longer than maxVoxels).
  uint32_t gaveUp() const { return gaveUp_; }

 private:
  struct Int3Hash {
    size_t operator()(const Int3& v) const;
  };
  std::unordered_set<Int3, Int3Hash> anchored_, detached_, seen_;
  uint64_t visited_ = 0;
  uint32_t gaveUp_ = 0;
};

/// The region's voxels as few box bricks: runs along x of one material, merged along y where
/// consecutive rows hold the same run (terrain-local units: voxel (i, j, k) spans
/// [i, i + 1) * voxelSize). Each brick keeps its voxels' material.
std::vector<Brick> voxelRegionBricks(const VoxelTerrain& voxels, std::span<const Int3> region, float voxelSize);

}  // namespace bw
