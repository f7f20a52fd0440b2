#include <cmath>
#include <gtest/gtest.h>
#include <map>
#include <tuple>

#include "collision/content/terrain_generator.h"
#include "collision/terrain/chunk_mesher.h"

namespace bw {
namespace {

using LatticeKey = std::tuple<int, int, int>;

LatticeKey toLattice(const Int3& chunk, const Vec3f& p, float voxelSize) {
  return {chunk.x * kChunkSize + int(std::lround(p.x() / voxelSize)), chunk.y * kChunkSize + int(std::lround(p.y() / voxelSize)),
          chunk.z * kChunkSize + int(std::lround(p.z() / voxelSize))};
}

/// Adds every directed edge of every chunk's mesh: +1 for (a, b) with a < b, -1 otherwise.
/// A closed, consistently wound surface cancels to zero on every edge.
void accumulateEdges(const VoxelTerrain& t, float voxelSize, std::map<std::pair<LatticeKey, LatticeKey>, int>& edges,
                     size_t& triangles) {
  ChunkNeighbourhood n;
  ChunkMesh mesh;
  for (int cy = 0; cy < t.chunkGrid().y; ++cy)
    for (int cz = 0; cz < t.chunkGrid().z; ++cz)
      for (int cx = 0; cx < t.chunkGrid().x; ++cx) {
        const Int3 c{cx, cy, cz};
        t.gatherNeighbourhood(c, n);
        meshChunk(n, voxelSize, mesh);
        triangles += mesh.triangleCount();
        for (uint32_t tri = 0; tri < mesh.triangleCount(); ++tri) {
          LatticeKey p[3];
          for (int k = 0; k < 3; ++k) {
            const Vec3f v = mesh.corner(tri, k);
            // Geometry never leaves the chunk's closed box.
            for (int i = 0; i < 3; ++i) {
              ASSERT_GE(v[i], 0.f);
              ASSERT_LE(v[i], kChunkSize * voxelSize);
            }
            p[k] = toLattice(c, v, voxelSize);
          }
          for (int k = 0; k < 3; ++k) {
            const LatticeKey& a = p[k];
            const LatticeKey& b = p[(k + 1) % 3];
            if (a < b) edges[{a, b}] += 1;
            else edges[{b, a}] -= 1;
          }
        }
      }
}

TEST(ChunkMesher, WatertightAcrossChunkBorders) {
  for (uint32_t seed : {3u, 4u}) {
    VoxelTerrain t({29, 19, 27});
    generateRandomTerrain(t, seed, 0.03f);
    const float voxelSize = seed == 3 ? 1.f : 0.25f;
    std::map<std::pair<LatticeKey, LatticeKey>, int> edges;
    size_t triangles = 0;
    accumulateEdges(t, voxelSize, edges, triangles);
    ASSERT_GT(triangles, 1000u);
    for (const auto& [edge, balance] : edges) {
      ASSERT_EQ(balance, 0) << "open edge at (" << std::get<0>(edge.first) << "," << std::get<1>(edge.first) << ","
                            << std::get<2>(edge.first) << ")";
    }
  }
}

TEST(ChunkMesher, RemovingOneChunksTrianglesOpensTheSurface) {
  // The edge balance must detect a missing face, or the watertight test proves nothing.
  VoxelTerrain t({16, 16, 16});
  t.fillBox({6, 6, 6}, {9, 9, 9}, Voxel::make(kMaterialFirstSolid));  // a cube across 8 chunks
  std::map<std::pair<LatticeKey, LatticeKey>, int> edges;
  size_t triangles = 0;
  accumulateEdges(t, 1.f, edges, triangles);
  EXPECT_EQ(triangles, 6u * 16u * 2u);
  ChunkNeighbourhood n;
  ChunkMesh mesh;
  t.gatherNeighbourhood({0, 0, 0}, n);
  meshChunk(n, 1.f, mesh);
  const LatticeKey a = toLattice({0, 0, 0}, mesh.corner(0, 0), 1.f), b = toLattice({0, 0, 0}, mesh.corner(0, 1), 1.f);
  if (a < b) edges[{a, b}] -= 1;
  else edges[{b, a}] += 1;
  bool open = false;
  for (const auto& e : edges) open |= e.second != 0;
  EXPECT_TRUE(open);
}

TEST(ChunkMesher, FacesPointFromSolidIntoNonSolidAndMatchExposedFaceCount) {
  VoxelTerrain t({24, 16, 24});
  generateRandomTerrain(t, 11, 0.03f);
  ChunkNeighbourhood n;
  ChunkMesh mesh;
  for (int cz = 0; cz < 3; ++cz)
    for (int cx = 0; cx < 3; ++cx)
      for (int cy = 0; cy < 2; ++cy) {
        const Int3 c{cx, cy, cz};
        t.gatherNeighbourhood(c, n);
        meshChunk(n, 1.f, mesh);
        int exposed = 0;
        for (int y = 0; y < 8; ++y)
          for (int z = 0; z < 8; ++z)
            for (int x = 0; x < 8; ++x) {
              const Int3 g{c.x * 8 + x, c.y * 8 + y, c.z * 8 + z};
              if (!t.get(g).isSolid()) continue;
              const Int3 d[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
              for (const Int3& s : d) exposed += !t.get({g.x + s.x, g.y + s.y, g.z + s.z}).isSolid();
            }
        ASSERT_EQ(mesh.triangleCount(), uint32_t(2 * exposed));
        for (uint32_t tri = 0; tri < mesh.triangleCount(); ++tri) {
          const Vec3f a = mesh.corner(tri, 0), b = mesh.corner(tri, 1), cc = mesh.corner(tri, 2);
          const Vec3f nrm = (b - a).cross(cc - a).normalized();
          const Vec3f centre = (a + b + cc) / 3.f + Vec3f(float(c.x * 8), float(c.y * 8), float(c.z * 8));
          const Vec3f out = centre + 0.25f * nrm, in = centre - 0.25f * nrm;
          const Voxel vin = t.get({int(std::floor(in.x())), int(std::floor(in.y())), int(std::floor(in.z()))});
          ASSERT_TRUE(vin.isSolid());
          ASSERT_EQ(vin.material, mesh.materials[tri]);
          ASSERT_FALSE(t.get({int(std::floor(out.x())), int(std::floor(out.y())), int(std::floor(out.z()))}).isSolid());
        }
      }
}

TEST(ChunkMesher, EmptyAndEnclosedChunksHaveNoTriangles) {
  VoxelTerrain t({24, 24, 24});
  ChunkNeighbourhood n;
  ChunkMesh mesh;
  t.gatherNeighbourhood({1, 1, 1}, n);
  meshChunk(n, 1.f, mesh);
  EXPECT_EQ(mesh.triangleCount(), 0u);
  t.fillBox({0, 0, 0}, {23, 23, 23}, Voxel::make(kMaterialFirstSolid));
  t.gatherNeighbourhood({1, 1, 1}, n);
  meshChunk(n, 1.f, mesh);
  EXPECT_EQ(mesh.triangleCount(), 0u);
  // A border chunk of a full terrain is closed by faces on the terrain boundary.
  t.gatherNeighbourhood({0, 1, 1}, n);
  meshChunk(n, 1.f, mesh);
  EXPECT_EQ(mesh.triangleCount(), 2u * 64u);
  // Water next to solid is not solid: the solid face toward water is emitted.
  t.set({12, 12, 12}, Voxel::make(kMaterialWater));
  t.gatherNeighbourhood({1, 1, 1}, n);
  meshChunk(n, 1.f, mesh);
  EXPECT_EQ(mesh.triangleCount(), 12u);
  EXPECT_LE(mesh.vertices.size(), size_t(9 * 9 * 9));
}

}  // namespace
}  // namespace bw
