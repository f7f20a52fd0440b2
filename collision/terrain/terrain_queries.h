#pragma once
/// Ray queries against a voxel terrain (world space in, world space out).
#include <cstdint>
#include <optional>

#include "collision/terrain/terrain.h"

namespace bw {

/// Closest hit of a ray against the terrain's solid surface.
struct TerrainRayHit {
  double distance;    ///< along the normalised direction, world units
  Vec3d position;     ///< world hit point
  Vec3f normal;       ///< world unit normal of the hit triangle, pointing out of the terrain
  uint8_t material;   ///< solid material of the hit triangle
  Int3 chunk;         ///< chunk holding the triangle
  uint32_t triangle;  ///< triangle index in that chunk's mesh
};

/// Counters of one raycast (tests and benchmarks).
struct TerrainRayStats {
  uint32_t chunksStepped = 0;  ///< chunk cells walked along the ray
  uint32_t chunksTraced = 0;   ///< chunks whose kD tree was traversed
};

/// Closest solid hit along origin + t * normalize(dir), t in [0, maxDistance]. Chunks are
/// walked front to back through the chunk grid; only chunks whose broadphase mask has solid
/// bits are meshed (lazily, through the cache) and traced; the walk stops as soon as the best
/// hit lies before the current chunk's exit. A ray running within float rounding of a chunk
/// border also traces the chunk on the other side, so rays exactly along borders find
/// geometry owned by either chunk. maxDistance may be +inf. Throws InvalidInput for NaN/inf
/// origin or direction, a zero direction, or a NaN or negative maxDistance.
bool raycastTerrain(Terrain& terrain, const Vec3d& origin, const Vec3d& dir, double maxDistance, TerrainRayHit& hit,
                    TerrainRayStats* stats = nullptr);

/// The same ray through the chunks the cache holds already, reading only (safe on many threads
/// while nothing edits the terrain or fills its cache): whether it hits, exactly as
/// raycastTerrain answers, or nullopt when the walk reached a chunk that would have to be built
/// first (then raycastTerrain answers).
std::optional<bool> raycastTerrainCached(const Terrain& terrain, const Vec3d& origin, const Vec3d& dir, double maxDistance,
                                         TerrainRayHit& hit);

}  // namespace bw
