// bench::OctoBvhWalkFloor, the fewest box tests any exact walk of a tree could make for a query
// (bench_octobvh's LoadFloor rows, and issue 20's bound on the load workload): checked against
// the tree's own walk and against a count made from brute force.
#include <gtest/gtest.h>
#include <set>
#include <vector>

#include "collision/content/brick_workload.h"
#include "collision/core/seeded_random.h"
#include "collision/index/octobvh.h"
#include "profiles/bench/octobvh_walk_floor.h"

namespace bw {
namespace {

// The floor from its definition, the slow way: the nodes whose subtrees hold a hit, found by
// gathering every node's subtree; their non-empty children and held elements, plus the root.
uint64_t floorByBruteForce(const OctoBvh& t, const std::vector<uint32_t>& hits) {
  const std::set<uint32_t> hitSet(hits.begin(), hits.end());
  uint64_t n = 1;
  std::vector<uint32_t> stack{octobvh::nodeRef(t.rootCluster(), 0)};
  while (!stack.empty()) {
    const uint32_t ref = stack.back();
    stack.pop_back();
    const octobvh::NodeCluster& cl = t.cluster(ref >> 3);
    const int s = int(ref & 7);
    bool leadsToHit = false;
    std::vector<uint32_t> subtree{ref};  // every node at or below ref
    for (size_t k = 0; k < subtree.size(); ++k) {
      const octobvh::NodeCluster& c = t.cluster(subtree[k] >> 3);
      t.forEachHeldPublic(c, int(subtree[k] & 7), [&](uint32_t e) { leadsToHit = leadsToHit || hitSet.count(e); });
      c.forEachSubCluster(int(subtree[k] & 7), [&](uint32_t sc) {
        for (int o = 0; o < 8; ++o)
          if (!t.cluster(sc).isEmpty(o)) subtree.push_back(octobvh::nodeRef(sc, o));
      });
    }
    if (!leadsToHit) continue;
    t.forEachHeldPublic(cl, s, [&](uint32_t) { ++n; });
    cl.forEachSubCluster(s, [&](uint32_t sc) {
      for (int o = 0; o < 8; ++o)
        if (!t.cluster(sc).isEmpty(o)) {
          ++n;
          stack.push_back(octobvh::nodeRef(sc, o));
        }
    });
  }
  return n;
}

TEST(OctoBvhWalkFloor, EqualsItsDefinitionAndNeverExceedsTheTreesOwnWalk) {
  for (uint64_t seed : {3u, 11u}) {
    for (float density : {1.f, kDenseBuild}) {
      BrickWorkloadParams p;
      p.count = 3000;
      p.seed = seed;
      p.extent = 200.f;
      p.density = density;
      p.offset = seed == 11 ? Vec3f(3.0e5f, -2.0e5f, 1.0e5f) : Vec3f::Zero();  // far from the origin too
      const std::vector<Aabb> bricks = generateBrickWorkload(p);
      OctoBvh tree;
      for (uint32_t i = 0; i < bricks.size(); ++i) tree.insert(bricks[i], 1, i);
      bench::OctoBvhWalkFloor floor(tree);
      SeededRandom r(seed);
      uint64_t walkSum = 0, floorSum = 0;
      for (int q = 0; q < 150; ++q) {
        const Aabb& b = bricks[r.below(uint32_t(bricks.size()))];
        const Aabb query = q % 3 ? b.expanded(0.05f) : b.expanded(float(r.unit() * 20));
        std::vector<uint32_t> hits;
        QueryStats st;
        tree.overlap(query, 1, [&](uint32_t e) { hits.push_back(e); }, &st);
        const uint64_t least = floor.tests(hits);
        ASSERT_EQ(least, floorByBruteForce(tree, hits)) << "seed " << seed << " density " << density << " query " << q;
        ASSERT_LE(least, st.boxTests) << "a floor above the walk that reached these hits";
        ASSERT_GE(least, 1 + hits.size());
        walkSum += st.boxTests;
        floorSum += least;
      }
      EXPECT_LT(floorSum, walkSum) << "the walk also enters nodes that lead to no hit";
    }
  }
  // A query that hits nothing costs the root's test.
  OctoBvh tree;
  tree.insert({{0, 0, 0}, {1, 1, 1}}, 1, 0);
  EXPECT_EQ(bench::OctoBvhWalkFloor(tree).tests({}), 1u);
}

}  // namespace
}  // namespace bw
