// Two-way grid vs grid (collideGridPair): with the LOD off, exactly the contacts of every brick
// pair (brute force), for random builds of every shape in random relative poses, near and far
// from the origin; interlocked rings touch nowhere though their convex approximations overlap
// deeply; with the LOD on, no touching pair goes without contacts.
#include <algorithm>
#include <gtest/gtest.h>
#include <tuple>

#include "collision/bricks/brick_geometry.h"
#include "collision/bricks/brick_grid.h"
#include "collision/bricks/grid_pair.h"
#include "collision/core/seeded_random.h"

namespace bw {
namespace {

Brick randomBrick(SeededRandom& r, const Vec3f& position) {
  Brick b;
  b.position = position;
  b.halfSize = Vec3f(float(r.logUniform(0.1, 0.6)), float(r.logUniform(0.1, 0.6)), float(r.logUniform(0.1, 0.6)));
  b.shape = BrickShape(r.below(4));
  b.sides = uint8_t(3 + r.below(14));
  b.rotation = AxisRotation::fromIndex(int(r.below(24)));
  return b;
}

int placed(const BrickGrid& g) { return int(g.brickCount()); }

// A lumpy build: bricks on a jittered lattice with holes, a few large plates among them.
void fillGrid(BrickGrid& g, uint64_t seed, int n, const Vec3f& offset) {
  SeededRandom r(seed);
  const int side = int(std::ceil(std::cbrt(double(n) * 1.5)));
  for (int i = 0; placed(g) < n && i < 8 * n; ++i) {
    if (r.below(3) == 0) continue;  // holes
    const Vec3f cell(float(i % side), float((i / side) % side), float(i / (side * side)));
    Brick b = randomBrick(r, offset + cell * 1.0f + Vec3f(float(r.uniform(-0.1, 0.1)), float(r.uniform(-0.1, 0.1)), 0.f));
    if (i % 53 == 0) b.halfSize = Vec3f(3.f, 2.f, 0.1f);
    g.placeBrick(b);
  }
}

using Key = std::tuple<uint32_t, uint32_t, float>;

std::vector<Key> bruteForce(const BrickGrid& a, const BrickGrid& b, const LocalPose& aInB, float margin) {
  std::vector<Key> keys;
  Vec3f hull[kMaxBrickVertices];
  LocalContact c[kMaxContactsPerBrick];
  a.forEachBrick([&](uint32_t ia) {
    const Brick& ba = a.brick(ia);
    const QueryShape shape = brickQueryShape(ba, hull);
    const LocalPose pose{aInB.rotation * ba.position + aInB.position, aInB.rotation * ba.rotation.quaternion()};
    b.forEachBrick([&](uint32_t ib) {
      const int n = collideShapeBrick(shape, pose, b.brick(ib), ib, margin, c);
      for (int k = 0; k < n; ++k) keys.emplace_back(ia, ib, c[k].depth);
    });
  });
  std::sort(keys.begin(), keys.end());
  return keys;
}

TEST(GridPair, WithoutLodEqualsEveryBrickPair) {
  int withContacts = 0;
  for (const Vec3f& offset : {Vec3f(0, 0, 0), Vec3f(3e5f, -1e5f, 2e4f)}) {
    BrickGrid a, b;
    fillGrid(a, 1, 300, offset);
    fillGrid(b, 2, 400, offset);
    SeededRandom r(3);
    for (int q = 0; q < 40; ++q) {
      const Quatf rot(Eigen::AngleAxisf(float(r.uniform(0, 6.28)), Vec3f(float(r.normal()), float(r.normal()), float(r.normal())).normalized()));
      // a's centre placed near a random point of b's bounds
      const Vec3f target = b.bounds().center() + b.bounds().halfExtent().cwiseProduct(Vec3f(float(r.uniform(-1, 1)), float(r.uniform(-1, 1)), float(r.uniform(-1, 1))));
      const LocalPose aInB{target - rot * a.bounds().center(), rot};
      GridPairParams params;
      params.lodFraction = 0.f;
      params.speculativeMargin = q % 2 ? 0.05f : 0.f;
      GridPairScratch scratch;
      std::vector<GridPairContact> got;
      GridPairStats stats;
      collideGridPair(a, b, aInB, params, scratch, got, &stats);
      std::vector<Key> keys;
      for (const GridPairContact& c : got) {
        ASSERT_NEAR(c.normal.norm(), 1.f, 1e-3f);
        keys.emplace_back(c.brickA, c.brickB, c.depth);
      }
      std::sort(keys.begin(), keys.end());
      const std::vector<Key> expected = bruteForce(a, b, aInB, params.speculativeMargin);
      ASSERT_EQ(keys.size(), expected.size()) << "pose " << q;
      ASSERT_TRUE(keys == expected) << "pose " << q;
      // it prunes: far fewer narrowphase pairs than every brick pair
      EXPECT_LT(stats.brickPairs, uint64_t(a.brickCount()) * b.brickCount() / 4) << "pose " << q;
      withContacts += !got.empty();
    }
  }
  EXPECT_GT(withContacts, 40);
}

// A square ring of 0.1 m box bricks, 4 m across, in the plane through `centre` whose normal is
// `axis`: 160 bricks, more than kBrickwiseGridBricks, so the one-way path meets its hull.
void ring(BrickGrid& g, int axis, const Vec3f& centre) {
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  const Vec3f h = Vec3f::Constant(0.05f);
  for (int i = -20; i <= 20; ++i)
    for (int side = -1; side <= 1; side += 2) {
      Vec3f p1 = centre, p2 = centre;
      p1[u] += 0.1f * float(i), p1[v] += 2.f * float(side);  // the bars along u, at v = +-2
      p2[v] += 0.1f * float(i), p2[u] += 2.f * float(side);  // the bars along v, at u = +-2
      g.placeBrick(Brick::box(p1, h));
      if (std::abs(i) < 20) g.placeBrick(Brick::box(p2, h));
    }
}

TEST(GridPair, InterlockedRingsTouchNowhereThoughTheirHullsOverlap) {
  // Ring a in the xz plane (normal y) raised 2 m, ring b in the yz plane (normal x), linked:
  // a's lower bar passes through b's hole and b's upper bar through a's, 2 m from any brick.
  BrickGrid a, b;
  ring(a, 1, Vec3f(0, 0, 0));
  ring(b, 0, Vec3f(0, 0, 0));
  ASSERT_GT(a.brickCount(), kBrickwiseGridBricks);
  const LocalPose aInB{Vec3f(0.f, 0.f, 2.f), Quatf::Identity()};
  GridPairParams params;
  GridPairScratch scratch;
  std::vector<GridPairContact> got;
  for (float lod : {0.f, 1.f / 16, 0.25f}) {
    params.lodFraction = lod;
    got.clear();
    collideGridPair(a, b, aInB, params, scratch, got);
    EXPECT_TRUE(got.empty()) << "lod " << lod << ": " << got.size() << " contacts between rings that do not touch";
  }
  // The one-way path, b's convex approximation against a's bricks, is solid across b's hole.
  ContactParams cp;
  ContactScratch cs;
  std::vector<Contact> oneWay;
  int smaller = 0;
  collideGrids(a, RigidTransform{aInB.position.cast<double>(), aInB.rotation}, b, RigidTransform{}, 2, cp, cs, oneWay, smaller);
  float deepest = 0;
  for (const Contact& c : oneWay) deepest = std::max(deepest, c.depth);
  EXPECT_GT(deepest, 0.05f) << "the convex approximation should overlap the other ring (by its 0.1 m thickness)";
  // Lowered by 1.98 m, a's lower bar (z -2.03..-1.93) overlaps b's (-2.05..-1.95) by 8 cm.
  params.lodFraction = 0.f;
  got.clear();
  collideGridPair(a, b, LocalPose{Vec3f(0.f, 0.f, 0.02f), Quatf::Identity()}, params, scratch, got);
  ASSERT_FALSE(got.empty());
  float deepestTwoWay = 0;
  for (const GridPairContact& c : got) {
    EXPECT_GE(c.depth, -1e-4f);  // the crossing cubes' neighbours touch face to face (depth 0)
    EXPECT_LE(c.depth, 0.081f);
    deepestTwoWay = std::max(deepestTwoWay, c.depth);
  }
  EXPECT_NEAR(deepestTwoWay, 0.08f, 1e-3f);
}

TEST(GridPair, LodNeverLeavesATouchingPairWithoutContacts) {
  BrickGrid a, b;
  fillGrid(a, 4, 200, Vec3f::Zero());
  fillGrid(b, 5, 3000, Vec3f::Zero());
  SeededRandom r(6);
  int touching = 0;
  for (int q = 0; q < 60; ++q) {
    const Quatf rot(Eigen::AngleAxisf(float(r.uniform(0, 6.28)), Vec3f(float(r.normal()), float(r.normal()), float(r.normal())).normalized()));
    const Vec3f target = b.bounds().center() + b.bounds().halfExtent().cwiseProduct(Vec3f(float(r.uniform(-1, 1)), float(r.uniform(-1, 1)), float(r.uniform(-1, 1))));
    const LocalPose aInB{target - rot * a.bounds().center(), rot};
    GridPairScratch scratch;
    std::vector<GridPairContact> exact, lod;
    GridPairParams params;
    params.lodFraction = 0.f;
    collideGridPair(a, b, aInB, params, scratch, exact);
    params.lodFraction = 1.f / 4;
    GridPairStats stats;
    collideGridPair(a, b, aInB, params, scratch, lod, &stats);
    const bool exactTouch = std::any_of(exact.begin(), exact.end(), [](const GridPairContact& c) { return c.depth > 0; });
    if (exactTouch) {
      ++touching;
      EXPECT_TRUE(std::any_of(lod.begin(), lod.end(), [](const GridPairContact& c) { return c.depth > 0; })) << "pose " << q;
    }
  }
  EXPECT_GT(touching, 20);
}

}  // namespace
}  // namespace bw

namespace bw {
namespace {

// collideGrids with the two-way and automatic modes: the linked rings (hull fill far above
// kAutoTwoWayFill) go brick against brick in both, so nothing touches; the convex mode's hull
// does; a solid slab (fill 1) stays convex under auto.
TEST(GridPair, CollideGridsModesChooseTwoWayForHollowGrids) {
  BrickGrid a, b;
  ring(a, 1, Vec3f(0, 0, 0));
  ring(b, 0, Vec3f(0, 0, 0));
  const RigidTransform poseA{Vec3d(100.0, -50.0, 2.0), Quatf::Identity()}, poseB{Vec3d(100.0, -50.0, 0.0), Quatf::Identity()};
  const ConvexApproximation& hull = a.convexApproximation(3);
  EXPECT_GT(hull.hullVolume, kAutoTwoWayFill * hull.brickVolume);
  ContactParams params;
  ContactScratch scratch;
  std::vector<Contact> out;
  int smaller = 0;
  for (GridPairMode mode : {GridPairMode::TwoWay, GridPairMode::Auto}) {
    out.clear();
    collideGrids(a, poseA, b, poseB, 3, params, scratch, out, smaller, nullptr, mode);
    EXPECT_TRUE(std::none_of(out.begin(), out.end(), [](const Contact& c) { return c.depth > 0; })) << int(mode);
  }
  out.clear();
  collideGrids(a, poseA, b, poseB, 3, params, scratch, out, smaller, nullptr, GridPairMode::Convex);
  EXPECT_TRUE(std::any_of(out.begin(), out.end(), [](const Contact& c) { return c.depth > 0.05f; }));
  // Lowered to b's centre height: both rings' upper bars cross at z = 2 and lower bars at z =
  // -2; the two-way contacts are world-space, on b's bars, at most the manifold after reduction.
  out.clear();
  const RigidTransform lowered{Vec3d(100.0, -50.0, 0.02), Quatf::Identity()};
  collideGrids(a, lowered, b, poseB, 3, params, scratch, out, smaller, nullptr, GridPairMode::TwoWay);
  ASSERT_FALSE(out.empty());
  EXPECT_LE(out.size(), size_t(params.maxContacts * kManifoldNormalGroups));
  for (const Contact& c : out) {
    EXPECT_NEAR(c.position.x(), 100.0, 2.5);
    EXPECT_NEAR(std::abs(c.position.z()), 2.0, 0.1);
  }
  // A solid slab of 4x4x2 bricks: its hull is its bricks, so auto keeps the convex path.
  BrickGrid slab;
  for (int i = 0; i < 200; ++i) slab.placeBrick(Brick::box(Vec3f(float(i % 10), float((i / 10) % 10), float(i / 100)), Vec3f::Constant(0.5f)));
  const ConvexApproximation& solid = slab.convexApproximation(3);
  EXPECT_LE(solid.hullVolume, kAutoTwoWayFill * solid.brickVolume);
}

}  // namespace
}  // namespace bw
