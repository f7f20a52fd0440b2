#include <algorithm>
#include <gtest/gtest.h>
#include <random>

#include "collision/content/terrain_generator.h"
#include "collision/terrain/bitmask_broadphase.h"

namespace bw {
namespace {

/// Brute force: the dilated mask bit of voxel v is set when a voxel within one step of v is
/// solid (water), so a range touches solid iff a solid voxel lies in the range grown by one.
TerrainOverlap bruteForce(const VoxelTerrain& t, const VoxelRange& r) {
  TerrainOverlap o;
  for (int y = r.lo.y - 1; y <= r.hi.y + 1; ++y) {
    for (int z = r.lo.z - 1; z <= r.hi.z + 1; ++z) {
      for (int x = r.lo.x - 1; x <= r.hi.x + 1; ++x) {
        const Voxel v = t.get({x, y, z});
        o.solid |= v.isSolid();
        o.water |= v.isWater();
      }
    }
  }
  return o;
}

Aabb randomBox(std::mt19937& rng, const Int3& size, float voxelSize) {
  std::uniform_real_distribution<float> u(-0.2f, 1.2f);
  const bool large = rng() % 4 == 0;
  std::uniform_real_distribution<float> e(0.f, large ? 20.f : 1.5f);
  const Vec3f lo(u(rng) * float(size.x) * voxelSize, u(rng) * float(size.y) * voxelSize, u(rng) * float(size.z) * voxelSize);
  const Vec3f ext(e(rng) * voxelSize, e(rng) * voxelSize, e(rng) * voxelSize);
  return {lo, lo + ext};
}

void expectMatchesBruteForce(const VoxelTerrain& t, const BitmaskBroadphase& bp, float voxelSize, uint32_t seed, int queries) {
  std::mt19937 rng(seed);
  int solidHits = 0, waterHits = 0, misses = 0;
  for (int q = 0; q < queries; ++q) {
    const Aabb box = randomBox(rng, t.size(), voxelSize);
    VoxelRange r;
    const bool inside = bp.voxelRangeOf(box, voxelSize, r);
    const TerrainOverlap got = bp.overlap(box, voxelSize);
    const TerrainOverlap want = inside ? bruteForce(t, r) : TerrainOverlap{};
    ASSERT_EQ(got.solid, want.solid) << "query " << q;
    ASSERT_EQ(got.water, want.water) << "query " << q;
    solidHits += got.solid;
    waterHits += got.water;
    misses += !got.solid && !got.water;
  }
  // The workload must exercise both answers, or the comparison proves nothing.
  EXPECT_GT(solidHits, queries / 20);
  EXPECT_GT(waterHits, queries / 50);
  EXPECT_GT(misses, queries / 50);
}

TEST(BitmaskBroadphase, MatchesBruteForceOnRandomTerrains) {
  for (uint32_t seed : {1u, 2u, 3u}) {
    // Sizes that are not multiples of 8 exercise partial border chunks.
    VoxelTerrain t({37 + int(seed), 27, 45});
    generateRandomTerrain(t, seed);
    BitmaskBroadphase bp(t.chunkGrid(), t.size());
    bp.rebuildAll(t);
    expectMatchesBruteForce(t, bp, seed == 2 ? 0.5f : 1.0f, seed * 100, 3000);
  }
}

TEST(BitmaskBroadphase, MatchesBruteForceAfterEditsAndEqualsFreshBuild) {
  VoxelTerrain t({40, 24, 40});
  generateRandomTerrain(t, 9);
  BitmaskBroadphase bp(t.chunkGrid(), t.size());
  bp.rebuildAll(t);
  std::mt19937 rng(99);
  for (int round = 0; round < 6; ++round) {
    for (int e = 0; e < 40; ++e) {
      const Int3 lo{int(rng() % 40), int(rng() % 24), int(rng() % 40)};
      const Int3 hi{std::min(39, lo.x + int(rng() % 10)), std::min(23, lo.y + int(rng() % 4)), std::min(39, lo.z + int(rng() % 10))};
      const uint32_t k = rng() % 3;
      const Voxel v = k == 0 ? Voxel{} : (k == 1 ? Voxel::make(kMaterialWater) : Voxel::make(kMaterialFirstSolid));
      t.fillBox(lo, hi, v);
      bp.rebuildAround(t, lo, hi);
    }
    expectMatchesBruteForce(t, bp, 1.0f, 1000 + round, 1500);
    // Incremental rebuilds must leave exactly what a full rebuild produces.
    BitmaskBroadphase fresh(t.chunkGrid(), t.size());
    fresh.rebuildAll(t);
    ASSERT_EQ(fresh.entryCount(), bp.entryCount());
    for (int cy = 0; cy < t.chunkGrid().y; ++cy) {
      for (int cz = 0; cz < t.chunkGrid().z; ++cz) {
        for (int cx = 0; cx < t.chunkGrid().x; ++cx) {
          const Int3 c{cx, cy, cz};
          ASSERT_EQ(fresh.kind(c), bp.kind(c));
          if (const ChunkBitmask* m = fresh.masks(c)) {
            for (int y = 0; y < kChunkSize; ++y) {
              ASSERT_EQ(m->solid[y], bp.masks(c)->solid[y]);
              ASSERT_EQ(m->water[y], bp.masks(c)->water[y]);
            }
          }
        }
      }
    }
  }
}

TEST(BitmaskBroadphase, SingleVoxelDilatesIntoAllTwentySevenNeighboursAcrossChunks) {
  VoxelTerrain t({24, 24, 24});
  t.set({8, 8, 8}, Voxel::make(kMaterialFirstSolid));  // corner voxel of chunk (1,1,1)
  BitmaskBroadphase bp(t.chunkGrid(), t.size());
  bp.rebuildAll(t);
  // The dilated voxel set spans chunks 0 and 1 on every axis: 8 entries, all masked.
  EXPECT_EQ(bp.entryCount(), 8u);
  EXPECT_EQ(bp.maskedCount(), 8u);
  int bits = 0;
  for (int cy = 0; cy < 3; ++cy)
    for (int cz = 0; cz < 3; ++cz)
      for (int cx = 0; cx < 3; ++cx)
        if (const ChunkBitmask* m = bp.masks({cx, cy, cz}))
          for (int y = 0; y < 8; ++y) bits += __builtin_popcountll(m->solid[y]);
  EXPECT_EQ(bits, 27);
  EXPECT_EQ(bp.masks({0, 0, 0})->solid[7], sliceBit(7, 7));
}

TEST(BitmaskBroadphase, EmptyChunksDroppedFullChunksTaggedWithoutMasks) {
  VoxelTerrain t({64, 32, 64});
  BitmaskBroadphase bp(t.chunkGrid(), t.size());
  bp.rebuildAll(t);
  EXPECT_EQ(bp.entryCount(), 0u);
  EXPECT_FALSE(bp.overlap({Vec3f(-5, -5, -5), Vec3f(100, 100, 100)}, 1.f).solid);

  t.fillBox({0, 0, 0}, {63, 31, 63}, Voxel::make(kMaterialFirstSolid));
  bp.rebuildAll(t);
  // Interior chunks see 10^3 solid voxels; border chunks see air outside the terrain.
  EXPECT_EQ(bp.kind({3, 1, 3}), ChunkMaskKind::AllSolid);
  EXPECT_EQ(bp.masks({3, 1, 3}), nullptr);
  EXPECT_EQ(bp.kind({0, 0, 0}), ChunkMaskKind::Masked);
  EXPECT_EQ(bp.entryCount(), 8u * 4u * 8u);
  EXPECT_EQ(bp.maskedCount(), 8u * 4u * 8u - 6u * 2u * 6u);

  t.fillBox({0, 0, 0}, {63, 31, 63}, Voxel::make(kMaterialWater));
  bp.rebuildAll(t);
  EXPECT_EQ(bp.kind({3, 1, 3}), ChunkMaskKind::AllWater);
  const TerrainOverlap o = bp.overlap({Vec3f(30, 10, 30), Vec3f(31, 11, 31)}, 1.f);
  EXPECT_TRUE(o.water);
  EXPECT_FALSE(o.solid);

  t.fillBox({0, 0, 0}, {63, 31, 63}, Voxel{});
  bp.rebuildAround(t, {0, 0, 0}, {63, 31, 63});
  EXPECT_EQ(bp.entryCount(), 0u);
  EXPECT_EQ(bp.maskedCount(), 0u);
  EXPECT_EQ(t.storedChunkCount(), 0u);
}

TEST(BitmaskBroadphase, MaskedChunksCostAtMostTwoBitsPerVoxel) {
  EXPECT_LE(sizeof(ChunkBitmask) * 8, 2u * kChunkVoxels);
}

TEST(BitmaskBroadphase, SliceMaskTablesSelectExactlyTheXzRectangle) {
  const SliceMaskTables& tab = sliceMaskTables();
  for (int x0 = 0; x0 < 8; ++x0)
    for (int x1 = x0; x1 < 8; ++x1)
      for (int z0 = 0; z0 < 8; ++z0)
        for (int z1 = z0; z1 < 8; ++z1) {
          uint64_t want = 0;
          for (int z = z0; z <= z1; ++z)
            for (int x = x0; x <= x1; ++x) want |= sliceBit(x, z);
          ASSERT_EQ(tab.xRange[x0][x1] & tab.zRange[z0][z1], want);
        }
}

TEST(BitmaskBroadphase, BoxesOnChunkBordersAndOutsideTheTerrain) {
  VoxelTerrain t({32, 16, 32});
  t.fillBox({16, 0, 0}, {16, 0, 31}, Voxel::make(kMaterialFirstSolid));  // a wall on a chunk border
  BitmaskBroadphase bp(t.chunkGrid(), t.size());
  bp.rebuildAll(t);
  // Touching the wall's face x=16 from the chunk on the other side (x in [13,14]).
  EXPECT_TRUE(bp.overlap({Vec3f(13.f, 0.5f, 3.f), Vec3f(14.f, 0.6f, 4.f)}, 1.f).solid);
  EXPECT_FALSE(bp.overlap({Vec3f(10.f, 0.5f, 3.f), Vec3f(12.5f, 0.6f, 4.f)}, 1.f).solid);
  EXPECT_FALSE(bp.overlap({Vec3f(-50.f, 0.f, 0.f), Vec3f(-40.f, 1.f, 1.f)}, 1.f).solid);
  EXPECT_FALSE(bp.overlap({Vec3f(16.f, 40.f, 0.f), Vec3f(17.f, 41.f, 1.f)}, 1.f).solid);
  EXPECT_TRUE(bp.overlap({Vec3f(-1e30f, -1e30f, -1e30f), Vec3f(1e30f, 1e30f, 1e30f)}, 1.f).solid);
}

}  // namespace
}  // namespace bw
