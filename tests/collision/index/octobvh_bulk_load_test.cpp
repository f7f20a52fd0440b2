// OctoBvh::bulkLoad: the handles it returns name their inputs, its records sit in the pool in
// the order the build places them (a leaf's records side by side), and bad input changes nothing.
#include <algorithm>
#include <cmath>
#include <gtest/gtest.h>
#include <limits>
#include <vector>

#include "collision/content/brick_workload.h"
#include "collision/core/errors.h"
#include "collision/core/seeded_random.h"
#include "collision/index/octobvh.h"

namespace bw {
namespace {

// Brick builds of every size class (dense clusters included), a plate stack (forced splits),
// giants, and exact duplicates (min-level overflow chains), shifted by `offset`.
std::vector<Aabb> adversarialBuild(uint32_t count, uint64_t seed, const Vec3f& offset, float density) {
  BrickWorkloadParams p;
  p.count = count;
  p.seed = seed;
  p.offset = offset;
  p.extent = 300.f;
  p.density = density;
  std::vector<Aabb> out = generateBrickWorkload(p);
  for (const Aabb& b : generatePlateStack(30, 80.f, seed)) out.push_back({b.min + offset, b.max + offset});
  SeededRandom r(seed * 31 + 7);
  for (int i = 0; i < 6; ++i) {  // giants up to 500 units and thin plates
    const Vec3f c = offset + Vec3f(float(r.unit() * 200), float(r.unit() * 200), float(r.unit() * 200));
    const Vec3f half(float(10 + r.unit() * 240), i % 2 ? 0.1f : float(5 + r.unit() * 100), float(10 + r.unit() * 240));
    out.push_back({c - half, c + half});
  }
  const Aabb dup{offset + Vec3f(1.f, 2.f, 3.f), offset + Vec3f(1.2f, 2.2f, 3.2f)};
  for (int i = 0; i < 20; ++i) out.push_back(dup);
  // Shuffled, so the input order says nothing about where an element lands.
  for (size_t i = out.size(); i > 1; --i) std::swap(out[i - 1], out[r.below(uint32_t(i))]);
  return out;
}

struct Inputs {
  std::vector<Aabb> bounds;
  std::vector<uint32_t> filters, payloads;
};

Inputs inputsOf(std::vector<Aabb> bounds) {
  Inputs in{std::move(bounds), {}, {}};
  for (uint32_t i = 0; i < in.bounds.size(); ++i) {
    in.filters.push_back(1u << (i % 5));
    in.payloads.push_back(i * 3 + 1);
  }
  return in;
}

// Handles met walking the tree in the order a build places elements: a node's held list, then
// its forced cluster's nodes, then its children's.
void handlesInBuildOrder(const OctoBvh& tree, uint32_t c, int s, std::vector<uint32_t>& out) {
  const octobvh::NodeCluster& cl = tree.cluster(c);
  tree.forEachHeldPublic(cl, s, [&](uint32_t e) { out.push_back(e); });
  if (cl.child[s] == kInvalidIndex) return;
  if (cl.forced(s) != kInvalidIndex)
    for (int o = 0; o < 8; ++o) handlesInBuildOrder(tree, cl.forced(s), o, out);
  for (int o = 0; o < 8; ++o) handlesInBuildOrder(tree, cl.child[s], o, out);
}

struct Case {
  uint32_t count;
  uint64_t seed;
  Vec3f offset;
  float density;
};
const Case kCases[] = {
    {3000, 1, Vec3f::Zero(), 1.f},
    {3000, 2, Vec3f(2.5e5f, -1.2e5f, 7.5e4f), 1.f},  // far from the origin
    {4000, 3, Vec3f(-40.f, 10.f, 0.f), kDenseBuild},  // dense clusters: full leaves, forced clusters
};

TEST(OctoBvhBulkLoad, EveryHandleNamesItsInputAndTheTreeIsTheCanonicalOne) {
  for (const Case& k : kCases) {
    const Inputs in = inputsOf(adversarialBuild(k.count, k.seed, k.offset, k.density));
    OctoBvh bulk;
    const std::vector<uint32_t> handles = bulk.bulkLoad(in.bounds, in.filters, in.payloads);
    ASSERT_EQ(handles.size(), in.bounds.size());
    bulk.validate();
    std::vector<uint32_t> sorted = handles;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end()) << "seed " << k.seed << ": a handle twice";
    for (uint32_t i = 0; i < handles.size(); ++i) {
      ASSERT_TRUE(bulk.contains(handles[i])) << "seed " << k.seed << ", input " << i;
      EXPECT_TRUE(bulk.bounds(handles[i]) == in.bounds[i]) << "seed " << k.seed << ", input " << i;
      EXPECT_EQ(bulk.filter(handles[i]), in.filters[i]) << "seed " << k.seed << ", input " << i;
      EXPECT_EQ(bulk.payload(handles[i]), in.payloads[i]) << "seed " << k.seed << ", input " << i;
    }
    OctoBvh inserted;
    for (uint32_t i = 0; i < in.bounds.size(); ++i) inserted.insert(in.bounds[i], in.filters[i], in.payloads[i]);
    EXPECT_EQ(bulk.structureHash(), inserted.structureHash()) << "seed " << k.seed;

    // Queries name the same inputs as brute force over the input arrays.
    SeededRandom r(k.seed * 5);
    for (int q = 0; q < 200; ++q) {
      const Aabb& around = in.bounds[r.below(uint32_t(in.bounds.size()))];
      const Aabb box = around.expanded(float(0.05 + r.unit() * 4));
      const uint32_t mask = 1u << r.below(5) | 1u << r.below(5);
      std::vector<uint32_t> got, want;
      bulk.overlap(box, mask, [&](uint32_t e) { got.push_back(bulk.payload(e)); });
      for (uint32_t i = 0; i < in.bounds.size(); ++i)
        if ((in.filters[i] & mask) && in.bounds[i].overlaps(box)) want.push_back(in.payloads[i]);
      std::sort(got.begin(), got.end());
      std::sort(want.begin(), want.end());
      ASSERT_EQ(got, want) << "seed " << k.seed << ", query " << q;

      const Vec3f dir = Vec3f(float(r.normal()), float(r.normal()), float(r.normal())).normalized();
      const Ray ray = Ray::make(box.center() + dir * 2.f, dir, 300.f);
      const RayHit hit = bulk.raycastClosest(ray, mask);
      float best = std::numeric_limits<float>::infinity();
      for (uint32_t i = 0; i < in.bounds.size(); ++i) {
        float t;
        if ((in.filters[i] & mask) && intersectRayAabb(ray, in.bounds[i], 0.f, ray.maxT, t)) best = std::min(best, t);
      }
      ASSERT_EQ(hit.hit(), std::isfinite(best)) << "seed " << k.seed << ", ray " << q;
      if (hit.hit()) {
        EXPECT_EQ(hit.t, best) << "seed " << k.seed << ", ray " << q;
      }
    }
  }
}

// bulkLoad sorts elements by their first 19 levels of path below the root and leaves deeper
// runs to the partitioning build (octobvh_sorted_build.cpp): tiny elements far from the origin
// make trees 23+ levels deep, with forced nodes and duplicates on the way down.
TEST(OctoBvhBulkLoad, TreesDeeperThanTheSortedLevelsAreTheCanonicalOnes) {
  for (uint64_t seed : {11u, 12u, 13u}) {
    SeededRandom r(seed);
    const Vec3f far(float(1.5e5 * (seed == 12 ? -1 : 1)), 7.3e4f, -2.1e4f);
    std::vector<Aabb> boxes;
    for (int i = 0; i < 4000; ++i) {  // 2 m clusters of 3-50 mm boxes
      const Vec3f c = far + Vec3f(float(r.unit() * 2), float(r.unit() * 2), float(r.unit() * 2)) + Vec3f::Constant(float(i % 4) * 40.f);
      const float h = float(0.0015 + r.unit() * 0.024);
      boxes.push_back({c - Vec3f::Constant(h), c + Vec3f(h, h * 0.5f, h)});
    }
    for (int i = 0; i < 40; ++i) {  // boxes of the same min level stacked at one point: forced down
      const Vec3f c = far + Vec3f(0.5f, 0.5f, 0.5f);
      boxes.push_back({c - Vec3f::Constant(0.3f + 0.001f * float(i)), c + Vec3f::Constant(0.3f)});
    }
    for (size_t i = boxes.size(); i > 1; --i) std::swap(boxes[i - 1], boxes[r.below(uint32_t(i))]);
    const Inputs in = inputsOf(boxes);
    OctoBvh bulk, inserted;
    bulk.bulkLoad(in.bounds, in.filters, in.payloads);
    bulk.validate();
    for (uint32_t i = 0; i < in.bounds.size(); ++i) inserted.insert(in.bounds[i], in.filters[i], in.payloads[i]);
    EXPECT_EQ(bulk.structureHash(), inserted.structureHash()) << "seed " << seed;
    EXPECT_GT(bulk.shapeStats().depth, 19) << "seed " << seed << ": not deeper than the sorted levels";
    EXPECT_GT(bulk.shapeStats().forcedNodes, 0u) << "seed " << seed;
  }
}

// The point of writing records as the build places them: a leaf's elements, and the leaves
// after one another, have ascending handles, so their records share and neighbour cache lines.
TEST(OctoBvhBulkLoad, RecordsSitInThePoolInTheOrderTheBuildPlacesThem) {
  for (const Case& k : kCases) {
    const Inputs in = inputsOf(adversarialBuild(k.count, k.seed, k.offset, k.density));
    OctoBvh bulk;
    bulk.bulkLoad(in.bounds, in.filters, in.payloads);
    std::vector<uint32_t> walked;
    handlesInBuildOrder(bulk, bulk.rootCluster(), 0, walked);
    ASSERT_EQ(walked.size(), in.bounds.size()) << "seed " << k.seed;
    for (size_t i = 1; i < walked.size(); ++i)
      ASSERT_LT(walked[i - 1], walked[i]) << "seed " << k.seed << ": element " << i << " of the walk";
  }
}

TEST(OctoBvhBulkLoad, BadInputThrowsBeforeAnythingChanges) {
  Inputs in = inputsOf(adversarialBuild(500, 9, Vec3f::Zero(), 1.f));
  OctoBvh tree;
  for (const float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(), 2e9f}) {
    Inputs broken = in;
    broken.bounds.back().max.y() = bad;  // the last input: every other one was already read
    EXPECT_THROW(tree.bulkLoad(broken.bounds, broken.filters, broken.payloads), InvalidInput);
    EXPECT_TRUE(tree.empty());
  }
  Inputs shortPayloads = in;
  shortPayloads.payloads.pop_back();
  EXPECT_THROW(tree.bulkLoad(shortPayloads.bounds, shortPayloads.filters, shortPayloads.payloads), InvalidInput);
  EXPECT_TRUE(tree.empty());
  // The same tree then loads the good input exactly as a fresh one does.
  const std::vector<uint32_t> handles = tree.bulkLoad(in.bounds, in.filters, in.payloads);
  tree.validate();
  OctoBvh fresh;
  EXPECT_EQ(handles, fresh.bulkLoad(in.bounds, in.filters, in.payloads));
  EXPECT_EQ(tree.structureHash(), fresh.structureHash());
  EXPECT_THROW(tree.bulkLoad(in.bounds, in.filters, in.payloads), InvalidInput);  // not empty any more
}

}  // namespace
}  // namespace bw
