#include <cmath>
#include <gtest/gtest.h>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include "collision/content/terrain_generator.h"
#include "collision/core/argument_checks.h"
#include "collision/terrain/chunk_mesher.h"
#include "collision/terrain/ray_triangle.h"
#include "collision/terrain/terrain_queries.h"

namespace bw {
namespace {

/// Every chunk's triangles in terrain-local coordinates, for brute-force references.
struct AllTriangles {
  std::vector<Vec3f> corners;  // 3 per triangle
  std::vector<uint8_t> materials;
};

AllTriangles collectTriangles(const VoxelTerrain& t, float voxelSize) {
  AllTriangles all;
  ChunkNeighbourhood n;
  ChunkMesh mesh;
  for (int cy = 0; cy < t.chunkGrid().y; ++cy)
    for (int cz = 0; cz < t.chunkGrid().z; ++cz)
      for (int cx = 0; cx < t.chunkGrid().x; ++cx) {
        t.gatherNeighbourhood({cx, cy, cz}, n);
        meshChunk(n, voxelSize, mesh);
        const Vec3f off = Vec3f(float(cx), float(cy), float(cz)) * (8.f * voxelSize);
        for (uint32_t i = 0; i < mesh.indices.size(); ++i) all.corners.push_back(mesh.vertex(mesh.indices[i]) + off);
        all.materials.insert(all.materials.end(), mesh.materials.begin(), mesh.materials.end());
      }
  return all;
}

bool bruteRay(const AllTriangles& all, const Vec3f& o, const Vec3f& d, float maxT, float& best, uint8_t& material) {
  const WatertightRay wr = WatertightRay::make(o, d);
  bool found = false;
  best = maxT;
  for (size_t t = 0; t < all.materials.size(); ++t) {
    float th;
    if (wr.intersect(all.corners[3 * t], all.corners[3 * t + 1], all.corners[3 * t + 2], 0.f, best, th) && (!found || th < best)) {
      best = th;
      material = all.materials[t];
      found = true;
    }
  }
  return found;
}

void expectRayMatches(Terrain& terrain, const AllTriangles& all, const Vec3f& o, const Vec3f& dir, float maxT, int& hits) {
  const Vec3f d = dir.normalized();
  float want;
  uint8_t wantMaterial = 0;
  const bool wantHit = bruteRay(all, o, d, maxT, want, wantMaterial);
  TerrainRayHit hit;
  const bool gotHit = raycastTerrain(terrain, o.cast<double>(), d.cast<double>(), maxT, hit);
  ASSERT_EQ(gotHit, wantHit) << "origin " << o.transpose() << " dir " << d.transpose();
  if (!gotHit) return;
  ++hits;
  // Chunk-local and terrain-local floats round differently: compare with a tolerance.
  ASSERT_NEAR(hit.distance, want, 1e-4 * (1.0 + want)) << "origin " << o.transpose() << " dir " << d.transpose();
  EXPECT_NEAR(hit.normal.norm(), 1.f, 1e-5f);
  // Blocky faces: the normal is a unit axis (two-sided hits: a ray from inside solid reports
  // the face it leaves through, whose normal points along the ray).
  EXPECT_NEAR(hit.normal.cwiseAbs().maxCoeff(), 1.f, 1e-5f);
}

TEST(TerrainRaycast, ClosestHitMatchesBruteForceOverAllChunks) {
  Terrain terrain({40, 24, 40}, 1.f);
  terrain.edit({0, 0, 0}, {39, 23, 39}, [](VoxelTerrain& v) { generateRandomTerrain(v, 31, 0.02f); });
  const AllTriangles all = collectTriangles(terrain.voxels(), 1.f);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> pos(-10.f, 50.f), dir(-1.f, 1.f);
  int hits = 0;
  for (int q = 0; q < 400; ++q) {
    const Vec3f o(pos(rng), pos(rng) * 0.5f, pos(rng));
    Vec3f d(dir(rng), dir(rng), dir(rng));
    if (d.norm() < 1e-3f) d = Vec3f(0, -1, 0);
    expectRayMatches(terrain, all, o, d, q % 3 == 0 ? 15.f : 200.f, hits);
  }
  EXPECT_GT(hits, 100);
}

TEST(TerrainRaycast, TheWalkThroughBuiltChunksAnswersAsTheBuildingWalkOrDefers) {
  // raycastTerrainCached only reads: it answers exactly as raycastTerrain when every chunk the
  // walk needs is built, and defers (nullopt) when one is not, building nothing itself.
  Terrain terrain({40, 24, 40}, 1.f);
  terrain.edit({0, 0, 0}, {39, 23, 39}, [](VoxelTerrain& v) { generateRandomTerrain(v, 17, 0.02f); });
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> pos(-10.f, 50.f), dir(-1.f, 1.f);
  int deferred = 0, answeredBefore = 0, hits = 0;
  for (int q = 0; q < 300; ++q) {
    const Vec3d o(pos(rng), pos(rng) * 0.5f, pos(rng));
    Vec3d d(dir(rng), dir(rng), dir(rng));
    if (d.norm() < 1e-3) d = Vec3d(0, -1, 0);
    const double maxT = q % 3 == 0 ? 6.0 : 80.0;
    const size_t cachedBefore = terrain.cache().size();
    const ChunkCacheStats statsBefore = terrain.cache().stats();
    TerrainRayHit before, built, after;
    const std::optional<bool> early = raycastTerrainCached(terrain, o, d, maxT, before);
    EXPECT_EQ(terrain.cache().size(), cachedBefore);
    EXPECT_EQ(terrain.cache().stats().misses, statsBefore.misses);
    EXPECT_EQ(terrain.cache().stats().hits, statsBefore.hits);
    const bool hit = raycastTerrain(terrain, o, d, maxT, built);
    if (early) {
      ++answeredBefore;
      ASSERT_EQ(*early, hit) << q;
      if (hit) EXPECT_EQ(before.distance, built.distance) << q;
    } else {
      ++deferred;
      EXPECT_GT(terrain.cache().size(), cachedBefore) << q << ": deferred, yet the building walk built nothing";
    }
    const std::optional<bool> late = raycastTerrainCached(terrain, o, d, maxT, after);
    ASSERT_TRUE(late.has_value()) << q;
    ASSERT_EQ(*late, hit) << q;
    if (hit) {
      ++hits;
      EXPECT_EQ(after.distance, built.distance) << q;
      EXPECT_EQ(after.triangle, built.triangle) << q;
    }
  }
  EXPECT_GT(deferred, 20);
  EXPECT_GT(answeredBefore, 20);
  EXPECT_GT(hits, 50);
}

TEST(TerrainRaycast, RaysExactlyAlongChunkBordersAndAxisParallel) {
  Terrain terrain({32, 16, 32}, 1.f);
  // Columns of different heights meeting at chunk borders x = 8, 16 and z = 8, 16.
  for (int z = 0; z < 32; ++z)
    for (int x = 0; x < 32; ++x) terrain.fillBox({x, 0, z}, {x, 2 + ((x / 8 + z / 8) % 3) * 2, z}, Voxel::make(uint8_t(2 + x / 8)));
  const AllTriangles all = collectTriangles(terrain.voxels(), 1.f);
  int hits = 0;
  for (int b = 0; b <= 32; b += 8) {
    for (float s = 0.f; s <= 32.f; s += 2.f) {
      // Straight down on border lines, on border corners, and in border planes.
      expectRayMatches(terrain, all, Vec3f(float(b), 15.f, s), Vec3f(0, -1, 0), 100.f, hits);
      expectRayMatches(terrain, all, Vec3f(s, 15.f, float(b)), Vec3f(0, -1, 0), 100.f, hits);
      expectRayMatches(terrain, all, Vec3f(float(b), 15.f, s), Vec3f(0, -1, 0.5f), 100.f, hits);
      expectRayMatches(terrain, all, Vec3f(float(b), 15.f, s), Vec3f(0, -0.3f, -1.f), 100.f, hits);
      // Horizontal rays along border planes at face heights (grazing the tops).
      expectRayMatches(terrain, all, Vec3f(-3.f, 4.f, float(b)), Vec3f(1, 0, 0), 100.f, hits);
      expectRayMatches(terrain, all, Vec3f(float(b), 6.f, -3.f), Vec3f(0, 0, 1), 100.f, hits);
      expectRayMatches(terrain, all, Vec3f(s, 3.f, float(b)), Vec3f(1, 0, 1), 100.f, hits);
    }
  }
  EXPECT_GT(hits, 150);
  // The step case: on x = 24 the DDA cell is chunk 3 (top at y = 3 for z < 8) but the ray
  // touches the edge of chunk 2's higher top (y = 7), which must win.
  TerrainRayHit hit;
  ASSERT_TRUE(raycastTerrain(terrain, Vec3d(24.0, 15.0, 3.5), Vec3d(0, -1, 0), 100, hit));
  float want;
  uint8_t m;
  ASSERT_TRUE(bruteRay(all, Vec3f(24.f, 15.f, 3.5f), Vec3f(0, -1, 0), 100.f, want, m));
  EXPECT_NEAR(want, 8.f, 1e-6f);
  EXPECT_NEAR(hit.distance, want, 1e-5);
}

TEST(TerrainRaycast, PlacementFarFromOriginAndRotatedGivesTheSameHits) {
  const RigidTransform place{Vec3d(1.0e7, -2.5e6, 3.0e7), Quatf(Eigen::AngleAxisf(0.7f, Vec3f(0.3f, 1.f, 0.2f).normalized()))};
  Terrain local({32, 16, 32}, 0.5f);
  Terrain placed({32, 16, 32}, 0.5f, place);
  for (Terrain* t : {&local, &placed}) t->edit({0, 0, 0}, {31, 15, 31}, [](VoxelTerrain& v) { generateRandomTerrain(v, 41, 0.02f); });
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> pos(-2.f, 18.f), dir(-1.f, 1.f);
  int hits = 0;
  for (int q = 0; q < 300; ++q) {
    const Vec3d o(pos(rng), pos(rng) * 0.5, pos(rng));
    const Vec3d d = Vec3d(dir(rng), dir(rng) - 0.5, dir(rng)).normalized();
    TerrainRayHit a, b;
    const bool ha = raycastTerrain(local, o, d, 100, a);
    const bool hb = raycastTerrain(placed, place.translation + place.rotation.cast<double>() * o, place.rotation.cast<double>() * d, 100, b);
    ASSERT_EQ(ha, hb) << q;
    if (!ha) continue;
    ++hits;
    EXPECT_NEAR(a.distance, b.distance, 1e-3);
    EXPECT_LT((place.directionToWorld(a.normal) - b.normal).norm(), 1e-3f);
    EXPECT_EQ(a.material, b.material);
  }
  EXPECT_GT(hits, 100);
}

TEST(TerrainRaycast, RejectsInvalidInputAndHandlesEmptyTerrain) {
  Terrain terrain({16, 16, 16}, 1.f);
  TerrainRayHit hit;
  EXPECT_FALSE(raycastTerrain(terrain, Vec3d(1, 10, 1), Vec3d(0, -1, 0), 100, hit));
  EXPECT_THROW(raycastTerrain(terrain, Vec3d(1, 10, 1), Vec3d(0, 0, 0), 100, hit), InvalidInput);
  EXPECT_THROW(raycastTerrain(terrain, Vec3d(NAN, 10, 1), Vec3d(0, -1, 0), 100, hit), InvalidInput);
  EXPECT_THROW(raycastTerrain(terrain, Vec3d(1, 10, 1), Vec3d(0, -1, 0), -1, hit), InvalidInput);
  // Fully solid: no surface inside, the boundary faces are the only triangles.
  terrain.fillBox({0, 0, 0}, {15, 15, 15}, Voxel::make(kMaterialFirstSolid));
  ASSERT_TRUE(raycastTerrain(terrain, Vec3d(5, 30, 5), Vec3d(0, -1, 0), 100, hit));
  EXPECT_NEAR(hit.distance, 14.0, 1e-5);
  EXPECT_NEAR(hit.normal.y(), 1.f, 1e-6f);
  EXPECT_FALSE(raycastTerrain(terrain, Vec3d(5, 30, 5), Vec3d(0, -1, 0), 13.9, hit));
  // An unlimited ray, and one starting far outside the terrain.
  ASSERT_TRUE(raycastTerrain(terrain, Vec3d(5, 30, 5), Vec3d(0, -1, 0), std::numeric_limits<double>::infinity(), hit));
  EXPECT_NEAR(hit.distance, 14.0, 1e-5);
  ASSERT_TRUE(raycastTerrain(terrain, Vec3d(-1000, 8.5, 3.5), Vec3d(1, 0, 0), std::numeric_limits<double>::infinity(), hit));
  EXPECT_NEAR(hit.distance, 1000.0, 1e-3);
  EXPECT_NEAR(hit.normal.x(), -1.f, 1e-6f);
}

}  // namespace
}  // namespace bw
