#include "collision/terrain/terrain_queries.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "collision/core/argument_checks.h"

namespace bw {
namespace {

/// A few recently traced chunks, so border neighbours are not traced twice in a row.
struct RecentChunks {
  uint64_t keys[16];
  uint32_t count = 0;
  bool seen(uint64_t k) const {
    for (uint32_t i = 0; i < std::min<uint32_t>(count, 16); ++i) {
      if (keys[i] == k) return true;
    }
    return false;
  }
  void add(uint64_t k) { keys[count++ % 16] = k; }
};

// The ray walk of raycastTerrain, with chunkAt(c) giving a chunk's collision data (nullptr: not
// at hand, and the walk gives up: RayWalk::Incomplete).
enum class RayWalk { Miss, Hit, Incomplete };
template <class ChunkAt>
RayWalk walkRay(const Terrain& terrain, const Vec3d& origin, const Vec3d& dir, double maxDistance, TerrainRayHit& hit,
                TerrainRayStats* stats, ChunkAt&& chunkAt) {
  requireFinite(origin, "raycastTerrain", "origin");
  requireFinite(dir, "raycastTerrain", "dir");
  // note: +inf is a valid maxDistance (an unlimited ray); NaN and negative values are not.
  if (std::isnan(maxDistance) || maxDistance < 0) throw InvalidInput("raycastTerrain: maxDistance is NaN or negative");
  const double len = dir.norm();
  if (!(len > 0)) throw InvalidInput("raycastTerrain: dir has zero length");
  const Vec3d unitDir = dir / len;

  const RigidTransform& place = terrain.placement();
  const Vec3f o = place.pointToLocal(origin);
  const Vec3f d = place.directionToLocal(unitDir);
  const float cs = terrain.voxelSize() * float(kChunkSize);  // chunk edge, terrain-local units
  const Int3 grid = terrain.voxels().chunkGrid();
  const float gridMax[3] = {float(grid.x) * cs, float(grid.y) * cs, float(grid.z) * cs};
  // Chunk-walk tolerance: rays within this distance of a border also visit the other side.
  const float eps = cs * 1e-4f;

  // Clip to the terrain's chunk grid.
  float t0 = 0.f, t1 = float(maxDistance);
  for (int i = 0; i < 3; ++i) {
    if (d[i] == 0.f) {
      if (o[i] < -eps || o[i] > gridMax[i] + eps) return RayWalk::Miss;
      continue;
    }
    float a = (-eps - o[i]) / d[i], b = (gridMax[i] + eps - o[i]) / d[i];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  if (!(t0 <= t1)) return RayWalk::Miss;

  // 3D DDA over chunk cells (Amanatides-Woo).
  const Vec3f start = o + d * t0;
  int cell[3], step[3];
  float tNext[3], tDelta[3];
  const int gridN[3] = {grid.x, grid.y, grid.z};
  for (int i = 0; i < 3; ++i) {
    cell[i] = std::clamp(int(std::floor(start[i] / cs)), 0, gridN[i] - 1);
    if (d[i] > 0.f) {
      step[i] = 1;
      tNext[i] = (float(cell[i] + 1) * cs - o[i]) / d[i];
      tDelta[i] = cs / d[i];
    } else if (d[i] < 0.f) {
      step[i] = -1;
      tNext[i] = (float(cell[i]) * cs - o[i]) / d[i];
      tDelta[i] = -cs / d[i];
    } else {
      step[i] = 0;
      tNext[i] = std::numeric_limits<float>::infinity();
      tDelta[i] = std::numeric_limits<float>::infinity();
    }
  }

  const BitmaskBroadphase& bp = terrain.broadphase();
  RecentChunks recent;
  bool found = false;
  double best = maxDistance;
  float tEnter = t0;
  for (;;) {
    const float tExit = std::min({tNext[0], tNext[1], tNext[2], t1});
    if (stats) ++stats->chunksStepped;
    // Which neighbours does the ray graze inside this cell? (within eps of a cell face)
    int lo[3], hi[3];
    for (int i = 0; i < 3; ++i) {
      const float a = o[i] + d[i] * tEnter, b = o[i] + d[i] * tExit;
      const float mn = std::min(a, b), mx = std::max(a, b);
      lo[i] = (mn - float(cell[i]) * cs <= eps && cell[i] > 0) ? -1 : 0;
      hi[i] = (float(cell[i] + 1) * cs - mx <= eps && cell[i] + 1 < gridN[i]) ? 1 : 0;
    }
    for (int dy = lo[1]; dy <= hi[1]; ++dy)
      for (int dz = lo[2]; dz <= hi[2]; ++dz)
        for (int dx = lo[0]; dx <= hi[0]; ++dx) {
          const Int3 c{cell[0] + dx, cell[1] + dy, cell[2] + dz};
          const uint64_t key = chunkKey(c);
          if (recent.seen(key)) continue;
          recent.add(key);
          // Only masked chunks with solid bits can hold triangles (all-solid chunks have none).
          const ChunkBitmask* m = bp.masks(c);
          if (!m) continue;
          uint64_t any = 0;
          for (uint64_t s : m->solid) any |= s;
          if (!any) continue;
          const ChunkCollision* at = chunkAt(c);
          if (!at) return RayWalk::Incomplete;
          const ChunkCollision& cc = *at;
          if (cc.mesh.triangleCount() == 0) continue;
          if (stats) ++stats->chunksTraced;
          const RigidTransform xf = terrain.chunkTransform(c);
          const Ray local = xf.rayToLocal(origin, unitDir, float(best));
          KdRayHit h;
          if (cc.tree.raycastClosest(cc.mesh.view(), local, h) && (!found || double(h.t) < best)) {
            found = true;
            best = h.t;
            Vec3f a, b, e;
            cc.mesh.view().corners(h.triangle, a, b, e);
            hit.distance = h.t;
            hit.position = origin + unitDir * double(h.t);
            hit.normal = xf.directionToWorld((b - a).cross(e - a).normalized());
            hit.material = cc.mesh.materials[h.triangle];
            hit.chunk = c;
            hit.triangle = h.triangle;
          }
        }
    // Everything beyond this cell starts after tExit; a hit before it cannot be beaten.
    if (found && best <= double(tExit)) break;
    int axis = 0;
    if (tNext[1] < tNext[axis]) axis = 1;
    if (tNext[2] < tNext[axis]) axis = 2;
    if (tNext[axis] > t1) break;
    cell[axis] += step[axis];
    if (cell[axis] < 0 || cell[axis] >= gridN[axis]) break;
    tEnter = tNext[axis];
    tNext[axis] += tDelta[axis];
  }
  return found ? RayWalk::Hit : RayWalk::Miss;
}

}  // namespace

bool raycastTerrain(Terrain& terrain, const Vec3d& origin, const Vec3d& dir, double maxDistance, TerrainRayHit& hit,
                    TerrainRayStats* stats) {
  return walkRay(terrain, origin, dir, maxDistance, hit, stats, [&](const Int3& c) { return &terrain.chunkCollision(c); }) ==
         RayWalk::Hit;
}

std::optional<bool> raycastTerrainCached(const Terrain& terrain, const Vec3d& origin, const Vec3d& dir, double maxDistance,
                                         TerrainRayHit& hit) {
  const RayWalk r = walkRay(terrain, origin, dir, maxDistance, hit, nullptr,
                            [&](const Int3& c) { return terrain.cachedChunkCollision(c); });
  if (r == RayWalk::Incomplete) return std::nullopt;
  return r == RayWalk::Hit;
}

}  // namespace bw
