#include <gtest/gtest.h>
#include <memory>

#include "collision/content/terrain_generator.h"
#include "collision/terrain/chunk_cache.h"
#include "collision/terrain/chunk_mesher.h"
#include "collision/terrain/terrain.h"
#include "collision/terrain/terrain_queries.h"

namespace bw {
namespace {

std::unique_ptr<VoxelTerrain> bumpyTerrain() {
  auto t = std::make_unique<VoxelTerrain>(Int3{64, 16, 16});
  generateRandomTerrain(*t, 21, 0.02f);
  return t;
}

TEST(ChunkCache, BuildsLazilyAndCountsHits) {
  const auto holder = bumpyTerrain();
  const VoxelTerrain& t = *holder;
  ChunkCache cache(size_t(1) << 30);
  EXPECT_EQ(cache.size(), 0u);
  EXPECT_EQ(cache.bytes(), 0u);
  const ChunkCollision& a = cache.get({1, 0, 1}, t, 1.f);
  const uint32_t tris = a.mesh.triangleCount();
  EXPECT_GT(tris, 0u);
  EXPECT_EQ(cache.stats().misses, 1u);
  EXPECT_EQ(cache.get({1, 0, 1}, t, 1.f).mesh.triangleCount(), tris);
  EXPECT_EQ(cache.stats().hits, 1u);
  EXPECT_DOUBLE_EQ(cache.stats().hitRate(), 0.5);
  EXPECT_EQ(cache.bytes(), cache.get({1, 0, 1}, t, 1.f).bytes());
  // The cached data equals a fresh build.
  ChunkNeighbourhood n;
  ChunkMesh fresh;
  t.gatherNeighbourhood({1, 0, 1}, n);
  meshChunk(n, 1.f, fresh);
  EXPECT_EQ(fresh.vertices, cache.get({1, 0, 1}, t, 1.f).mesh.vertices);
  EXPECT_EQ(fresh.indices, cache.get({1, 0, 1}, t, 1.f).mesh.indices);
}

TEST(ChunkCache, EvictsLeastRecentlyUsedWithinBudget) {
  const auto holder = bumpyTerrain();
  const VoxelTerrain& t = *holder;
  ChunkCache probe(size_t(1) << 30);
  size_t perChunk = 0;
  for (int x = 0; x < 8; ++x) perChunk = std::max(perChunk, probe.get({x, 0, 0}, t, 1.f).bytes());
  // Room for three of the largest chunks.
  ChunkCache cache(3 * perChunk);
  cache.get({0, 0, 0}, t, 1.f);
  cache.get({1, 0, 0}, t, 1.f);
  cache.get({2, 0, 0}, t, 1.f);
  EXPECT_EQ(cache.stats().evictions, 0u);
  cache.get({0, 0, 0}, t, 1.f);  // 0 becomes most recent; 1 is now the oldest
  cache.get({3, 0, 0}, t, 1.f);
  EXPECT_LE(cache.bytes(), cache.budget());
  EXPECT_TRUE(cache.contains({0, 0, 0}));
  EXPECT_TRUE(cache.contains({3, 0, 0}));
  EXPECT_FALSE(cache.contains({1, 0, 0}));
  EXPECT_GE(cache.stats().evictions, 1u);
  for (int round = 0; round < 3; ++round) {
    for (int x = 0; x < 8; ++x) {
      cache.get({x, 0, 1}, t, 1.f);
      ASSERT_LE(cache.bytes(), cache.budget());
    }
  }
  // Shrinking the budget evicts at once; a zero budget still returns valid data.
  cache.setBudget(0);
  EXPECT_EQ(cache.size(), 0u);
  EXPECT_GT(cache.get({2, 0, 1}, t, 1.f).mesh.triangleCount(), 0u);
  EXPECT_EQ(cache.size(), 1u);
}

TEST(ChunkCache, EditsInvalidateTheChunkAndItsNeighbours) {
  Terrain terrain({32, 16, 32}, 1.f);
  terrain.fillBox({0, 0, 0}, {31, 3, 31}, Voxel::make(kMaterialFirstSolid));
  TerrainRayHit hit;
  // A ray down a column on the x = 8 border between chunks 0 and 1.
  ASSERT_TRUE(raycastTerrain(terrain, Vec3d(8.5, 15, 3.5), Vec3d(0, -1, 0), 100, hit));
  EXPECT_NEAR(hit.distance, 11.0, 1e-5);
  EXPECT_GT(terrain.cache().size(), 0u);
  EXPECT_TRUE(terrain.cache().contains({1, 0, 0}));
  // Dig a hole under the ray. Voxel x = 8 sits on chunk 1's low border, so chunk 0 (which reads
  // it through its neighbourhood) is invalidated too.
  terrain.cache().get({0, 0, 0}, terrain.voxels(), 1.f);
  terrain.fillBox({8, 2, 3}, {8, 3, 3}, Voxel{});
  EXPECT_FALSE(terrain.cache().contains({1, 0, 0}));
  EXPECT_FALSE(terrain.cache().contains({0, 0, 0}));
  EXPECT_GE(terrain.cache().stats().invalidations, 2u);
  ASSERT_TRUE(raycastTerrain(terrain, Vec3d(8.5, 15, 3.5), Vec3d(0, -1, 0), 100, hit));
  EXPECT_NEAR(hit.distance, 13.0, 1e-5);
  // A far-away edit leaves the cached chunk alone.
  const uint64_t inv = terrain.cache().stats().invalidations;
  terrain.setVoxel({30, 10, 30}, Voxel::make(kMaterialFirstSolid));
  EXPECT_TRUE(terrain.cache().contains({1, 0, 0}));
  EXPECT_EQ(terrain.cache().stats().invalidations, inv);
}

TEST(ChunkCache, InvalidateAllAndLargeEditsWalkEntries) {
  const auto holder = bumpyTerrain();
  const VoxelTerrain& t = *holder;
  ChunkCache cache(size_t(1) << 30);
  for (int x = 0; x < 8; ++x) cache.get({x, 0, 0}, t, 1.f);
  cache.invalidateAround({0, 0, 0}, {63, 15, 15});  // range larger than the cache: walks entries
  EXPECT_EQ(cache.size(), 0u);
  EXPECT_EQ(cache.bytes(), 0u);
  for (int x = 0; x < 8; ++x) cache.get({x, 0, 0}, t, 1.f);
  cache.invalidateAll();
  EXPECT_EQ(cache.size(), 0u);
  EXPECT_EQ(cache.stats().invalidations, 16u);
}

}  // namespace
}  // namespace bw
