// Terrain edits (World): the scene's carves on terrains, then the solid regions they cut off
// from the anchored voxels made dynamic bodies (article 001's prototype), then wakes and
// dropped contacts near what changed.
//
// A region that breaks free becomes a grid of box bricks (voxel_regions.h: runs of voxels
// merged along x and y) and collides as every grid does: by its convex approximation against
// terrains and other grids, brick by brick against primitives. note: chosen over a small moving
// terrain because every path a grid body needs (mass and inertia from bricks, grid vs grid,
// grid vs terrain, containment, splits' body bookkeeping) exists and is tested, and a moving
// terrain would need a terrain vs terrain narrowphase that does not; measured in
// profiles/RESULTS.md (session 9, quarry).
#include <algorithm>
#include <chrono>
#include <cmath>

#include "world/world.h"

namespace bw {

namespace {
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// World box of terrain-local voxel box [lo, hi].
WorldAabb voxelBoxInWorld(const Terrain& t, const Int3& lo, const Int3& hi) {
  const float s = t.voxelSize();
  const Vec3d a = t.placement().pointToWorld(Vec3f(float(lo.x), float(lo.y), float(lo.z)) * s);
  const Vec3d b = t.placement().pointToWorld(Vec3f(float(hi.x + 1), float(hi.y + 1), float(hi.z + 1)) * s);
  return {a.cwiseMin(b), a.cwiseMax(b)};
}
}  // namespace

void World::carveTerrains() {
  if (carveLoad_.empty()) return;
  const auto t = Clock::now();
  carves_.clear();
  carveLoad_.apply(frame_, terrains_, carves_);
  stats_.editsSkipped += carveLoad_.skipped();
  if (carves_.empty()) return;
  std::vector<WorldAabb> changed;  // world boxes of everything carved or broken free
  for (const TerrainCarve& c : carves_) {
    stats_.voxelsCarved += c.voxels;
    changed.push_back(voxelBoxInWorld(*terrains_[c.terrain], c.lo, c.hi));
  }
  breakTerrainFree(changed);
  // Bodies near the change wake and forget their cached contacts with the terrain (they rested
  // on voxels that may be gone).
  std::vector<uint8_t> near(bodies_.size(), 0);
  for (uint32_t i = 0; i < bodies_.size(); ++i) {
    if (bodies_.motion[i] != MotionType::Dynamic) continue;
    float reach;
    const WorldAabb box = boundsOf(i, reach);
    for (const WorldAabb& c : changed)
      if ((box.min.array() <= c.max.array()).all() && (c.min.array() <= box.max.array()).all()) {
        near[i] = 1;
        sleep_.wake(i);
        break;
      }
  }
  pairCache_.forget([&](const BodyPair& p) {
    return (bodies_.shape[p.a].isTerrain() && near[p.b]) || (bodies_.shape[p.b].isTerrain() && near[p.a]);
  });
  stats_.terrainEditMs = msSince(t);
}

void World::breakTerrainFree(std::vector<WorldAabb>& changed) {
  std::vector<Int3> seeds;
  std::vector<std::vector<Int3>> regions;
  for (uint32_t ti = 0; ti < terrains_.size(); ++ti) {
    const TerrainBreak& rule = terrainBreaks_[ti];
    if (!rule.breakFree) continue;
    Terrain& terrain = *terrains_[ti];
    const VoxelTerrain& voxels = terrain.voxels();
    // Seeds: the solid voxels just outside each carved sphere (what may have lost its support).
    seeds.clear();
    for (const TerrainCarve& c : carves_) {
      if (c.terrain != ti || c.voxels == 0) continue;
      const float inner = c.radius * c.radius, outer = (c.radius + 1.8f) * (c.radius + 1.8f);
      const int32_t reach = int32_t(std::ceil(c.radius + 1.8f));
      for (int32_t z = c.centre.z - reach; z <= c.centre.z + reach; ++z)
        for (int32_t y = c.centre.y - reach; y <= c.centre.y + reach; ++y)
          for (int32_t x = c.centre.x - reach; x <= c.centre.x + reach; ++x) {
            const float dx = float(x - c.centre.x), dy = float(y - c.centre.y), dz = float(z - c.centre.z);
            const float d = dx * dx + dy * dy + dz * dz;
            if (d > inner && d <= outer && voxels.contains({x, y, z}) && voxels.get({x, y, z}).isSolid()) seeds.push_back({x, y, z});
          }
    }
    if (seeds.empty()) continue;
    voxelSearch_.find(voxels, rule.anchorZ, seeds, regions);
    stats_.voxelsSearched += voxelSearch_.visited();
    for (const std::vector<Int3>& region : regions) {
      Int3 lo = region.front(), hi = region.front();
      for (const Int3& v : region) {
        lo = {std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z)};
        hi = {std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z)};
      }
      changed.push_back(voxelBoxInWorld(terrain, lo, hi));
      std::vector<Brick> bricks;
      if (region.size() >= rule.debrisVoxels) bricks = voxelRegionBricks(voxels, region, terrain.voxelSize());
      terrain.edit(lo, hi, [&](VoxelTerrain& v) {
        for (const Int3& x : region) v.set(x, Voxel{});
      });
      if (bricks.empty()) {
        stats_.debrisVoxels += uint32_t(region.size());
        continue;
      }
      // The region's grid sits where its voxels were: grid frame = the terrain's local frame.
      auto grid = std::make_unique<BrickGrid>(BrickGrid::Config(uint32_t(bricks.size() + 64)));
      grid->placeBricks(bricks);
      addPartBody(std::move(grid), nullptr, 0, scene_.terrains[ti].name + "/slab" + std::to_string(++piecesMade_), terrain.placement(),
                  Vec3f::Zero(), Vec3f::Zero());
      ++stats_.terrainParts;
    }
  }
}

}  // namespace bw
