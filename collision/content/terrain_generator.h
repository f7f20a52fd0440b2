#pragma once
/// Seeded terrain workloads shared by tests, benchmarks and scenes (one generator, so a figure
/// measured in a benchmark is measured on the terrain the tests check).
#include <cstdint>
#include <vector>

#include "collision/terrain/triangle_mesh.h"
#include "collision/terrain/voxel_terrain.h"

namespace bw {

/// Bumpy ground a third of the height up, a water layer two voxels above it, then random small
/// solid, water and air boxes (`blobDensity` boxes per 8 voxels): every chunk kind appears
/// (empty, all solid, masked, water, overhangs, caves). Deterministic for a seed.
void generateRandomTerrain(VoxelTerrain& t, uint32_t seed, float blobDensity = 0.01f);

/// Rolling hills (sum of seeded sines, heights in [base, base + amplitude]) with water filling
/// every column up to `waterLevel`. One fillBox per column: fast enough for 1024^2 columns.
void generateRollingHills(VoxelTerrain& t, uint32_t seed, int base, int amplitude, int waterLevel);

/// A quarry, z up: solid ground 4 voxels thick over the whole terrain, then (back to front in
/// y) a cliff a fifth of the depth thick rising to 3/4 of the height, a fin 2 voxels thick in
/// front of it, and a row of 4 x 4 pillars of seeded heights in front of that: what carving
/// cuts into slabs and pillar tops that break free. Needs at least 32 x 32 x 16 voxels
/// (InvalidInput otherwise). Materials 2 (ground), 3 (cliff), 4 (fin), 5 (pillars).
void generateQuarry(VoxelTerrain& t, uint32_t seed);

/// A smooth heightfield triangle mesh with 32-bit indices: (n + 1)^2 vertices, 2 n^2 triangles.
struct HeightfieldMesh {
  std::vector<Vec3f> vertices;   ///< grid vertices, spacing apart in X and Z
  std::vector<uint32_t> indices; ///< 3 per triangle
  /// Read-only view.
  TriangleMeshView view() const {
    return {vertices.data(), nullptr, indices.data(), uint32_t(vertices.size()), uint32_t(indices.size() / 3)};
  }
};
/// A heightfield of n x n quads, heights from seeded sines with the given amplitude.
HeightfieldMesh makeHeightfieldMesh(uint32_t n, float spacing, float amplitude, uint32_t seed);
/// Height of that heightfield's surface function at (x, z) (for placing queries).
float heightfieldHeight(float x, float z, float amplitude, uint32_t seed);

}  // namespace bw
