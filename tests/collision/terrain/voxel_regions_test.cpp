// DetachedVoxelSearch and voxelRegionBricks (collision/terrain/voxel_regions.h) against brute
// force: on seeded random terrains (ground, blobs, pillars, arches) carved by random spheres,
// the regions found from the carves' rims are exactly the 6-connected solid components, among
// those the seeds touch, that reach no anchored voxel (a flood fill over the whole terrain);
// each region's bricks cover exactly its voxels, once, with their materials.
#include <gtest/gtest.h>

#include <map>
#include <queue>
#include <set>
#include <tuple>

#include "collision/content/terrain_generator.h"
#include "collision/core/seeded_random.h"
#include "collision/terrain/voxel_regions.h"

namespace bw {
namespace {

using Key = std::tuple<int32_t, int32_t, int32_t>;
Key key(const Int3& v) { return {v.x, v.y, v.z}; }

// Brute force: label every solid voxel's 6-connected component; a component is anchored when
// any of its voxels has z < anchorZ.
struct Components {
  std::map<Key, int> label;
  std::vector<bool> anchored;
  std::vector<std::set<Key>> voxels;
  Components(const VoxelTerrain& t, int32_t anchorZ) {
    const Int3 s = t.size();
    for (int32_t z = 0; z < s.z; ++z)
      for (int32_t y = 0; y < s.y; ++y)
        for (int32_t x = 0; x < s.x; ++x) {
          if (!t.get({x, y, z}).isSolid() || label.count({x, y, z})) continue;
          const int id = int(anchored.size());
          anchored.push_back(false);
          voxels.emplace_back();
          std::queue<Int3> open;
          open.push({x, y, z});
          label[{x, y, z}] = id;
          while (!open.empty()) {
            const Int3 v = open.front();
            open.pop();
            voxels[id].insert(key(v));
            if (v.z < anchorZ) anchored[id] = true;
            for (const Int3& n : {Int3{v.x - 1, v.y, v.z}, Int3{v.x + 1, v.y, v.z}, Int3{v.x, v.y - 1, v.z}, Int3{v.x, v.y + 1, v.z},
                                  Int3{v.x, v.y, v.z - 1}, Int3{v.x, v.y, v.z + 1}}) {
              if (!t.contains(n) || !t.get(n).isSolid() || label.count(key(n))) continue;
              label[key(n)] = id;
              open.push(n);
            }
          }
        }
  }
};

// A terrain with ground below z = 3 and random boxes of 2..6 voxels a side in four materials:
// towers, floating blocks, bridges between them.
void randomTerrain(VoxelTerrain& t, SeededRandom& r) {
  const Int3 s = t.size();
  t.fillBox({0, 0, 0}, {s.x - 1, s.y - 1, 2}, Voxel::make(kMaterialFirstSolid));
  for (int i = 0; i < 40; ++i) {
    const Int3 lo{int32_t(r.below(uint32_t(s.x - 6))), int32_t(r.below(uint32_t(s.y - 6))), 2 + int32_t(r.below(uint32_t(s.z - 8)))};
    const Int3 hi{lo.x + 1 + int32_t(r.below(5)), lo.y + 1 + int32_t(r.below(5)), lo.z + 1 + int32_t(r.below(5))};
    t.fillBox(lo, hi, Voxel::make(uint8_t(kMaterialFirstSolid + r.below(4))));
  }
}

TEST(DetachedVoxelSearch, FindsExactlyTheCutOffComponentsTheCarvesTouch) {
  int detachedSeen = 0;
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    SeededRandom r(seed);
    VoxelTerrain t({40, 40, 24});
    randomTerrain(t, r);
    const int32_t anchorZ = 3;
    DetachedVoxelSearch search;
    std::vector<std::vector<Int3>> regions;
    for (int carve = 0; carve < 25; ++carve) {
      const Int3 c{int32_t(r.below(40)), int32_t(r.below(40)), 3 + int32_t(r.below(18))};
      const int rad = 1 + int(r.below(3));
      std::vector<Int3> seeds;
      for (int32_t z = c.z - rad - 1; z <= c.z + rad + 1; ++z)
        for (int32_t y = c.y - rad - 1; y <= c.y + rad + 1; ++y)
          for (int32_t x = c.x - rad - 1; x <= c.x + rad + 1; ++x) {
            if (!t.contains({x, y, z}) || z < anchorZ) continue;
            const int d = (x - c.x) * (x - c.x) + (y - c.y) * (y - c.y) + (z - c.z) * (z - c.z);
            if (d <= rad * rad) t.set({x, y, z}, Voxel{});
            else if (t.get({x, y, z}).isSolid()) seeds.push_back({x, y, z});
          }
      search.find(t, anchorZ, seeds, regions);
      // Brute force: the unanchored components holding a seed.
      const Components all(t, anchorZ);
      std::set<int> expected;
      for (const Int3& s : seeds)
        if (t.get(s).isSolid() && !all.anchored[all.label.at(key(s))]) expected.insert(all.label.at(key(s)));
      ASSERT_EQ(regions.size(), expected.size()) << "seed " << seed << " carve " << carve;
      for (const std::vector<Int3>& region : regions) {
        const int id = all.label.at(key(region.front()));
        EXPECT_TRUE(expected.count(id));
        std::set<Key> got;
        for (const Int3& v : region) got.insert(key(v));
        EXPECT_EQ(got, all.voxels[id]) << "a region differs from its flood-filled component";
        // Its bricks cover it exactly once, with each voxel's material.
        const float voxel = 0.5f;
        std::map<Key, int> cover;
        for (const Brick& b : voxelRegionBricks(t, region, voxel)) {
          const Vec3f lo = (b.position - b.halfSize) / voxel, hi = (b.position + b.halfSize) / voxel;
          for (int32_t z = int32_t(std::lround(lo.z())); z < int32_t(std::lround(hi.z())); ++z)
            for (int32_t y = int32_t(std::lround(lo.y())); y < int32_t(std::lround(hi.y())); ++y)
              for (int32_t x = int32_t(std::lround(lo.x())); x < int32_t(std::lround(hi.x())); ++x) {
                ++cover[{x, y, z}];
                EXPECT_EQ(b.material, t.get({x, y, z}).material);
              }
        }
        EXPECT_EQ(cover.size(), got.size());
        for (const auto& [k, n] : cover) {
          EXPECT_EQ(n, 1);
          EXPECT_TRUE(got.count(k));
        }
        for (const Int3& v : region) t.set(v, Voxel{});  // gone, as the world takes it away
        ++detachedSeen;
      }
    }
  }
  EXPECT_GT(detachedSeen, 5) << "the carves must cut regions off for this test to mean anything";
}

TEST(DetachedVoxelSearch, StandingRegionsStopEarlyAndLongWalksGiveUp) {
  // A 2 x 2 pillar 30 voxels tall on the ground: a seed at its top reaches the anchor after about
  // its height of voxels, not its volume; with a walk limit below that it gives up (left in place).
  VoxelTerrain t({16, 16, 40});
  t.fillBox({0, 0, 0}, {15, 15, 1}, Voxel::make(kMaterialFirstSolid));
  t.fillBox({6, 6, 2}, {7, 7, 31}, Voxel::make(kMaterialFirstSolid));
  DetachedVoxelSearch search;
  std::vector<std::vector<Int3>> regions;
  const std::vector<Int3> seeds{{6, 6, 31}};
  search.find(t, 2, seeds, regions);
  EXPECT_TRUE(regions.empty());
  EXPECT_LT(search.visited(), 80u) << "a pillar of 120 voxels is walked down, not filled";
  search.find(t, 2, seeds, regions, 16);
  EXPECT_TRUE(regions.empty());
  EXPECT_EQ(search.gaveUp(), 1u);
  // Cut it at z = 10: the top 22 voxels' rows come off as one region.
  t.fillBox({6, 6, 10}, {7, 7, 10}, Voxel{});
  search.find(t, 2, seeds, regions);
  ASSERT_EQ(regions.size(), 1u);
  EXPECT_EQ(regions[0].size(), 4u * 21u);
}

}  // namespace
}  // namespace bw
