#include "world/terrain_carve_load.h"

#include <algorithm>
#include <cmath>

namespace bw {

TerrainCarveLoad::TerrainCarveLoad(const std::vector<EditLoadDescription>& edits, const std::vector<uint32_t>& terrainIndex,
                                   std::vector<int32_t> anchorZ)
    : anchorZ_(std::move(anchorZ)) {
  for (size_t i = 0; i < edits.size(); ++i)
    if (!edits[i].terrain.empty()) streams_.push_back({edits[i], terrainIndex[i], SeededRandom(edits[i].seed)});
}

void TerrainCarveLoad::apply(uint64_t frame, std::vector<std::unique_ptr<Terrain>>& terrains, std::vector<TerrainCarve>& out) {
  skipped_ = 0;
  for (Stream& s : streams_) {
    if (frame < s.d.firstFrame || frame > s.d.lastFrame || (frame - s.d.firstFrame) % s.d.every != 0) continue;
    Terrain& terrain = *terrains[s.terrain];
    const VoxelTerrain& voxels = terrain.voxels();
    const Int3 size = voxels.size();
    const float voxel = terrain.voxelSize();
    // The region in voxels (the terrain's placement only translates: scene terrains are not rotated).
    Int3 lo{0, 0, std::max(0, anchorZ_[s.terrain])}, hi{size.x - 1, size.y - 1, size.z - 1};
    if (s.d.hasRegion) {
      const Vec3f a = terrain.placement().pointToLocal(s.d.regionMin) / voxel, b = terrain.placement().pointToLocal(s.d.regionMax) / voxel;
      auto clampTo = [](float f, int32_t l, int32_t h) { return int32_t(std::clamp(std::floor(f), float(l), float(h))); };
      lo = {clampTo(a.x(), 0, size.x - 1), clampTo(a.y(), 0, size.y - 1), clampTo(a.z(), lo.z, size.z - 1)};
      hi = {clampTo(b.x(), 0, size.x - 1), clampTo(b.y(), 0, size.y - 1), clampTo(b.z(), 0, size.z - 1)};
    }
    const float r = s.d.radius / voxel;
    for (uint32_t k = 0; k < s.d.perFrame; ++k) {
      bool found = false;
      Int3 c;
      for (int t = 0; t < kTries && !found && lo.z <= hi.z; ++t) {
        c = {lo.x + int32_t(s.rng.below(uint32_t(hi.x - lo.x + 1))), lo.y + int32_t(s.rng.below(uint32_t(hi.y - lo.y + 1))),
             lo.z + int32_t(s.rng.below(uint32_t(hi.z - lo.z + 1)))};
        found = voxels.get(c).isSolid();
      }
      if (!found) {
        ++skipped_;
        continue;
      }
      const int32_t reach = int32_t(std::ceil(r));
      TerrainCarve carve{s.terrain, c, r, {std::max(0, c.x - reach), std::max(0, c.y - reach), std::max(0, c.z - reach)},
                         {std::min(size.x - 1, c.x + reach), std::min(size.y - 1, c.y + reach), std::min(size.z - 1, c.z + reach)}, 0};
      const int32_t anchor = anchorZ_[s.terrain];
      // Voxel centres within r of the centre voxel's centre become air (solid ones; water
      // stays); anchored voxels stay: the ground the scene anchors is not carved away.
      terrain.edit(carve.lo, carve.hi, [&](VoxelTerrain& v) {
        for (int32_t z = std::max(carve.lo.z, anchor); z <= carve.hi.z; ++z)
          for (int32_t y = carve.lo.y; y <= carve.hi.y; ++y)
            for (int32_t x = carve.lo.x; x <= carve.hi.x; ++x) {
              const float dx = float(x - c.x), dy = float(y - c.y), dz = float(z - c.z);
              if (dx * dx + dy * dy + dz * dz > r * r || !v.get({x, y, z}).isSolid()) continue;
              v.set({x, y, z}, Voxel{});
              ++carve.voxels;
            }
      });
      out.push_back(carve);
    }
  }
}

}  // namespace bw
