// BoxOccupancyBits (world/box_occupancy_bits.h) against brute force: a "no" must never hide an
// overlapping box (seeded boxes from 0.2 to 500 long, thin plates, clustered, far from the
// origin, all at one point; queries anywhere, touching a box exactly, points, huge, inverted,
// NaN), and on sparse small boxes most queries that meet nothing must get a "no".
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "collision/core/seeded_random.h"
#include "world/box_occupancy_bits.h"

namespace bw {
namespace {

bool anyOverlap(const std::vector<WorldAabb>& boxes, const WorldAabb& q) {
  for (const WorldAabb& b : boxes)
    if (b.overlaps(q)) return true;
  return false;
}

TEST(BoxOccupancyBits, NeverSaysNoWhereABoxOverlaps) {
  SeededRandom r(77);
  for (int round = 0; round < 8; ++round) {
    const Vec3d origin = round % 2 ? Vec3d(4e6, -3e6, 2e5) : Vec3d::Zero();
    const uint32_t n = round == 0 ? 0 : (round == 1 ? 1 : 150 * uint32_t(round));
    std::vector<WorldAabb> boxes;
    for (uint32_t i = 0; i < n; ++i) {
      // clustered: a third of them in a small region
      const double spread = i % 3 ? 400 : 4;
      const Vec3d c = origin + Vec3d(r.uniform(-spread, spread), r.uniform(-spread, spread), r.uniform(-spread / 4, spread / 4));
      Vec3d h(r.logUniform(0.1, 250), r.logUniform(0.1, 250), r.logUniform(0.1, 250));
      if (i % 5 == 0) h[i % 3] = 0.001;  // thin plates
      if (round == 6) h.setZero();       // every box a point
      boxes.push_back({round == 7 ? origin : c - h, round == 7 ? origin : c + h});  // round 7: all at one point
    }
    BoxOccupancyBits bits;
    bits.build(boxes);
    for (int q = 0; q < 600; ++q) {
      const Vec3d c = origin + Vec3d(r.uniform(-500, 500), r.uniform(-500, 500), r.uniform(-150, 150));
      const Vec3d h = q % 4 == 0 ? Vec3d::Zero() : Vec3d(r.logUniform(0.1, 300), r.logUniform(0.1, 300), r.logUniform(0.1, 300));
      WorldAabb query{c - h, c + h};
      if (q % 5 == 1 && n) {  // ends exactly where a box starts (closed intervals touch)
        const WorldAabb& b = boxes[r.below(n)];
        const int a = int(r.below(3));
        query = b;
        query.max[a] = b.min[a];
        query.min[a] = b.min[a] - h[a];
      }
      if (q % 7 == 3) std::swap(query.min, query.max);  // inverted
      if (anyOverlap(boxes, query)) {
        ASSERT_TRUE(bits.mayOverlap(query)) << "round " << round << ", query " << q;
      }
    }
    WorldAabb nan{Vec3d::Constant(std::numeric_limits<double>::quiet_NaN()), origin};
    EXPECT_FALSE(bits.mayOverlap(nan));  // WorldAabb::overlaps says no for NaN too
    EXPECT_EQ(bits.mayOverlap({origin - Vec3d::Constant(1e9), origin + Vec3d::Constant(1e9)}), n > 0);
  }
}

TEST(BoxOccupancyBits, SaysNoToMostQueriesThatMeetNothingAmongSparseBoxes) {
  // 1000 one-metre boxes scattered over a 1 km x 100 m x 50 m slab (the edit load's bricks on a
  // ship) and one-metre queries over the same slab: brute force finds most queries empty, and
  // the bits must answer them "no" (a filter that always says "may" fails here).
  SeededRandom r(5);
  const Vec3d origin(-2e5, 7e4, 30);
  const auto at = [&]() -> Vec3d { return origin + Vec3d(r.uniform(0, 1000), r.uniform(0, 100), r.uniform(0, 50)); };
  std::vector<WorldAabb> boxes;
  for (int i = 0; i < 1000; ++i) {
    const Vec3d c = at();
    boxes.push_back({c - Vec3d::Constant(0.5), c + Vec3d::Constant(0.5)});
  }
  BoxOccupancyBits bits;
  bits.build(boxes);
  int empty = 0, saidNo = 0;
  for (int q = 0; q < 2000; ++q) {
    const Vec3d c = at();
    const WorldAabb query{c - Vec3d::Constant(0.6), c + Vec3d::Constant(0.6)};
    const bool any = anyOverlap(boxes, query), may = bits.mayOverlap(query);
    if (any) {
      ASSERT_TRUE(may) << "query " << q;
    }
    empty += any ? 0 : 1;
    saidNo += may ? 0 : 1;
  }
  EXPECT_GT(empty, 1900);
  EXPECT_GT(saidNo, empty * 9 / 10);
}

TEST(BoxOccupancyBits, InvertedOrNonFiniteBoxesAreNeverMissed) {
  // An inverted box (min y above max y) still overlaps a query spanning its gap, by
  // WorldAabb::overlaps' rule; an endless one overlaps queries anywhere beyond.
  const Vec3d inf = Vec3d::Constant(std::numeric_limits<double>::infinity());
  const WorldAabb spanning{Vec3d(10.5, -6, 10.5), Vec3d(10.6, 6, 10.6)}, far{Vec3d::Constant(-1e3 - 1), Vec3d::Constant(-1e3)};
  const WorldAabb inverted{Vec3d(10, 5, 10), Vec3d(11, -5, 11)}, endless{-inf, Vec3d::Zero()};
  for (const auto& [odd, query] : {std::pair{inverted, spanning}, std::pair{endless, far}}) {
    const std::vector<WorldAabb> boxes{{Vec3d::Zero(), Vec3d::Ones()}, {Vec3d(-20, -20, -20), Vec3d(-19, 20, -19)}, odd};
    ASSERT_TRUE(anyOverlap(boxes, query));
    BoxOccupancyBits bits;
    bits.build(boxes);
    EXPECT_TRUE(bits.mayOverlap(query));
  }
}

}  // namespace
}  // namespace bw
