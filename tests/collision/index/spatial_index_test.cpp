// Differential tests of the spatial indices (OctoBVH and the loose-octree baseline) against
// brute force, on seeded workloads with sizes 0.04..500, thin plates, clustered placement and
// coordinates far from the origin, after random edit sequences.
#include <algorithm>
#include <cmath>
#include <gtest/gtest.h>

#include "collision/content/brick_workload.h"
#include "collision/core/argument_checks.h"
#include "collision/core/seeded_random.h"
#include "collision/index/loose_octree.h"
#include "collision/index/octobvh.h"
#include "collision/support/brute_force_index.h"

namespace bw {
namespace {

template <class Index>
class SpatialIndexTest : public ::testing::Test {};
using IndexTypes = ::testing::Types<OctoBvh, LooseOctree>;
TYPED_TEST_SUITE(SpatialIndexTest, IndexTypes);

// A mixed workload: brick builds, a plate stack (forced splits) and exact duplicates
// (overflowing min-level leaves).
std::vector<Aabb> mixedWorkload(uint32_t count, uint64_t seed, Vec3f offset) {
  BrickWorkloadParams p;
  p.count = count;
  p.seed = seed;
  p.offset = offset;
  p.extent = 400.f;
  std::vector<Aabb> out = generateBrickWorkload(p);
  for (const Aabb& b : generatePlateStack(40, 120.f, seed)) out.push_back({b.min + offset, b.max + offset});
  const Aabb dup{Vec3f(1.f, 2.f, 3.f) + offset, Vec3f(1.04f, 2.04f, 3.04f) + offset};
  for (int i = 0; i < 12; ++i) out.push_back(dup);
  return out;
}

uint32_t filterFor(uint32_t i) { return 1u << (i % 3); }

/// Inserts every box (payload: its position) into the index and the brute-force reference;
/// returns the handles.
template <class Index>
std::vector<uint32_t> insertMirrored(Index& index, test::BruteForceIndex& ref, const std::vector<Aabb>& boxes) {
  std::vector<uint32_t> live;
  for (uint32_t i = 0; i < boxes.size(); ++i) {
    const uint32_t h = index.insert(boxes[i], filterFor(i), i);
    ref.items[h] = {boxes[i], filterFor(i)};
    live.push_back(h);
  }
  return live;
}

Aabb regionOf(const std::vector<Aabb>& boxes) {
  Aabb region = Aabb::empty();
  for (const Aabb& b : boxes) region.merge(b);
  return region;
}

template <class Index>
void expectQueriesMatch(const Index& index, const test::BruteForceIndex& ref, SeededRandom& r, int queries,
                        const Aabb& region) {
  const Vec3f lo = region.min, span = region.extent();
  auto point = [&] {
    return Vec3f(lo.x() + float(r.unit()) * span.x(), lo.y() + float(r.unit()) * span.y(), lo.z() + float(r.unit()) * span.z());
  };
  for (int q = 0; q < queries; ++q) {
    const uint32_t mask = (q % 4 == 0) ? 0xFFFFFFFFu : (1u << (q % 3));
    // AABB overlap, sizes from tiny to huge.
    const Vec3f c = point();
    const Vec3f h = Vec3f::Constant(float(r.logUniform(0.01, 300)));
    const Aabb box{c - h, c + h};
    std::vector<uint32_t> got;
    QueryStats st;
    index.overlap(box, mask, got, &st);
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, ref.overlap(box, mask)) << "AABB overlap, query " << q;

    // OBB overlap.
    const Quatf rot(Eigen::AngleAxisf(float(r.uniform(0, 6.3)), Vec3f(float(r.normal()), float(r.normal()), float(r.normal())).normalized()));
    const Obb obb{point(), Vec3f(float(r.logUniform(0.05, 50)), float(r.logUniform(0.05, 50)), float(r.logUniform(0.05, 50))),
                  rot.toRotationMatrix()};
    got.clear();
    index.overlap(obb, mask, got);
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, ref.overlap(obb, mask)) << "OBB overlap, query " << q;

    // Rays: limited and unlimited, some axis-aligned (zero direction components).
    Vec3f dir(float(r.normal()), float(r.normal()), float(r.normal()));
    if (q % 5 == 0) dir = Vec3f::Zero(), dir[q % 3] = (q % 2) ? 1.f : -1.f;
    if (q % 7 == 0) dir[(q + 1) % 3] = 0.f;
    if (dir.isZero()) dir = Vec3f::UnitX();
    const float maxT = (q % 3 == 0) ? std::numeric_limits<float>::infinity() : float(r.logUniform(1, 2000));
    const Ray ray = Ray::make(point(), dir.normalized(), maxT);
    const std::vector<RayHit> all = ref.raycastAll(ray, mask);
    const RayHit closest = index.raycastClosest(ray, mask);
    if (all.empty()) {
      ASSERT_FALSE(closest.hit()) << "ray " << q;
    } else {
      ASSERT_TRUE(closest.hit()) << "ray " << q;
      ASSERT_EQ(closest.t, all.front().t) << "ray " << q;
      // Of hits at the same t, the OctoBVH reports the first it meets, the loose octree the lowest handle.
      bool tied = false;
      for (const RayHit& h : all) tied = tied || (h.t == closest.t && h.element == closest.element);
      ASSERT_TRUE(tied) << "ray " << q << ": element " << closest.element << " is no hit at t " << closest.t;
      if constexpr (std::is_same_v<Index, LooseOctree>) {
        ASSERT_EQ(closest.element, all.front().element);
      }
    }
    const RayHit any = index.raycastAny(ray, mask);
    ASSERT_EQ(any.hit(), !all.empty());
    if (any.hit()) {
      ASSERT_TRUE(std::find_if(all.begin(), all.end(), [&](const RayHit& h) { return h.element == any.element && h.t == any.t; }) != all.end());
    }
    std::vector<RayHit> gotAll;
    index.raycastAll(ray, mask, gotAll);
    ASSERT_EQ(gotAll.size(), all.size()) << "ray " << q;
    for (size_t i = 0; i < all.size(); ++i) ASSERT_TRUE(gotAll[i].element == all[i].element && gotAll[i].t == all[i].t);
  }
}

TYPED_TEST(SpatialIndexTest, QueriesMatchBruteForceAfterRandomEdits) {
  for (const Vec3f& offset : {Vec3f(0, 0, 0), Vec3f(-3e5f, 1e6f, -7e5f)}) {
    SeededRandom r(offset.x() == 0 ? 11 : 12);
    const std::vector<Aabb> boxes = mixedWorkload(6000, 5, offset);
    TypeParam index;
    test::BruteForceIndex ref;
    std::vector<uint32_t> live = insertMirrored(index, ref, boxes);
    const Aabb region = regionOf(boxes);
    expectQueriesMatch(index, ref, r, 150, region);
    // Remove a third, move a third, add some back.
    for (int k = 0; k < 2000; ++k) {
      const size_t i = r.below(uint32_t(live.size()));
      const uint32_t h = live[i];
      if (k % 2 == 0) {
        index.remove(h);
        ref.items.erase(h);
        live[i] = live.back();
        live.pop_back();
      } else {
        const Vec3f d(float(r.normal() * 20), float(r.normal() * 5), float(r.normal() * 20));
        const Aabb moved{index.bounds(h).min + d, index.bounds(h).max + d};
        index.update(h, moved, filterFor(k));
        ref.items[h] = {moved, filterFor(k)};
      }
    }
    index.validate();
    expectQueriesMatch(index, ref, r, 150, region);
  }
}

TYPED_TEST(SpatialIndexTest, HundredThousandElementsMatchBruteForce) {
  BrickWorkloadParams p;
  p.count = 100'000;
  p.seed = 21;
  const std::vector<Aabb> boxes = generateBrickWorkload(p);
  TypeParam index(typename TypeParam::Config{200'000});
  test::BruteForceIndex ref;
  for (uint32_t i = 0; i < boxes.size(); ++i) ref.items[index.insert(boxes[i], filterFor(i), i)] = {boxes[i], filterFor(i)};
  SeededRandom r(22);
  expectQueriesMatch(index, ref, r, 60, index.rootBounds());
}

TYPED_TEST(SpatialIndexTest, RaysAlongFacesAndFromInsideElements) {
  TypeParam index;
  test::BruteForceIndex ref;
  // A lattice of unit cubes touching each other: rays along shared faces and edges.
  uint32_t n = 0;
  for (int x = 0; x < 6; ++x)
    for (int y = 0; y < 6; ++y)
      for (int z = 0; z < 6; ++z) {
        const Aabb b{Vec3f(float(x), float(y), float(z)), Vec3f(float(x + 1), float(y + 1), float(z + 1))};
        ref.items[index.insert(b, 1, n++)] = {b, 1};
      }
  const Vec3f origins[] = {{-1, 1, 1}, {-1, 0, 0}, {-1, 6, 6}, {2.5f, 2.5f, 2.5f}, {3, 3, -2}, {-1, 2, 2.5f}};
  const Vec3f dirs[] = {{1, 0, 0}, {0, 0, 1}, {1, 1, 0}, {-1, 0, 0}, {1e-40f, 0, 1}, {1, -0.f, 0}};
  for (const Vec3f& o : origins)
    for (const Vec3f& d : dirs)
      for (float maxT : {std::numeric_limits<float>::infinity(), 2.5f}) {
        const Ray ray = Ray::make(o, d, maxT);
        const auto all = ref.raycastAll(ray, 1);
        const RayHit got = index.raycastClosest(ray, 1);
        ASSERT_EQ(got.hit(), !all.empty()) << o.transpose() << " dir " << d.transpose();
        if (got.hit()) {
          EXPECT_FALSE(std::isnan(got.t));
          EXPECT_EQ(got.t, all.front().t);
          EXPECT_EQ(got.element, all.front().element);
        }
        std::vector<RayHit> gotAll;
        index.raycastAll(ray, 1, gotAll);
        EXPECT_EQ(gotAll.size(), all.size());
      }
  // A ray starting inside an element hits it at t = 0.
  const RayHit inside = index.raycastClosest(Ray::make(Vec3f(0.5f, 0.5f, 0.5f), Vec3f(0, 1, 0)), 1);
  ASSERT_TRUE(inside.hit());
  EXPECT_EQ(inside.t, 0.f);
}

TYPED_TEST(SpatialIndexTest, BadInputIsRejectedAndNothingChanges) {
  TypeParam index;
  const uint32_t h = index.insert({Vec3f(0, 0, 0), Vec3f(1, 1, 1)}, 1, 0);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_THROW(index.insert({Vec3f(0, nan, 0), Vec3f(1, 1, 1)}, 1, 0), InvalidInput);
  EXPECT_THROW(index.insert({Vec3f(0, 0, 0), Vec3f(inf, 1, 1)}, 1, 0), InvalidInput);
  EXPECT_THROW(index.insert({Vec3f(2, 0, 0), Vec3f(1, 1, 1)}, 1, 0), InvalidInput);
  EXPECT_THROW(index.insert({Vec3f(0, 0, 0), Vec3f(2e9f, 1, 1)}, 1, 0), InvalidInput);
  EXPECT_THROW(index.update(h, {Vec3f(0, 0, 0), Vec3f(nan, 1, 1)}, 1), InvalidInput);
  EXPECT_THROW(index.remove(h + 1000), InvalidInput);
  EXPECT_EQ(index.size(), 1u);
  EXPECT_EQ(index.bounds(h), (Aabb{Vec3f(0, 0, 0), Vec3f(1, 1, 1)}));
  index.validate();
  try {
    index.insert({Vec3f(0, 0, 0), Vec3f(1, nan, 1)}, 1, 0);
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("bounds.max.y is NaN"), std::string::npos) << e.what();
  }
}

TYPED_TEST(SpatialIndexTest, FullIndexReportsCapacityAndStaysIntact) {
  TypeParam index(typename TypeParam::Config{100});
  uint32_t inserted = 0;
  try {
    for (uint32_t i = 0; i < 10'000; ++i, ++inserted) index.insert({Vec3f(float(i), 0, 0), Vec3f(float(i) + 0.5f, 1, 1)}, 1, i);
    FAIL() << "expected CapacityExceeded";
  } catch (const CapacityExceeded& e) {
    EXPECT_NE(std::string(e.what()).find("full"), std::string::npos) << e.what();
  }
  EXPECT_EQ(index.size(), inserted);
  index.validate();
}

// ---------------------------------------------------------------- OctoBVH only

// Canonical structure: the same set gives the same tree whatever the insert/remove order.
TEST(OctoBvh, StructureIsCanonicalOverRandomOrdersAndInterleavings) {
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    const Vec3f offset = seed % 2 ? Vec3f(0, 0, 0) : Vec3f(-5e5f, 2e5f, 9e5f);
    const std::vector<Aabb> set = mixedWorkload(2500, seed, offset);
    const std::vector<Aabb> extra = mixedWorkload(800, seed + 100, offset + Vec3f(300, -50, 10));

    OctoBvh bulk;
    std::vector<uint32_t> filters(set.size()), payloads(set.size());
    for (uint32_t i = 0; i < set.size(); ++i) filters[i] = filterFor(i), payloads[i] = i;
    bulk.bulkLoad(set, filters, payloads);
    bulk.validate();
    const uint64_t expected = bulk.structureHash();

    SeededRandom r(seed * 7);
    for (int trial = 0; trial < 3; ++trial) {
      OctoBvh tree;
      std::vector<uint32_t> order(set.size());
      for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
      for (uint32_t i = uint32_t(order.size()); i > 1; --i) std::swap(order[i - 1], order[r.below(i)]);
      // Interleave: extra elements are inserted among the real ones and removed again later.
      std::vector<uint32_t> extraHandles;
      size_t ex = 0;
      for (size_t k = 0; k < order.size(); ++k) {
        tree.insert(set[order[k]], filterFor(order[k]), order[k]);
        if (trial > 0 && ex < extra.size() && r.unit() < 0.4) {
          extraHandles.push_back(tree.insert(extra[ex], filterFor(uint32_t(ex)), 1'000'000 + uint32_t(ex)));
          ++ex;
        }
        if (!extraHandles.empty() && r.unit() < 0.15) {
          const size_t i = r.below(uint32_t(extraHandles.size()));
          tree.remove(extraHandles[i]);
          extraHandles[i] = extraHandles.back();
          extraHandles.pop_back();
        }
        if (k % 997 == 0) tree.validate();
      }
      for (uint32_t h : extraHandles) tree.remove(h);
      tree.validate();
      EXPECT_EQ(tree.structureHash(), expected) << "seed " << seed << " trial " << trial;
    }
  }
}

// Structure hash of a tree bulk-loaded from `tree`'s elements (what the canonical form must equal).
uint64_t freshBuildHash(const OctoBvh& tree) {
  std::vector<Aabb> b;
  std::vector<uint32_t> f, p;
  tree.forEachElement([&](uint32_t h) {
    b.push_back(tree.bounds(h));
    f.push_back(tree.filter(h));
    p.push_back(tree.payload(h));
  });
  OctoBvh fresh;
  fresh.bulkLoad(b, f, p);
  return fresh.structureHash();
}

// After every few random edits the incrementally maintained tree equals a fresh bulk build.
TEST(OctoBvh, RandomEditSequencesMatchFreshBuild) {
  SeededRandom r(99);
  const std::vector<Aabb> pool = mixedWorkload(1500, 3, Vec3f(0, 0, 0));
  OctoBvh tree;
  std::vector<std::pair<uint32_t, uint32_t>> live;  // (handle, pool index)
  for (int step = 0; step < 6000; ++step) {
    const double u = r.unit();
    if (u < 0.5 || live.empty()) {
      const uint32_t i = r.below(uint32_t(pool.size()));
      live.push_back({tree.insert(pool[i], filterFor(i), i), i});
    } else if (u < 0.8) {
      const size_t k = r.below(uint32_t(live.size()));
      tree.remove(live[k].first);
      live[k] = live.back();
      live.pop_back();
    } else {
      const size_t k = r.below(uint32_t(live.size()));
      const uint32_t i = r.below(uint32_t(pool.size()));
      tree.update(live[k].first, pool[i], filterFor(i));
      // update keeps the handle; the payload is unchanged by design
      live[k].second = i | 0x80000000u;
    }
    if (step % 250 == 0) {
      tree.validate();
      ASSERT_EQ(tree.structureHash(), freshBuildHash(tree)) << "step " << step;
    }
  }
}

// Small moves and resizes mostly keep an element's centre in the cube of the node holding it,
// which update() absorbs in place (summaries refitted along the path, no remove and insert):
// the tree must stay exactly the canonical one, with tight bounds and filter ORs.
TEST(OctoBvh, SmallMovesAndResizesKeepTheTreeCanonical) {
  for (const Vec3f& offset : {Vec3f(0, 0, 0), Vec3f(4e5f, -2e5f, 9e5f)}) {
    SeededRandom r(offset.x() == 0 ? 41 : 42);
    const std::vector<Aabb> boxes = mixedWorkload(3000, 7, offset);
    OctoBvh tree;
    test::BruteForceIndex ref;
    std::vector<uint32_t> live = insertMirrored(tree, ref, boxes);
    const Aabb region = regionOf(boxes);
    for (int step = 0; step < 4000; ++step) {
      const uint32_t h = live[r.below(uint32_t(live.size()))];
      const Aabb b = tree.bounds(h);
      const Vec3f half = b.extent() * 0.5f;
      // Up to a third of the element's size, sometimes a resize by up to 10%, sometimes new filter bits.
      const Vec3f d(float(r.uniform(-0.3, 0.3)) * b.extent().x(), float(r.uniform(-0.3, 0.3)) * b.extent().y(),
                    float(r.uniform(-0.3, 0.3)) * b.extent().z());
      const float scale = step % 3 == 0 ? float(r.uniform(0.9, 1.1)) : 1.f;
      const Vec3f c = b.center() + d;
      const Aabb moved{c - half * scale, c + half * scale};
      const uint32_t filter = step % 5 == 0 ? filterFor(uint32_t(step)) : ref.items[h].filter;
      tree.update(h, moved, filter);
      ref.items[h] = {moved, filter};
      if (step % 500 == 499) {
        tree.validate();
        ASSERT_EQ(tree.structureHash(), freshBuildHash(tree)) << "step " << step;
        expectQueriesMatch(tree, ref, r, 40, region);
      }
    }
  }
}

// removeMany takes many elements out in one walk: the tree must be the one that removing them
// one by one leaves (a twin tree does that), valid and answering as brute force does, for
// random subsets, a half-space cut (a grid losing a part), the giants of a plate stack (forced
// clusters emptied), everything, and a few (the one-by-one path); bad lists change nothing.
TEST(OctoBvh, RemoveManyLeavesWhatOneByOneRemovalsLeave) {
  for (const Vec3f& offset : {Vec3f(0, 0, 0), Vec3f(-3e5f, 7e5f, 2e5f)}) {
    SeededRandom r(offset.x() == 0 ? 71 : 72);
    const std::vector<Aabb> boxes = mixedWorkload(4000, 9, offset);
    OctoBvh tree, twin;
    test::BruteForceIndex ref, twinRef;
    std::vector<uint32_t> live = insertMirrored(tree, ref, boxes);
    insertMirrored(twin, twinRef, boxes);  // the same handles: both trees got the same inserts
    const Aabb region = regionOf(boxes);
    const float cutX = region.center().x();
    for (int round = 0; round < 6; ++round) {
      std::vector<uint32_t> gone, kept;
      for (uint32_t h : live) {
        const Aabb b = tree.bounds(h);
        bool take = false;
        switch (round) {
          case 0: take = r.unit() < 0.3; break;                              // scattered
          case 1: take = b.center().x() < cutX; break;                       // a half-space cut
          case 2: take = b.extent().maxCoeff() > 20.f; break;                // the giants
          case 3: take = gone.size() < 10 && r.unit() < 0.1; break;          // a few
          case 4: take = r.unit() < 0.9; break;                              // most
          default: take = true;                                              // the rest
        }
        (take ? gone : kept).push_back(h);
      }
      if (round == 0) {
        // Bad lists first: a dead handle, a handle listed twice; nothing may change.
        const uint64_t before = tree.structureHash();
        std::vector<uint32_t> bad = gone;
        bad.push_back(gone.front());
        EXPECT_THROW(tree.removeMany(bad), InvalidInput);
        bad.back() = 0xFFFFFFF0u;
        EXPECT_THROW(tree.removeMany(bad), InvalidInput);
        // Short lists (removed one by one) are checked whole first too.
        EXPECT_THROW(tree.removeMany(std::vector<uint32_t>{gone[0], gone[1], gone[0]}), InvalidInput);
        EXPECT_THROW(tree.removeMany(std::vector<uint32_t>{gone[0], 0xFFFFFFF0u}), InvalidInput);
        ASSERT_EQ(tree.structureHash(), before);
        tree.validate();
      }
      tree.removeMany(gone);
      for (uint32_t h : gone) {
        twin.remove(h);
        ref.items.erase(h);
      }
      live = kept;
      tree.validate();
      ASSERT_EQ(tree.size(), live.size());
      ASSERT_EQ(tree.structureHash(), twin.structureHash()) << "round " << round;
      ASSERT_EQ(tree.rootLevel(), twin.rootLevel()) << "round " << round;
      if (!live.empty()) expectQueriesMatch(tree, ref, r, 40, region);
    }
    EXPECT_TRUE(tree.empty());
    // An emptied tree takes elements again.
    const std::vector<uint32_t> again = insertMirrored(tree, ref, boxes);
    tree.validate();
    EXPECT_EQ(tree.structureHash(), freshBuildHash(tree));
  }
}

// prefetchPaths walks a group's paths in lockstep ahead of their edits: every walk must end at
// the node holding its element (giants held at inner nodes, forced clusters, overflowing leaves
// included), dead handles are skipped, and nothing changes: removals after it leave what a twin
// removing without it leaves.
TEST(OctoBvh, PrefetchedPathsEndAtEachHolderAndChangeNothing) {
  for (const Vec3f& offset : {Vec3f(0, 0, 0), Vec3f(-3e5f, 7e5f, 2e5f)}) {
    SeededRandom r(offset.x() == 0 ? 91 : 92);
    const std::vector<Aabb> boxes = mixedWorkload(4000, 11, offset);
    OctoBvh tree, twin;
    test::BruteForceIndex ref, twinRef;
    std::vector<uint32_t> live = insertMirrored(tree, ref, boxes);
    insertMirrored(twin, twinRef, boxes);
    ASSERT_GT(tree.shapeStats().forcedElements, 0u);
    for (uint32_t i = uint32_t(live.size()); i > 1; --i) std::swap(live[i - 1], live[r.below(i)]);
    std::vector<uint32_t> dead;
    for (size_t first = 0; first < live.size(); first += OctoBvh::kPrefetchGroup) {
      const size_t n = std::min(OctoBvh::kPrefetchGroup, live.size() - first);
      std::vector<uint32_t> group(live.begin() + first, live.begin() + first + n);
      const uint64_t before = tree.structureHash();
      ASSERT_EQ(tree.prefetchPaths(group), n) << "group at " << first;
      // Dead and never-used handles mixed in are skipped; longer lists go group by group.
      std::vector<uint32_t> mixed = group;
      mixed.insert(mixed.end(), dead.begin(), dead.begin() + std::min<size_t>(dead.size(), 5));
      mixed.push_back(0xFFFFFFF0u);
      mixed.insert(mixed.end(), group.begin(), group.end());
      ASSERT_EQ(tree.prefetchPaths(mixed), 2 * n);
      ASSERT_EQ(tree.structureHash(), before);
      // Half of each group removed, the rest moved a little (in place or along a new path).
      for (uint32_t h : group) {
        if (r.unit() < 0.5) {
          tree.remove(h);
          twin.remove(h);
          dead.push_back(h);
        } else {
          const Aabb b = tree.bounds(h);
          const Vec3f step(float(r.uniform(-0.3, 0.3)), 0.f, float(r.uniform(-2.0, 2.0)));
          tree.update(h, {b.min + step, b.max + step}, tree.filter(h));
          twin.update(h, {b.min + step, b.max + step}, twin.filter(h));
        }
      }
      if (first % (8 * OctoBvh::kPrefetchGroup) == 0) {
        tree.validate();
        ASSERT_EQ(tree.structureHash(), twin.structureHash()) << "group at " << first;
      }
    }
    tree.validate();
    EXPECT_EQ(tree.structureHash(), twin.structureHash());
    EXPECT_EQ(tree.prefetchPaths(dead), 0u);
  }
}

// Giants among small bricks sit in forced clusters: removing all but a few giants must hold them
// at their node again, and removing every small brick under them must turn the forced cluster
// back into the children, as single removals do.
TEST(OctoBvh, RemoveManyUndoesForcedClusters) {
  for (int keepGiants : {10, 40}) {
    SeededRandom r(uint64_t(80 + keepGiants));
    std::vector<Aabb> boxes = generatePlateStack(40, 120.f, 3);
    const Aabb stack = regionOf(boxes);
    for (int i = 0; i < 600; ++i) {  // half of them near the stack's axis, where the giants' nodes are
      const float reach = i % 2 ? 1.f : 0.05f;
      const Vec3f c(float(r.uniform(stack.min.x(), stack.max.x())) * reach, float(r.uniform(stack.min.y(), stack.max.y())),
                    float(r.uniform(stack.min.z(), stack.max.z())) * reach);
      const Vec3f h = Vec3f::Constant(float(r.logUniform(0.1, 1.0)));
      boxes.push_back({c - h, c + h});
    }
    OctoBvh tree, twin;
    test::BruteForceIndex ref, twinRef;
    const std::vector<uint32_t> live = insertMirrored(tree, ref, boxes);
    insertMirrored(twin, twinRef, boxes);
    ASSERT_GT(tree.shapeStats().forcedClusters, 0u);
    std::vector<uint32_t> gone;  // (at least 64: fewer are removed one by one)
    for (uint32_t i = 0; i < live.size(); ++i)
      if (i < 40 ? i % 4 != 0 && keepGiants < 40 : keepGiants == 40 || i % 5 == 0) gone.push_back(live[i]);  // 3 giants in 4 and small ones, or every small one
    for (uint32_t i = uint32_t(gone.size()); i > 1; --i) std::swap(gone[i - 1], gone[r.below(i)]);
    tree.removeMany(gone);
    for (uint32_t h : gone) {
      twin.remove(h);
      ref.items.erase(h);
    }
    tree.validate();
    EXPECT_EQ(tree.shapeStats().forcedClusters, twin.shapeStats().forcedClusters);
    ASSERT_EQ(tree.structureHash(), twin.structureHash()) << "keeping " << keepGiants << " giants";
    expectQueriesMatch(tree, ref, r, 40, stack);
  }
}

TEST(OctoBvh, PlateStackForceSplitsAndUndoesThem) {
  const std::vector<Aabb> plates = generatePlateStack(300, 200.f, 4);
  OctoBvh tree;
  std::vector<uint32_t> handles;
  for (uint32_t i = 0; i < plates.size(); ++i) handles.push_back(tree.insert(plates[i], 1, i));
  tree.validate();
  const auto shape = tree.shapeStats();
  EXPECT_GT(shape.forcedNodes, 0u);
  EXPECT_GT(shape.forcedElements, 200u);
  // A query near one plate must not test the whole stack.
  QueryStats st;
  std::vector<uint32_t> got;
  tree.overlap(Aabb{Vec3f(-1, 30, -1), Vec3f(1, 30.5f, 1)}, 1, got, &st);
  EXPECT_LT(st.boxTests, 200u) << "forced splits must localise queries in a plate stack";
  SeededRandom r(5);
  for (uint32_t i = uint32_t(handles.size()); i > 1; --i) std::swap(handles[i - 1], handles[r.below(i)]);
  for (size_t k = 0; k < handles.size(); ++k) {
    tree.remove(handles[k]);
    if (k % 37 == 0) tree.validate();
  }
  EXPECT_TRUE(tree.empty());
  EXPECT_EQ(tree.rootLevel(), octobvh::kMinLevel + 1);
  EXPECT_EQ(tree.memoryStats().clusters, 1u) << "only the root cluster remains";
  EXPECT_EQ(tree.memoryStats().leafBlocks, 0u);
}

// Giants among small bricks go to a forced cluster beside the small bricks' children, so the
// children's tight bounds stay small; the cluster moves back into the children when the last
// small brick goes, out again when one comes back, and dissolves when 8 giants are left.
TEST(OctoBvh, GiantsAmongSmallBricksLiveInAForcedClusterAndMoveBack) {
  const std::vector<Aabb> plates = generatePlateStack(60, 150.f, 8);
  BrickWorkloadParams p;
  p.count = 3000;
  p.seed = 8;
  p.clusters = 3;
  p.extent = 60.f;
  p.offset = Vec3f(-30.f, 0.f, -30.f);
  p.mediumShare = 0.f;
  p.smallShare = 1.f;
  const std::vector<Aabb> small = generateBrickWorkload(p);
  OctoBvh tree;
  std::vector<uint32_t> plateHandles, smallHandles;
  for (uint32_t i = 0; i < plates.size(); ++i) plateHandles.push_back(tree.insert(plates[i], 1, i));
  tree.validate();
  EXPECT_EQ(tree.shapeStats().forcedClusters, 0u) << "plates alone are forced into the children";
  EXPECT_GT(tree.shapeStats().forcedNodes, 0u);
  for (uint32_t i = 0; i < small.size(); ++i) smallHandles.push_back(tree.insert(small[i], 2, 1000 + i));
  tree.validate();
  EXPECT_GT(tree.shapeStats().forcedClusters, 0u) << "plates among small bricks sit in forced clusters";

  auto expectCanonical = [&](const char* when) {
    tree.validate();
    ASSERT_EQ(tree.structureHash(), freshBuildHash(tree)) << when;
  };
  expectCanonical("after inserting the small bricks");
  SeededRandom r(12);
  for (uint32_t i = uint32_t(smallHandles.size()); i > 1; --i) std::swap(smallHandles[i - 1], smallHandles[r.below(i)]);
  for (size_t k = 0; k < smallHandles.size(); ++k) {
    tree.remove(smallHandles[k]);
    if (k % 301 == 0) expectCanonical("removing small bricks");
  }
  expectCanonical("after removing every small brick");
  EXPECT_EQ(tree.shapeStats().forcedClusters, 0u);
  smallHandles.clear();
  for (uint32_t i = 0; i < small.size(); i += 7) smallHandles.push_back(tree.insert(small[i], 2, 1000 + i));
  expectCanonical("after putting some small bricks back");
  EXPECT_GT(tree.shapeStats().forcedClusters, 0u);
  for (uint32_t i = uint32_t(plateHandles.size()); i > 1; --i) std::swap(plateHandles[i - 1], plateHandles[r.below(i)]);
  for (size_t k = 0; k < plateHandles.size(); ++k) {
    tree.remove(plateHandles[k]);
    if (plateHandles.size() - k < 12) expectCanonical("removing the last plates");
  }
  EXPECT_EQ(tree.shapeStats().forcedClusters, 0u);
  for (uint32_t h : smallHandles) tree.remove(h);
  EXPECT_TRUE(tree.empty());
  EXPECT_EQ(tree.memoryStats().clusters, 1u) << "only the root cluster remains";
}

TEST(OctoBvh, LodReportsSmallSubtreesAsBoxesCoveringTheirElements) {
  BrickWorkloadParams p;
  p.count = 20'000;
  p.extent = 300.f;
  const std::vector<Aabb> boxes = generateBrickWorkload(p);
  OctoBvh tree;
  for (uint32_t i = 0; i < boxes.size(); ++i) tree.insert(boxes[i], 1, i);
  SeededRandom r(8);
  for (int q = 0; q < 200; ++q) {
    const Vec3f c = tree.rootBounds().center() + Vec3f(float(r.normal() * 60), float(r.normal() * 20), float(r.normal() * 60));
    const Aabb box = Aabb::fromCenterHalf(c, Vec3f::Constant(float(r.logUniform(1, 40))));
    std::vector<uint32_t> exact;
    tree.overlap(box, 1, exact);
    std::vector<uint32_t> elems;
    std::vector<LodBox> lods;
    QueryStats lodStats, fullStats;
    tree.overlapLod(box, 1, 1.f / 16, [&](uint32_t e) { elems.push_back(e); }, [&](const LodBox& b) { lods.push_back(b); }, &lodStats);
    tree.overlap(box, 1, [](uint32_t) {}, &fullStats);
    EXPECT_LE(lodStats.boxTests, fullStats.boxTests);
    const float limit = box.extent().maxCoeff() / 16;
    for (const LodBox& b : lods) {
      EXPECT_LT(b.bounds.extent().maxCoeff(), limit);
      EXPECT_TRUE(b.bounds.overlaps(box));
    }
    // Every exactly-overlapping element is reported or lies inside a reported LOD box.
    for (uint32_t e : exact) {
      const bool direct = std::find(elems.begin(), elems.end(), e) != elems.end();
      const bool covered = std::any_of(lods.begin(), lods.end(), [&](const LodBox& b) { return b.bounds.contains(tree.bounds(e)); });
      ASSERT_TRUE(direct || covered) << "element " << e << " lost by LOD";
    }
    // With LOD off (fraction 0) it is the plain overlap.
    elems.clear();
    lods.clear();
    tree.overlapLod(box, 1, 0.f, [&](uint32_t e) { elems.push_back(e); }, [&](const LodBox& b) { lods.push_back(b); });
    std::sort(elems.begin(), elems.end());
    std::sort(exact.begin(), exact.end());
    EXPECT_EQ(elems, exact);
    EXPECT_TRUE(lods.empty());
  }
}

TEST(OctoBvh, MemoryGoesBackWhenEmptiedInRandomOrder) {
  BrickWorkloadParams p;
  p.count = 300'000;
  const std::vector<Aabb> boxes = generateBrickWorkload(p);
  OctoBvh tree(OctoBvh::Config{400'000});
  std::vector<uint32_t> h;
  for (uint32_t i = 0; i < boxes.size(); ++i) h.push_back(tree.insert(boxes[i], 1, i));
  const size_t full = tree.residentBytes();
  const auto mem = tree.memoryStats();
  EXPECT_EQ(mem.nodeBytes / mem.nodes, 40u);
  SeededRandom r(3);
  for (uint32_t i = uint32_t(h.size()); i > 1; --i) std::swap(h[i - 1], h[r.below(i)]);
  for (uint32_t x : h) tree.remove(x);
  EXPECT_TRUE(tree.empty());
  EXPECT_LT(tree.residentBytes(), full / 50) << "resident " << tree.residentBytes() << " of " << full;
  tree.validate();
}

TEST(OctoBvh, RayChildOrderRanksAxesByMagnitudeWithTiesInAxisOrder) {
  // The visit order decides which of two hits at equal t a traversal meets first, so it must not
  // change with how the axes are ranked: against std::stable_sort's ranking, on random
  // directions and on directions whose components tie in magnitude (and in sign or not).
  SeededRandom r(5);
  const float values[] = {0.f, 1.f, -1.f, 0.5f, -0.5f, 2.f};
  for (int i = 0; i < 3000; ++i) {
    Vec3f d;
    for (int k = 0; k < 3; ++k) d[k] = i < 1500 ? values[r.below(6)] : float(r.normal());
    int axis[3] = {0, 1, 2};
    std::stable_sort(axis, axis + 3, [&](int a, int b) { return std::abs(d[a]) > std::abs(d[b]); });
    std::array<uint8_t, 8> expected{};
    for (int k = 0; k < 8; ++k)
      for (int rank = 0; rank < 3; ++rank)
        expected[k] |= uint8_t((((k >> (2 - rank)) & 1) ^ (d[axis[rank]] < 0.f ? 1 : 0)) << axis[rank]);
    ASSERT_EQ(OctoBvh::rayChildOrder(d), expected) << d.transpose();
  }
}

TEST(OctoBvh, RayChildOrderIsFrontToBack) {
  // For every direction, a child visited later is never strictly nearer on every axis.
  SeededRandom r(4);
  for (int i = 0; i < 2000; ++i) {
    Vec3f d(float(r.normal()), float(r.normal()), float(r.normal()));
    if (i % 3 == 0) d[i % 3] = 0.f;
    const auto order = OctoBvh::rayChildOrder(d);
    std::array<bool, 8> seen{};
    for (int k = 0; k < 8; ++k) seen[order[k]] = true;
    for (bool s : seen) ASSERT_TRUE(s);
    // A child visited later is never nearer on every axis where the two differ.
    for (int a = 0; a < 8; ++a)
      for (int b = a + 1; b < 8; ++b) {
        bool bNearerEverywhere = true;
        for (int ax = 0; ax < 3; ++ax) {
          const int nearBit = d[ax] < 0 ? 1 : 0;
          if ((((order[b] >> ax) & 1) ^ nearBit) > (((order[a] >> ax) & 1) ^ nearBit)) bNearerEverywhere = false;
        }
        ASSERT_FALSE(bNearerEverywhere) << "child " << int(order[b]) << " is in front of " << int(order[a]);
      }
  }
}

}  // namespace
}  // namespace bw

namespace bw {
namespace {

TEST(OctoBvhLayout, MinLevelIsTheSmallestCoveringPowerOfTwo) {
  using octobvh::minLevelForExtent;
  EXPECT_EQ(minLevelForExtent(0.f), octobvh::kMinLevel);
  EXPECT_EQ(minLevelForExtent(1e-30f), octobvh::kMinLevel);
  EXPECT_EQ(minLevelForExtent(1.f), 0);
  EXPECT_EQ(minLevelForExtent(std::nextafter(1.f, 2.f)), 1);
  EXPECT_EQ(minLevelForExtent(0.5f), -1);
  EXPECT_EQ(minLevelForExtent(0.04f), -4);
  EXPECT_EQ(minLevelForExtent(500.f), 9);
  EXPECT_EQ(minLevelForExtent(512.f), 9);
  EXPECT_EQ(minLevelForExtent(3e9f), octobvh::kMaxLevel);
  SeededRandom r(1);
  for (int i = 0; i < 100000; ++i) {
    const float e = float(r.logUniform(1e-4, 1e9));
    const int l = minLevelForExtent(e);
    ASSERT_GE(std::ldexp(1.0, l), double(e));
    if (l > octobvh::kMinLevel) {
      ASSERT_LT(std::ldexp(1.0, l - 1), double(e));
    }
  }
}

}  // namespace
}  // namespace bw
