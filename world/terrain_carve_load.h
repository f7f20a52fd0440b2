#pragma once
/// The scene's edits on terrains (EditLoadDescription with `terrain`): spheres carved to air
/// around random solid voxels above the terrain's anchor, between steps. World::step makes a
/// frame's carves, then lets the regions they cut off break free (voxel_regions.h).
///
///   TerrainCarveLoad load(scene.edits, terrainIndexOfEachEdit, anchorZOfEachTerrain);
///   load.apply(frame, terrains, carves);   // carves: what this frame cut, terrain by terrain
///
/// Deterministic: each stream draws from its own SeededRandom (splitmix64, the same on every
/// standard library) and reads only voxels, which only edits change.
#include <cstdint>
#include <memory>
#include <vector>

#include "collision/core/seeded_random.h"
#include "collision/terrain/terrain.h"
#include "world/scene_description.h"

namespace bw {

/// One sphere carved: terrain-local voxel box [lo, hi] it touched and the solid voxels it removed.
struct TerrainCarve {
  uint32_t terrain;
  Int3 centre;
  float radius;  ///< voxels
  Int3 lo, hi;
  uint32_t voxels = 0;
};

class TerrainCarveLoad {
 public:
  TerrainCarveLoad() = default;
  /// Takes the streams of `edits` that name a terrain; terrainIndex[i] is edits[i]'s terrain (or
  /// ignored for grid edits), anchorZ[t] terrain t's first unanchored voxel z.
  TerrainCarveLoad(const std::vector<EditLoadDescription>& edits, const std::vector<uint32_t>& terrainIndex, std::vector<int32_t> anchorZ);
  bool empty() const { return streams_.empty(); }
  /// Frame `frame`'s carves, appended to `out`. A stream's centre is a random voxel of its region
  /// (terrain-local) that is solid and above the anchor; after kTries misses it skips (counted).
  void apply(uint64_t frame, std::vector<std::unique_ptr<Terrain>>& terrains, std::vector<TerrainCarve>& out);
  /// Carves given up in the last apply() (no solid voxel found in the region).
  uint32_t skipped() const { return skipped_; }
  static constexpr int kTries = 64;

 private:
  struct Stream {
    EditLoadDescription d;
    uint32_t terrain;
    SeededRandom rng;
  };
  std::vector<Stream> streams_;
  std::vector<int32_t> anchorZ_;
  uint32_t skipped_ = 0;
};

}  // namespace bw
