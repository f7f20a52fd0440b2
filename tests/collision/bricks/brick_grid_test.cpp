// Brick shapes and grids: exact geometry, mass properties, raycasts and contacts against brute
// force over every brick, collision LOD, convex approximation, grid vs grid, edits, bad input.
#include <algorithm>
#include <cstring>
#include <gtest/gtest.h>
#include <map>

#include "collision/bricks/brick_grid.h"
#include "collision/core/argument_checks.h"
#include "collision/core/errors.h"
#include "collision/core/seeded_random.h"

namespace bw {
namespace {

Brick randomBrick(SeededRandom& r, const Vec3f& position, float scale = 1.f) {
  Brick b;
  b.position = position;
  b.halfSize = Vec3f(float(r.logUniform(0.04, 1.0)), float(r.logUniform(0.04, 1.0)), float(r.logUniform(0.04, 1.0))) * scale;
  b.shape = BrickShape(r.below(4));
  b.sides = uint8_t(3 + r.below(14));
  b.rotation = AxisRotation::fromIndex(int(r.below(24)));
  b.filter = 1u << r.below(3);
  b.material = uint8_t(r.below(4));
  return b;
}

// A grid of random bricks on a jittered lattice (neighbours touch or nearly), plus a few large ones.
std::vector<Brick> randomBuild(uint64_t seed, int n, const Vec3f& offset) {
  SeededRandom r(seed);
  std::vector<Brick> out;
  const int side = int(std::ceil(std::cbrt(double(n))));
  for (int i = 0; i < n; ++i) {
    const Vec3f cell(float(i % side), float((i / side) % side), float(i / (side * side)));
    Brick b = randomBrick(r, offset + cell * 2.f + Vec3f(float(r.uniform(-0.2, 0.2)), float(r.uniform(-0.2, 0.2)), 0.f));
    if (i % 97 == 0) b.halfSize *= 6.f;  // large bricks among small ones
    out.push_back(b);
  }
  return out;
}

TEST(BrickGeometry, MomentsMatchNumericalIntegration) {
  SeededRandom r(1);
  for (int k = 0; k < 24; ++k) {
    Brick b = randomBrick(r, Vec3f(float(r.uniform(-5, 5)), 1.f, 2.f));
    b.halfSize = Vec3f(float(r.uniform(0.3, 1.5)), float(r.uniform(0.3, 1.5)), float(r.uniform(0.3, 1.5)));
    b.shape = BrickShape(k % 4);
    const Vec3d ref(0.5, -1, 2);
    const ShapeMoments exact = brickMoments(b, 2.0, ref);
    // Midpoint integration over the bounds on a 64^3 lattice.
    const Aabb box = brickBounds(b);
    const int n = 64;
    const Vec3d step = box.extent().cast<double>() / n;
    const double cell = step.prod();
    ShapeMoments num;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int l = 0; l < n; ++l) {
          const Vec3d p = box.min.cast<double>() + Vec3d((i + 0.5) * step.x(), (j + 0.5) * step.y(), (l + 0.5) * step.z());
          if (!brickContains(b, p.cast<float>())) continue;
          const Vec3d q = p - ref;
          num.volume += 2.0 * cell;
          num.first += 2.0 * cell * q;
          num.second += 2.0 * cell * q * q.transpose();
        }
    const double scale = box.extent().maxCoeff();
    EXPECT_NEAR(num.volume, exact.volume, 0.03 * exact.volume) << "shape " << k % 4;
    EXPECT_LT((num.first - exact.first).norm(), 0.03 * exact.volume * (scale + ref.norm())) << "shape " << k % 4;
    EXPECT_LT((num.second - exact.second).norm(), 0.05 * exact.second.norm()) << "shape " << k % 4;
  }
}

// Boxes take a shortcut to their moments: bit for bit the general formula's result (state hashes
// depend on it), for every rotation, offsets with zero and negative-zero components, far points.
TEST(BrickGeometry, BoxMomentsShortcutGivesTheGeneralFormulasBits) {
  SeededRandom r(12);
  for (int k = 0; k < 20000; ++k) {
    Brick b = Brick::box(Vec3f::Zero(), Vec3f(float(r.logUniform(0.01, 500)), float(r.logUniform(0.01, 500)), float(r.logUniform(0.01, 500))));
    b.rotation = AxisRotation::fromIndex(k % 24);
    const int mode = int(r.below(4));
    if (mode > 0) b.position = Vec3f(float(r.uniform(-1e5, 1e5)), mode == 2 ? -0.f : float(r.uniform(-10, 10)), float(r.uniform(-3e3, 3e3)));
    const Vec3d reference = mode == 3 ? b.position.cast<double>() : Vec3d(r.uniform(-100, 100), 0.0, -0.0);
    const double density = k % 2 ? 1.0 : 2.5;
    const ShapeMoments fast = brickMoments(b, density, reference), general = generalBrickMoments(b, density, reference);
    ASSERT_EQ(std::memcmp(&fast.volume, &general.volume, sizeof(double)), 0) << k;
    ASSERT_EQ(std::memcmp(fast.first.data(), general.first.data(), 3 * sizeof(double)), 0) << k;
    ASSERT_EQ(std::memcmp(fast.second.data(), general.second.data(), 9 * sizeof(double)), 0) << k;
  }
}

TEST(BrickGeometry, BoundsAreExactForEveryShapeAndRotation) {
  SeededRandom r(2);
  for (int k = 0; k < 2000; ++k) {
    const Brick b = randomBrick(r, Vec3f(float(r.uniform(-100, 100)), 0, 3));
    Vec3f v[kMaxBrickVertices];
    const int n = brickVertices(b, v);
    Aabb tight = Aabb::empty();
    for (int i = 0; i < n; ++i) tight.merge(v[i]);
    const Aabb got = brickBounds(b);
    ASSERT_LT((got.min - tight.min).cwiseAbs().maxCoeff(), 1e-5f * (1 + got.extent().maxCoeff()));
    ASSERT_LT((got.max - tight.max).cwiseAbs().maxCoeff(), 1e-5f * (1 + got.extent().maxCoeff()));
    for (int i = 0; i < n; ++i) ASSERT_TRUE(brickContains(b, v[i], 1e-4f));
  }
}

TEST(BrickGeometry, RayEntersOnTheSurface) {
  SeededRandom r(3);
  int hits = 0;
  for (int k = 0; k < 5000; ++k) {
    const Brick b = randomBrick(r, Vec3f::Zero());
    const Vec3f o = Vec3f(float(r.normal()), float(r.normal()), float(r.normal())) * 2.f;
    // Aim at a random point of the bounds so most rays hit; some stay axis-parallel.
    const Aabb box = brickBounds(b);
    const Vec3f target(float(r.uniform(box.min.x(), box.max.x())), float(r.uniform(box.min.y(), box.max.y())),
                       float(r.uniform(box.min.z(), box.max.z())));
    Vec3f d = target - o;
    if (k % 5 == 0) d[k % 3] = 0.f;
    if (d.isZero()) continue;
    float t;
    Vec3f n;
    if (!rayBrick(b, Ray::make(o, d.normalized()), 100.f, t, n)) continue;
    ++hits;
    const Vec3f p = o + d.normalized() * t;
    ASSERT_TRUE(brickContains(b, p, 1e-4f));
    if (t > 1e-3f) {
      ASSERT_FALSE(brickContains(b, o + d.normalized() * (t - 1e-3f), 0.f)) << "entered earlier than reported";
      ASSERT_LE(n.dot(d.normalized()), 1e-5f) << "normal faces the ray";
    }
  }
  EXPECT_GT(hits, 500);
}

// Direct sum of every brick's moments, compared with the incrementally kept properties.
// The sum is taken about `reference` (near the bricks): about the origin, a build 1e6 away would
// lose ~1e-6 of its inertia to cancellation in the reference itself.
void expectMassMatchesDirectSum(const BrickGrid& grid, const BrickGrid::Config& config, const Vec3d& reference) {
  ShapeMoments sum;
  grid.forEachBrick([&](uint32_t id) { sum += brickMoments(grid.brick(id), config.density[grid.brick(id).material], reference); });
  const MassProperties m = grid.massProperties();
  ASSERT_NEAR(m.mass, sum.volume, 1e-9 * sum.volume);
  const Vec3d comRel = sum.first / sum.volume;
  const Vec3d com = reference + comRel;
  EXPECT_LT((m.centerOfMass - com).norm(), 1e-6 * (1 + com.norm()));
  const Mat3d c = sum.second - sum.volume * comRel * comRel.transpose();
  const Mat3d inertia = c.trace() * Mat3d::Identity() - c;
  EXPECT_LT((m.inertia - inertia).norm(), 1e-8 * inertia.norm());
}

TEST(BrickGrid, MassPropertiesFollowRandomEditsAndMatchDirectSums) {
  for (const Vec3f& offset : {Vec3f(0, 0, 0), Vec3f(1e6f, -2e5f, 3e5f)}) {
    BrickGrid::Config config;
    config.density[1] = 2.5f;
    config.density[3] = 0.3f;
    BrickGrid grid(config);
    const std::vector<Brick> build = randomBuild(4, 3000, offset);
    std::vector<uint32_t> ids;
    for (const Brick& b : build) ids.push_back(grid.placeBrick(b));
    expectMassMatchesDirectSum(grid, config, offset.cast<double>());
    SeededRandom r(5);
    for (int k = 0; k < 2000; ++k) {
      const size_t i = r.below(uint32_t(ids.size()));
      grid.removeBrick(ids[i]);
      ids[i] = ids.back();
      ids.pop_back();
      if (k % 3 == 0) ids.push_back(grid.placeBrick(randomBrick(r, offset + Vec3f(float(r.uniform(0, 30)), float(r.uniform(0, 30)), float(r.uniform(0, 30))))));
    }
    expectMassMatchesDirectSum(grid, config, offset.cast<double>());
    grid.index().validate();
    for (uint32_t id : ids) grid.removeBrick(id);
    EXPECT_EQ(grid.massProperties().mass, 0.0);
  }
}

// Found by fuzz_grid_edits: a 10^4 m brick placed and removed left 1e-4 of rounding in the
// running mass of small bricks (now a compensated sum), and bricks kilometres from the first
// brick placed (the moments' reference) lost 2e-7 of their inertia to cancellation (now
// re-based on the centre of mass when the bricks near the reference are gone).
TEST(BrickGrid, MassPropertiesStayExactAfterHugeAndFarEdits) {
  BrickGrid::Config config;
  config.density[1] = 7.8f;
  BrickGrid grid(config);
  SeededRandom r(31);
  std::vector<uint32_t> near;
  for (int i = 0; i < 200; ++i) near.push_back(grid.placeBrick(randomBrick(r, Vec3f(float(r.uniform(0, 5)), float(r.uniform(0, 5)), 0.f))));
  Brick huge = Brick::box(Vec3f(3, 4, 5), Vec3f(1e4f, 1e4f, 1e4f));
  huge.material = 1;
  for (int k = 0; k < 3; ++k) grid.removeBrick(grid.placeBrick(huge));
  // (the direct sum's own reference: the first brick, as the grid's)
  expectMassMatchesDirectSum(grid, config, grid.brick(near.front()).position.cast<double>());
  // Far bricks, then the near ones (the reference among them) removed.
  const Vec3f far(8000.f, -6000.f, 3000.f);
  for (int i = 0; i < 50; ++i) grid.placeBrick(randomBrick(r, far + Vec3f(float(r.uniform(0, 2)), float(r.uniform(0, 2)), float(r.uniform(0, 2))), 0.05f));
  for (uint32_t id : near) grid.removeBrick(id);
  expectMassMatchesDirectSum(grid, config, far.cast<double>());
}

TEST(BrickGrid, RaycastsMatchBruteForceOverEveryBrick) {
  BrickGrid grid;
  for (const Brick& b : randomBuild(6, 4000, Vec3f(-10, -10, -10))) grid.placeBrick(b);
  SeededRandom r(7);
  int hits = 0;
  for (int q = 0; q < 400; ++q) {
    const Vec3f o(float(r.uniform(-20, 20)), float(r.uniform(-20, 20)), float(r.uniform(-20, 20)));
    Vec3f d(float(r.normal()), float(r.normal()), float(r.normal()));
    if (q % 4 == 0) d = Vec3f::Zero(), d[q % 3] = 1.f;
    const Ray ray = Ray::make(o, d.normalized(), q % 2 ? 60.f : std::numeric_limits<float>::infinity());
    const uint32_t mask = q % 3 ? 0xFFFFFFFFu : 2u;
    float best = std::numeric_limits<float>::infinity();
    grid.forEachBrick([&](uint32_t id) {
      const Brick& b = grid.brick(id);
      float t;
      Vec3f n;
      if ((b.filter & mask) && rayBrick(b, ray, ray.maxT, t, n)) best = std::min(best, t);
    });
    const GridRayHit h = grid.raycast(ray, mask);
    ASSERT_EQ(h.hit(), best < std::numeric_limits<float>::infinity()) << "ray " << q;
    if (h.hit()) {
      ++hits;
      ASSERT_EQ(h.t, best) << "ray " << q;
      ASSERT_TRUE(grid.brick(h.brick).filter & mask);
    }
  }
  EXPECT_GT(hits, 50);
}

QueryShape shapeFor(int k, std::vector<Vec3f>& hullPoints) {
  switch (k % 4) {
    case 0: return QueryShape::sphere(0.7f);
    case 1: return QueryShape::box(Vec3f(0.9f, 0.5f, 0.3f));
    case 2: return QueryShape::capsule(0.4f, 0.8f);
    default: {
      hullPoints.clear();
      for (int i = 0; i < 8; ++i) hullPoints.emplace_back((i & 1) ? 0.6f : -0.6f, (i & 2) ? 0.4f : -0.4f, (i & 4) ? 0.5f : -0.5f);
      hullPoints.emplace_back(0.f, 0.f, 0.9f);
      return QueryShape::hull(hullPoints.data(), uint32_t(hullPoints.size()));
    }
  }
}

struct ContactKey {
  uint32_t feature;
  float depth;
  bool operator<(const ContactKey& o) const { return feature < o.feature || (feature == o.feature && depth < o.depth); }
};

TEST(BrickGrid, ContactsMatchBruteForceOverEveryBrick) {
  BrickGrid grid;
  for (const Brick& b : randomBuild(8, 3000, Vec3f::Zero())) grid.placeBrick(b);
  SeededRandom r(9);
  std::vector<Vec3f> hull;
  int withContacts = 0;
  for (int q = 0; q < 300; ++q) {
    const QueryShape shape = shapeFor(q, hull);
    const LocalPose pose{Vec3f(float(r.uniform(-1, 30)), float(r.uniform(-1, 30)), float(r.uniform(-1, 30))),
                         Quatf(Eigen::AngleAxisf(float(r.uniform(0, 6.28)), Vec3f(float(r.normal()), float(r.normal()), float(r.normal())).normalized()))};
    ContactParams params;
    params.lodFraction = 0.f;
    params.speculativeMargin = q % 2 ? 0.05f : 0.f;
    std::vector<LocalContact> got;
    grid.collideLocal(shape, pose, params, got);
    std::vector<LocalContact> expected;
    LocalContact buf[kMaxContactsPerBrick];
    grid.forEachBrick([&](uint32_t id) {
      const int n = collideShapeBrick(shape, pose, grid.brick(id), id, params.speculativeMargin, buf);
      expected.insert(expected.end(), buf, buf + n);
    });
    std::vector<ContactKey> a, b;
    for (auto& c : got) a.push_back({c.feature, c.depth});
    for (auto& c : expected) b.push_back({c.feature, c.depth});
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    ASSERT_EQ(a.size(), b.size()) << "query " << q;
    for (size_t i = 0; i < a.size(); ++i) ASSERT_TRUE(a[i].feature == b[i].feature && a[i].depth == b[i].depth);
    withContacts += !got.empty();
    for (const LocalContact& c : got) {
      ASSERT_NEAR(c.normal.norm(), 1.f, 1e-4f);
      if (c.depth > 0) {
        ASSERT_TRUE(brickContains(grid.brick(c.feature), c.position, 2e-3f)) << "contact point off the brick";
      }
    }
  }
  EXPECT_GT(withContacts, 50);
}

TEST(BrickGrid, RestingBoxGetsAFourPointManifoldWithUpNormals) {
  BrickGrid grid;
  // A floor of 10x10 plates.
  for (int x = 0; x < 10; ++x)
    for (int y = 0; y < 10; ++y) {
      Brick b;
      b.position = Vec3f(float(x), float(y), 0.f);
      b.halfSize = Vec3f(0.5f, 0.5f, 0.08f);
      grid.placeBrick(b);
    }
  ContactScratch scratch;
  std::vector<Contact> contacts;
  const RigidTransform gridPose{Vec3d(1e7, -1e7, 5e6), Quatf::Identity()};
  const RigidTransform boxPose{Vec3d(1e7 + 4.3, -1e7 + 4.6, 5e6 + 0.08 + 0.25 - 0.01), Quatf::Identity()};
  const size_t n = grid.collide(gridPose, QueryShape::box(Vec3f(0.5f, 0.5f, 0.25f)), boxPose, ContactParams{}, scratch, contacts);
  ASSERT_EQ(n, 4u);
  for (const Contact& c : contacts) {
    EXPECT_NEAR(c.normal.z(), 1.f, 1e-4f);
    EXPECT_NEAR(c.depth, 0.01f, 2e-3f) << "far from the origin the depth keeps its precision";
    EXPECT_NEAR(c.position.z(), 5e6 + 0.08, 1e-3);
  }
}

TEST(BrickGrid, LodCollidesSmallSubtreesAsBoxesAndNeverLosesContact) {
  BrickGrid grid;
  // A floor of microbricks under a large box: LOD must collapse the detail.
  SeededRandom r(10);
  for (int x = 0; x < 60; ++x)
    for (int y = 0; y < 60; ++y) {
      Brick b;
      b.position = Vec3f(x * 0.1f, y * 0.1f, 0.f);
      b.halfSize = Vec3f(0.05f, 0.05f, 0.05f);
      grid.placeBrick(b);
    }
  const QueryShape big = QueryShape::box(Vec3f(4.f, 4.f, 4.f));
  const LocalPose pose{Vec3f(3.f, 3.f, 4.04f), Quatf::Identity()};
  ContactParams off, on;
  off.lodFraction = 0.f;
  on.lodFraction = 1.f / 16;
  std::vector<LocalContact> full, lod;
  ContactStats sFull, sLod;
  grid.collideLocal(big, pose, off, full, &sFull);
  grid.collideLocal(big, pose, on, lod, &sLod);
  EXPECT_GT(sLod.lodBoxes, 0u);
  EXPECT_LT(sLod.bricksTested + sLod.lodBoxes, sFull.bricksTested / 4) << "LOD must do much less narrowphase";
  ASSERT_FALSE(lod.empty());
  float maxFull = 0, maxLod = 0;
  for (auto& c : full) maxFull = std::max(maxFull, c.depth);
  for (auto& c : lod) maxLod = std::max(maxLod, c.depth);
  EXPECT_NEAR(maxLod, maxFull, 0.02f) << "a flat detailed floor collides like a solid floor";
}

TEST(BrickGrid, ConvexApproximationDetectsBoxesButNeverWedges) {
  BrickGrid cube;
  for (int i = 0; i < 27; ++i) {
    Brick b;
    b.position = Vec3f(float(i % 3), float((i / 3) % 3), float(i / 9));
    b.halfSize = Vec3f::Constant(0.5f);
    cube.placeBrick(b);
  }
  for (int depth = 0; depth < 4; ++depth) {
    const ConvexApproximation& a = cube.convexApproximation(depth);
    EXPECT_TRUE(a.isBox) << "depth " << depth;
    EXPECT_NEAR(a.hullVolume, 27.0, 1e-3);
  }
  BrickGrid wedge;
  Brick w;
  w.position = Vec3f::Zero();
  w.halfSize = Vec3f(1, 2, 3);
  w.shape = BrickShape::Wedge;
  wedge.placeBrick(w);
  const ConvexApproximation& aw = wedge.convexApproximation(2);
  EXPECT_FALSE(aw.isBox);
  EXPECT_EQ(aw.vertices.size(), 6u);
  EXPECT_NEAR(aw.hullVolume, 24.0, 1e-3);  // half of the 2x4x6 box
  // An L-shape of boxes is not a box either, and its hull is larger than its volume.
  BrickGrid ell;
  for (int i = 0; i < 3; ++i) {
    Brick b;
    b.halfSize = Vec3f::Constant(0.5f);
    b.position = i < 2 ? Vec3f(float(i), 0, 0) : Vec3f(0, 1, 0);
    ell.placeBrick(b);
  }
  EXPECT_FALSE(ell.convexApproximation(3).isBox);
  EXPECT_NEAR(ell.convexApproximation(3).hullVolume, 3.5, 1e-3);
  // The hull's query shape carries its points' bounds, found once: the largest |coordinate| of
  // its points per axis, as a walk over them finds (the L's hull is not centred on its points).
  for (const ConvexApproximation* a : {&aw, &ell.convexApproximation(3)}) {
    const QueryShape shape = a->shape();
    ASSERT_EQ(shape.kind, QueryShape::Kind::Hull);
    Vec3f walked = Vec3f::Zero();
    for (uint32_t i = 0; i < shape.pointCount; ++i) walked = walked.cwiseMax(shape.points[i].cwiseAbs());
    EXPECT_EQ(shape.localHalfExtents(), walked);
    EXPECT_GT(walked.minCoeff(), 0.f);
  }
  const Vec3f skewed[4] = {{-3, 0, 0}, {1, 0.5f, 0}, {0, -2, 0.25f}, {0, 0, 7}};
  EXPECT_EQ(QueryShape::hull(skewed, 4).localHalfExtents(), Vec3f(3, 2, 7));
  // Cached until an edit.
  const uint32_t extra = ell.placeBrick(Brick::box(Vec3f(1, 1, 0), Vec3f::Constant(0.5f)));
  EXPECT_TRUE(ell.convexApproximation(3).isBox);
  ell.removeBrick(extra);
  EXPECT_FALSE(ell.convexApproximation(3).isBox);
}

TEST(BrickGrid, SmallGridRestsOnLargeGridThroughItsApproximation) {
  BrickGrid floor, crate;
  for (int x = 0; x < 20; ++x)
    for (int y = 0; y < 20; ++y) floor.placeBrick(Brick::box(Vec3f(float(x), float(y), 0.f), Vec3f(0.5f, 0.5f, 0.1f)));
  for (int i = 0; i < 8; ++i) crate.placeBrick(Brick::box(Vec3f(float(i & 1), float((i >> 1) & 1), float(i >> 2)) * 0.5f, Vec3f::Constant(0.25f)));
  ContactScratch scratch;
  std::vector<Contact> contacts;
  int smaller = -1;
  // The crate's bottom (local z = -0.25) sits 0.02 into the floor top (z = 0.1).
  const RigidTransform cratePose{Vec3d(5, 5, 0.1 + 0.25 - 0.02), Quatf::Identity()};
  const size_t n = collideGrids(floor, RigidTransform{}, crate, cratePose, 2, ContactParams{}, scratch, contacts, smaller);
  EXPECT_EQ(smaller, 1);
  ASSERT_GT(n, 0u);
  for (const Contact& c : contacts) {
    EXPECT_NEAR(c.normal.z(), 1.f, 1e-3f);
    EXPECT_NEAR(c.depth, 0.02f, 2e-3f);
  }
  EXPECT_TRUE(crate.convexApproximation(2).isBox);
}

TEST(BrickGrid, EditsBetweenQueriesAreSeenImmediately) {
  BrickGrid grid;
  const uint32_t wall = grid.placeBrick(Brick::box(Vec3f(5, 0, 0), Vec3f(0.5f, 5, 5)));
  const uint32_t back = grid.placeBrick(Brick::box(Vec3f(10, 0, 0), Vec3f(0.5f, 5, 5)));
  const Ray ray = Ray::make(Vec3f::Zero(), Vec3f::UnitX());
  EXPECT_EQ(grid.raycast(ray, ~0u).brick, wall);
  grid.removeBrick(wall);
  EXPECT_EQ(grid.raycast(ray, ~0u).brick, back);
  EXPECT_NEAR(grid.raycast(ray, ~0u).t, 9.5f, 1e-5f);
  std::vector<LocalContact> contacts;
  grid.collideLocal(QueryShape::sphere(1.f), LocalPose{Vec3f(5, 0, 0), Quatf::Identity()}, ContactParams{}, contacts);
  EXPECT_TRUE(contacts.empty()) << "a removed brick must not collide";
}

TEST(BrickGrid, BadBricksAndQueriesAreRejectedWithoutChanges) {
  BrickGrid grid;
  grid.placeBrick(Brick::box(Vec3f(0, 0, 0), Vec3f::Constant(0.5f)));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(grid.placeBrick(Brick::box(Vec3f(nan, 0, 0), Vec3f::Constant(0.5f))), InvalidInput);
  EXPECT_THROW(grid.placeBrick(Brick::box(Vec3f(0, 0, 0), Vec3f(0.5f, -1.f, 0.5f))), InvalidInput);
  EXPECT_THROW(grid.placeBrick(Brick::box(Vec3f(0, 0, 0), Vec3f(0.5f, 0.f, 0.5f))), InvalidInput);
  EXPECT_THROW(grid.placeBrick(Brick::box(Vec3f(2e9f, 0, 0), Vec3f::Constant(0.5f))), InvalidInput);
  Brick cyl = Brick::box(Vec3f(0, 0, 0), Vec3f::Constant(0.5f));
  cyl.shape = BrickShape::Cylinder;
  cyl.sides = 2;
  EXPECT_THROW(grid.placeBrick(cyl), InvalidInput);
  EXPECT_THROW(grid.removeBrick(77), InvalidInput);
  EXPECT_EQ(grid.brickCount(), 1u);
  grid.index().validate();
  ContactScratch scratch;
  std::vector<Contact> out;
  RigidTransform bad;
  bad.translation.x() = std::nan("");
  EXPECT_THROW(grid.collide(RigidTransform{}, QueryShape::sphere(1), bad, ContactParams{}, scratch, out), InvalidInput);
  EXPECT_THROW(grid.collide(RigidTransform{}, QueryShape::sphere(-1), RigidTransform{}, ContactParams{}, scratch, out), InvalidInput);
  // Grid against grid: checked once a pair (the bricks then collide unchecked), on every path:
  // brick by brick (a one-brick grid) and through the hull (a bigger one).
  BrickGrid small, large;
  small.placeBrick(Brick::box(Vec3f(0, 0, 0.9f), Vec3f::Constant(0.5f)));
  for (int i = 0; i < int(kBrickwiseGridBricks) + 1; ++i) large.placeBrick(Brick::box(Vec3f(float(i), 0, 0), Vec3f::Constant(0.5f)));
  ContactParams tooMany;
  tooMany.maxContacts = 65;
  RigidTransform tilted;
  tilted.rotation.coeffs() << 0.5f, 0.f, 0.f, 0.5f;  // not a unit quaternion
  int smaller = -1;
  for (BrickGrid* other : {&small, &large}) {
    EXPECT_THROW(collideGrids(grid, RigidTransform{}, *other, bad, 2, ContactParams{}, scratch, out, smaller), InvalidInput);
    EXPECT_THROW(collideGrids(grid, tilted, *other, RigidTransform{}, 2, ContactParams{}, scratch, out, smaller), InvalidInput);
    EXPECT_THROW(collideGrids(grid, RigidTransform{}, *other, RigidTransform{}, 2, tooMany, scratch, out, smaller), InvalidInput);
    EXPECT_TRUE(out.empty()) << "nothing is reported for refused input";
    EXPECT_GT(collideGrids(grid, RigidTransform{}, *other, RigidTransform{}, 2, ContactParams{}, scratch, out, smaller), 0u);
    out.clear();
  }
  try {
    grid.placeBrick(Brick::box(Vec3f(0, 0, 0), Vec3f(0.5f, nan, 0.5f)));
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("brick.halfSize.y"), std::string::npos) << e.what();
  }
}

// placeBricks (a part split off a grid, a scene's build) against placing the same bricks one
// by one: the same ids, tree, mass properties and answers; refused whole when it cannot place all.
TEST(BrickGrid, PlacingManyAtOnceEqualsPlacingThemOneByOne) {
  for (const Vec3f& offset : {Vec3f(0, 0, 0), Vec3f(3.0e4f, -2.0e4f, 500.f)}) {
    const std::vector<Brick> bricks = randomBuild(17, 3000, offset);
    BrickGrid one, many;
    std::vector<uint32_t> oneIds;
    for (const Brick& b : bricks) oneIds.push_back(one.placeBrick(b));
    const std::vector<uint32_t> manyIds = many.placeBricks(bricks);
    EXPECT_EQ(manyIds, oneIds);
    EXPECT_EQ(many.index().structureHash(), one.index().structureHash());
    const MassProperties a = one.massProperties(), b = many.massProperties();
    EXPECT_EQ(a.mass, b.mass);
    EXPECT_EQ(a.centerOfMass, b.centerOfMass);
    EXPECT_EQ(a.inertia, b.inertia);
    std::vector<uint32_t> hitsA, hitsB;
    const Aabb probe{offset + Vec3f(3, 3, 3), offset + Vec3f(9, 9, 9)};
    one.overlapBricks(probe, ~0u, hitsA);
    many.overlapBricks(probe, ~0u, hitsB);
    std::sort(hitsA.begin(), hitsA.end());
    std::sort(hitsB.begin(), hitsB.end());
    EXPECT_EQ(hitsA, hitsB);
    EXPECT_FALSE(hitsA.empty());
  }
  BrickGrid grid;
  std::vector<Brick> bad = randomBuild(3, 10, Vec3f::Zero());
  bad[7].halfSize.y() = -1.f;
  EXPECT_THROW(grid.placeBricks(bad), InvalidInput);
  EXPECT_EQ(grid.brickCount(), 0u);
  grid.placeBrick(randomBuild(3, 1, Vec3f::Zero())[0]);
  EXPECT_THROW(grid.placeBricks(randomBuild(4, 5, Vec3f::Zero())), InvalidInput) << "not empty";
  BrickGrid small(BrickGrid::Config(4));
  EXPECT_THROW(small.placeBricks(randomBuild(5, 9, Vec3f::Zero())), CapacityExceeded);
  EXPECT_EQ(small.brickCount(), 0u);
}

// moveBricks hands a part of a grid to an empty grid: both indices as one-by-one placing and
// removing leave them, mass properties the direct sums, for a scattered subset and a half-space
// cut, near the origin and far from it; a bad list moves nothing.
TEST(BrickGrid, MovingBricksOutEqualsPlacingAndRemovingThemOneByOne) {
  for (const Vec3f& offset : {Vec3f(0, 0, 0), Vec3f(-6.0e4f, 2.0e4f, 9.0e4f)}) {
    BrickGrid::Config config;
    config.density[2] = 3.f;
    const std::vector<Brick> bricks = randomBuild(23, 3000, offset);
    // Cuts 0 and 1 by moveBricks; 2 and 3 the same cuts in steps, the old grid letting go
    // before the new one is built (an order World may take on two threads); 4 and 5 in steps,
    // the new grid taking the bricks first (so each of the two mass steps comes second once);
    // 6 and 7 begun and gathered in uneven ranges from the back (as the world's jobs may finish),
    // then the steps in World::makeBodyOfPart's order.
    for (int cut = 0; cut < 8; ++cut) {
      const bool inSteps = cut >= 2, newFirst = cut >= 4 && cut < 6, inRanges = cut >= 6;
      BrickGrid grid(config), twin(config);
      std::vector<uint32_t> ids;
      for (const Brick& b : bricks) {
        ids.push_back(grid.placeBrick(b));
        twin.placeBrick(b);
      }
      SeededRandom r(uint64_t(31 + cut % 2));
      std::vector<uint32_t> part;
      for (uint32_t id : ids)
        if (cut % 2 ? grid.brick(id).position.x() < offset.x() + 20.f : r.unit() < 0.4) part.push_back(id);
      for (uint32_t i = uint32_t(part.size()); i > 1; --i) std::swap(part[i - 1], part[r.below(i)]);
      BrickGrid into(config);
      // Bad lists first: nothing may move.
      std::vector<uint32_t> bad = part;
      bad.push_back(part.front());
      EXPECT_THROW(grid.moveBricks(bad, into), InvalidInput);
      bad.back() = 999999;
      EXPECT_THROW(grid.moveBricks(bad, into), InvalidInput);
      EXPECT_THROW(grid.moveBricks(part, grid), InvalidInput);
      EXPECT_EQ(grid.brickCount(), bricks.size());
      EXPECT_EQ(into.brickCount(), 0u);
      std::vector<uint32_t> moved;
      if (inSteps) {
        BrickGrid::Move move = inRanges ? grid.beginMove(part, into) : grid.prepareMove(part, into);
        EXPECT_EQ(grid.brickCount(), bricks.size()) << "preparing changes nothing";
        if (inRanges) {
          ASSERT_EQ(move.size(), part.size());
          size_t end = part.size();
          for (const size_t take : {size_t(1), size_t(7), size_t(100)}) {
            grid.gatherMove(move, end - take, end);
            end -= take;
          }
          grid.gatherMove(move, 0, end);
        }
        // The four steps touch separate state (the world runs them at once): any order.
        if (inRanges) {
          into.receiveMoveIndex(move);
          grid.releaseMoveBricks(move);
          grid.releaseMoveIndex(move);
          into.receiveMoveBricks(move);
        } else if (newFirst) {
          into.receiveMoveIndex(move);
          into.receiveMoveBricks(move);
          grid.releaseMoveIndex(move);
          grid.releaseMoveBricks(move);
        } else {
          grid.releaseMoveBricks(move);
          into.receiveMoveBricks(move);
          grid.releaseMoveIndex(move);
          into.receiveMoveIndex(move);
        }
        moved = move.newIds();
      } else {
        moved = grid.moveBricks(part, into);
      }
      ASSERT_EQ(moved.size(), part.size());
      std::vector<Brick> partBricks;
      for (uint32_t id : part) {
        partBricks.push_back(twin.brick(id));
        twin.removeBrick(id);
      }
      BrickGrid twinPart(config);
      for (const Brick& b : partBricks) twinPart.placeBrick(b);
      for (size_t k = 0; k < part.size(); ++k) ASSERT_EQ(into.brick(moved[k]).position, partBricks[k].position);
      grid.index().validate();
      into.index().validate();
      EXPECT_EQ(grid.index().structureHash(), twin.index().structureHash()) << "cut " << cut;
      EXPECT_EQ(into.index().structureHash(), twinPart.index().structureHash()) << "cut " << cut;
      expectMassMatchesDirectSum(grid, config, offset.cast<double>());
      expectMassMatchesDirectSum(into, config, offset.cast<double>());
      uint32_t stays = 0;
      grid.forEachBrick([&](uint32_t id) { stays = id; });
      EXPECT_THROW(grid.moveBricks(std::vector<uint32_t>{stays}, into), InvalidInput) << "into is not empty";
    }
  }
}

// A prepared move's last step frees its bricks without checking them again: releaseMove (before
// either of its steps) and releaseMoveBricks refuse, changing nothing, when the grid was edited
// after prepareMove (a listed brick may be gone) or when the move was released already.
TEST(BrickGrid, AMoveIsRefusedOnceTheGridChangedUnderIt) {
  const std::vector<Brick> bricks = randomBuild(29, 400, Vec3f::Zero());
  BrickGrid grid;
  std::vector<uint32_t> ids;
  for (const Brick& b : bricks) ids.push_back(grid.placeBrick(b));
  const std::vector<uint32_t> part(ids.begin(), ids.begin() + 150);
  BrickGrid into;
  BrickGrid::Move move = grid.prepareMove(part, into);
  grid.removeBrick(part[17]);  // listed, and now gone
  EXPECT_THROW(grid.releaseMove(move), InvalidInput);
  EXPECT_EQ(grid.index().size(), bricks.size() - 1) << "refused before the index let go of anything";
  EXPECT_THROW(grid.releaseMoveBricks(move), InvalidInput);
  EXPECT_EQ(grid.brickCount(), bricks.size() - 1) << "nothing freed";
  grid.index().validate();
  BrickGrid into2;
  std::vector<uint32_t> rest(part);
  rest.erase(rest.begin() + 17);
  BrickGrid::Move again = grid.prepareMove(rest, into2);
  grid.releaseMoveBricks(again);
  EXPECT_EQ(grid.brickCount(), bricks.size() - 150);
  EXPECT_THROW(grid.releaseMoveBricks(again), InvalidInput) << "released twice";
  EXPECT_EQ(grid.brickCount(), bricks.size() - 150);
}

}  // namespace
}  // namespace bw

namespace bw {
namespace {

TEST(BrickGrid, SweepsMatchBruteForceAndStopAtFirstTouch) {
  BrickGrid grid;
  for (const Brick& b : randomBuild(11, 2500, Vec3f::Zero())) grid.placeBrick(b);
  SeededRandom r(12);
  std::vector<Vec3f> hull;
  int hits = 0;
  for (int q = 0; q < 120; ++q) {
    const QueryShape shape = shapeFor(q, hull);
    const Quatf rot(Eigen::AngleAxisf(float(r.uniform(0, 6.28)), Vec3f(float(r.normal()), float(r.normal()), float(r.normal())).normalized()));
    const Vec3f from(float(r.uniform(-6, 30)), float(r.uniform(-6, 30)), float(r.uniform(-6, 30)));
    Vec3f to = from + Vec3f(float(r.normal()), float(r.normal()), float(r.normal())) * 12.f;
    if (q % 5 == 0) to = from + Vec3f(0, 0, -15.f);  // axis-aligned sweeps
    float best = 2.f;
    grid.forEachBrick([&](uint32_t id) {
      float f;
      Vec3f n, p;
      if (sweepShapeBrick(shape, rot, from, to, grid.brick(id), f, n, p)) best = std::min(best, f);
    });
    const GridSweepHit h = grid.sweep(shape, rot, from, to, ~0u);
    ASSERT_EQ(h.hit(), best <= 1.f) << "sweep " << q;
    if (!h.hit()) continue;
    ++hits;
    ASSERT_EQ(h.fraction, best) << "sweep " << q;
    if (h.fraction > 0.f) {
      ASSERT_LE(h.normal.dot(to - from), 1e-4f) << "an impact normal opposes the motion, sweep " << q;
    }
    std::vector<LocalContact> contacts;
    ContactParams p;
    p.lodFraction = 0.f;
    if (h.fraction == 0.f) {
      // Starting in contact: the start pose touches or penetrates the reported brick.
      ContactParams touching = p;
      touching.speculativeMargin = 1e-3f;
      grid.collideLocal(shape, LocalPose{from, rot}, touching, contacts);
      ASSERT_TRUE(std::any_of(contacts.begin(), contacts.end(), [&](const LocalContact& c) { return c.feature == h.brick && c.depth > -1e-3f; }))
          << "sweep " << q;
      continue;
    }
    // Just before the impact the shape does not penetrate anything.
    grid.collideLocal(shape, LocalPose{from + (to - from) * std::max(0.f, h.fraction - 0.02f), rot}, p, contacts);
    for (const LocalContact& c : contacts) {
      ASSERT_LT(c.depth, 1e-3f) << "sweep " << q << " tunnels into brick " << c.feature;
    }
  }
  EXPECT_GT(hits, 30);
}

}  // namespace
}  // namespace bw

namespace bw {
namespace {

// A rotated query shape must get the same world normal as the unrotated one when its geometry
// is symmetric (sphere, capsule spun about its axis), and normals must point out of the brick.
TEST(BrickNarrowphase, NormalsDoNotDependOnTheShapeRotation) {
  SeededRandom r(13);
  Brick b = Brick::box(Vec3f::Zero(), Vec3f(1.f, 2.f, 0.5f));
  for (int k = 0; k < 500; ++k) {
    b.shape = BrickShape(k % 4);
    b.rotation = AxisRotation::fromIndex(int(r.below(24)));
    const Vec3f pos(float(r.uniform(-2, 2)), float(r.uniform(-3, 3)), float(r.uniform(-2, 2)));
    const Quatf spin(Eigen::AngleAxisf(float(r.uniform(0, 6.28)), Vec3f(float(r.normal()), float(r.normal()), float(r.normal())).normalized()));
    LocalContact a[4], c[4];
    const int na = collideShapeBrick(QueryShape::sphere(0.6f), LocalPose{pos, Quatf::Identity()}, b, 0, 1.f, a);
    const int nc = collideShapeBrick(QueryShape::sphere(0.6f), LocalPose{pos, spin}, b, 0, 1.f, c);
    ASSERT_EQ(na, nc);
    for (int i = 0; i < na; ++i) {
      ASSERT_LT((a[i].normal - c[i].normal).norm(), 2e-3f) << "case " << k;
      ASSERT_NEAR(a[i].depth, c[i].depth, 1e-4f);
      // A sphere centred outside the brick lies on the normal's side of the contact point.
      if (!brickContains(b, pos)) {
        ASSERT_GT((pos - a[i].position).dot(a[i].normal), -1e-3f) << "case " << k;
      }
    }
  }
}

}  // namespace
}  // namespace bw

namespace bw {
namespace {

// The boxes a large static grid enters the world's broadphase as: every brick's bounds lie in
// one of them for every box budget, through edits (removals, bricks placed far outside); there
// are never more than the budget, and a budget of 8 or more splits the grid (it lies 5 km from
// the origin, under a chain of single-child nodes that must not use up the budget).
TEST(BrickGrid, CoverBoxesHoldEveryBrickThroughEdits) {
  BrickGrid grid(BrickGrid::Config(1u << 14));
  std::vector<uint32_t> ids;
  for (const Brick& b : randomBuild(31, 3000, Vec3f(-5000.f, 200.f, 0.f))) ids.push_back(grid.placeBrick(b));
  SeededRandom r(5);
  // Slabs as large as the build: the index holds them near its root, above the cover depth.
  for (int i = 0; i < 3; ++i) ids.push_back(grid.placeBrick(Brick::box(Vec3f(-4970.f + 10.f * float(i), 230.f, 30.f * float(i)), Vec3f(40.f, 35.f, 0.5f))));
  auto check = [&](const char* when) {
    for (uint32_t budget : {1u, 8u, 64u, 512u, 4096u}) {
      std::vector<Aabb> boxes;
      grid.coverBoxes(budget, boxes);
      ASSERT_FALSE(boxes.empty()) << when;
      EXPECT_LE(boxes.size(), budget) << when;
      if (budget >= 8) {
        EXPECT_GT(boxes.size(), 1u) << when << ": budget " << budget;
      }
      grid.forEachBrick([&](uint32_t id) {
        const Aabb b = brickBounds(grid.brick(id));
        EXPECT_TRUE(std::any_of(boxes.begin(), boxes.end(), [&](const Aabb& c) { return c.contains(b); }))
            << when << ": brick " << id << " outside every cover box with a budget of " << budget;
      });
      // Tight: the boxes stay within the grid's bounds.
      for (const Aabb& c : boxes) EXPECT_TRUE(grid.bounds().contains(c)) << when << " budget " << budget;
    }
  };
  check("built");
  for (int i = 0; i < 1000; ++i) {
    const size_t k = r.below(uint32_t(ids.size()));
    grid.removeBrick(ids[k]);
    ids.erase(ids.begin() + std::ptrdiff_t(k));
  }
  for (int i = 0; i < 50; ++i)
    grid.placeBrick(randomBrick(r, Vec3f(float(r.uniform(-9000, 9000)), float(r.uniform(-900, 900)), float(r.uniform(-50, 500))), 3.f));
  check("edited");
  std::vector<Aabb> empty;
  BrickGrid none;
  none.coverBoxes(512, empty);
  EXPECT_TRUE(empty.empty());
}

}  // namespace
}  // namespace bw
