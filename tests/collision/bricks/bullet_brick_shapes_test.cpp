// buildBulletChunks (collision/bricks/bullet_brick_shapes.h), differential against brute force on
// seeded random grids far from the origin (~1e4), with all four brick shapes, all 24 rotations and
// sizes 0.2 .. 50.
//
// Guarantees these tests establish (each one can fail):
// - Every brick is exactly one compound child (a bijection bricks <-> children), in the chunk
//   whose cube [origin - s/2, origin + s/2) holds its centre; chunk origins lie on the s lattice.
// - A child's world transform (chunk origin * child transform) is the brick's pose: position
//   within 4 ulp of the coordinates, rotation equal to the brick's AxisRotation within 1e-5.
// - A child's shape is the brick's canonical shape: boxes and round cylinders by their half
//   extents (margin inside), wedges, corner wedges and oval cylinders as the hull of exactly the
//   brick's canonical vertices; one shared shape per distinct (shape, half size, sides) key and
//   no two keys sharing one.
// - Two builds give equal chunks (origins, child counts, child transforms) in equal order.
// - contactTest of a box against the chunked world (box bricks only) reports a penetrating point
//   iff brute force over every brick says the box overlaps one. Bullet rounds a box's edges by its
//   margin m (Bullet's own safe margin, <= a tenth of the smallest half size), so its box lies
//   between the box shrunk by m and the box itself: a case counts as overlapping when the boxes
//   shrunk by their margins still overlap by more than kBand, as apart when the query grown by
//   kBand touches nothing; the rest (within the band) are skipped and counted.
// - A chunk size that is zero, negative, NaN or infinite throws InvalidInput.
#include <btBulletCollisionCommon.h>
#include <cmath>
#include <cstdio>
#include <gtest/gtest.h>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "collision/bricks/brick_grid.h"
#include "collision/bricks/brick_narrowphase.h"
#include "collision/bricks/bullet_brick_shapes.h"
#include "collision/core/errors.h"
#include "collision/core/seeded_random.h"

namespace bw {
namespace {

const Vec3f kFar(1.0e4f, -1.0e4f, 1.0e4f);  // every test build sits around here

// Half sizes shared by many bricks (so shapes are shared), the rest drawn per brick.
const Vec3f kPalette[] = {Vec3f(0.1f, 0.1f, 0.1f), Vec3f(0.5f, 0.25f, 0.1f), Vec3f(2.f, 2.f, 0.6f),
                          Vec3f(25.f, 4.f, 2.f), Vec3f(1.f, 1.f, 1.f)};

Brick randomBrick(SeededRandom& r, float spread) {
  Brick b;
  const float x = float(r.uniform(-spread, spread)), y = float(r.uniform(-spread, spread)),
              z = float(r.uniform(-spread, spread));  // one draw per statement order: x, y, z
  b.position = kFar + Vec3f(x, y, z);
  b.shape = BrickShape(r.below(4));
  if (r.below(2)) {
    b.halfSize = kPalette[r.below(5)];
  } else {
    const float hx = float(r.logUniform(0.1, 25)), hy = float(r.logUniform(0.1, 25)), hz = float(r.logUniform(0.1, 25));
    b.halfSize = Vec3f(hx, hy, hz);
  }
  if (b.shape == BrickShape::Cylinder) {
    b.sides = uint8_t(3 + r.below(62));
    if (r.below(2)) b.halfSize.y() = b.halfSize.x();  // round: btCylinderShapeZ
  }
  b.rotation = AxisRotation::fromIndex(int(r.below(24)));
  return b;
}

float ulpOf(float v) {
  const float a = std::abs(v);
  return std::nextafter(a, std::numeric_limits<float>::infinity()) - a;
}

using ShapeKey = std::tuple<int, int, float, float, float>;
ShapeKey keyOf(const Brick& b) {
  return {int(b.shape), b.shape == BrickShape::Cylinder ? int(b.sides) : 0, b.halfSize.x(), b.halfSize.y(), b.halfSize.z()};
}

// The brick's canonical shape as Bullet holds it, checked against the brick's own geometry.
void expectShapeMatches(const btCollisionShape* s, const Brick& b, const char* where) {
  const bool round = b.shape == BrickShape::Cylinder && b.halfSize.x() == b.halfSize.y();
  if (b.shape == BrickShape::Box || round) {
    ASSERT_EQ(s->getShapeType(), b.shape == BrickShape::Box ? BOX_SHAPE_PROXYTYPE : CYLINDER_SHAPE_PROXYTYPE) << where;
    const btVector3 h = b.shape == BrickShape::Box ? static_cast<const btBoxShape*>(s)->getHalfExtentsWithMargin()
                                                   : static_cast<const btCylinderShape*>(s)->getHalfExtentsWithMargin();
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(h[a], b.halfSize[a], 1e-6f * b.halfSize[a]) << where << " axis " << a;
    return;
  }
  ASSERT_EQ(s->getShapeType(), CONVEX_HULL_SHAPE_PROXYTYPE) << where;
  // The hull is the brick's face planes moved in by the margin: hull plus margin never passes
  // a face plane, comes within the margin of every true face (a plane holding 3 or more of the
  // brick's vertices; a face narrow beside the margin is cut off by its neighbours, and along a
  // plane that only touches an acute edge, such as a wedge's top, the rounded edge stays short
  // of it), reaches the full bottom face exactly, and no hull point lies outside the shrunk
  // brick.
  const auto* hull = static_cast<const btConvexHullShape*>(s);
  Brick canonical = b;
  canonical.position = Vec3f::Zero();
  canonical.rotation = AxisRotation::identity();
  const float margin = hull->getMargin();
  EXPECT_GT(margin, 0.f) << where;
  EXPECT_LE(margin, 0.1f * b.halfSize.minCoeff() * (1 + 1e-6f)) << where;
  BrickPlane planes[kMaxBrickPlanes];
  const int n = canonicalBrickPlanes(canonical, planes);
  Vec3f v[kMaxBrickVertices];
  const int vertices = canonicalBrickVertices(canonical, v);
  const float tolerance = 1e-4f * (1.f + b.halfSize.maxCoeff());
  for (int i = 0; i < n; ++i) {
    const btVector3 normal(planes[i].n.x(), planes[i].n.y(), planes[i].n.z());
    const float reach = hull->localGetSupportingVertex(normal).dot(normal);  // margin included
    int onPlane = 0;
    for (int k = 0; k < vertices; ++k) onPlane += std::abs(planes[i].n.dot(v[k]) - planes[i].d) <= tolerance ? 1 : 0;
    EXPECT_LE(reach, planes[i].d + tolerance) << where << ": plane " << i;
    if (onPlane >= 3) {
      EXPECT_GE(reach, planes[i].d - margin - tolerance) << where << ": face " << i;
    }
    if (planes[i].n.z() < -0.999f) {
      EXPECT_NEAR(reach, planes[i].d, tolerance) << where << ": bottom face";
    }
    for (int k = 0; k < hull->getNumPoints(); ++k)
      EXPECT_LE(hull->getUnscaledPoints()[k].dot(normal), planes[i].d - margin + tolerance) << where << ": point " << k << " face " << i;
  }
}

struct ChildRef {
  size_t chunk;
  int child;
  Vec3f world;  // chunk origin + child position
};

TEST(BulletBrickChunks, EveryBrickIsOneChildAtItsPoseWithItsSharedShape) {
  for (const float chunkSize : {4.f, 16.f, 64.f}) {
    SCOPED_TRACE("chunk size " + std::to_string(chunkSize));
    SeededRandom r(77);
    BrickGrid grid(BrickGrid::Config(4096));
    std::vector<Brick> bricks;
    for (int i = 0; i < 900; ++i) {
      bricks.push_back(randomBrick(r, 150.f));
      grid.placeBrick(bricks.back());
    }
    // A few bricks right on chunk boundaries (centres on the lattice).
    for (int i = 0; i < 20; ++i) {
      Brick b = randomBrick(r, 150.f);
      for (int a = 0; a < 3; ++a) b.position[a] = std::round(b.position[a] / chunkSize) * chunkSize;
      bricks.push_back(b);
      grid.placeBrick(b);
    }

    BulletBrickShapes shapes;
    const std::vector<BulletBrickChunk> chunks = buildBulletChunks(grid, chunkSize, shapes);

    // Chunks: on the lattice, non-empty, child count = bricks, an AABB tree.
    std::vector<ChildRef> children;
    uint32_t total = 0;
    for (size_t c = 0; c < chunks.size(); ++c) {
      const BulletBrickChunk& ch = chunks[c];
      ASSERT_TRUE(ch.shape);
      ASSERT_GT(ch.bricks, 0u);
      ASSERT_EQ(ch.shape->getNumChildShapes(), int(ch.bricks));
      ASSERT_NE(ch.shape->getDynamicAabbTree(), nullptr);
      total += ch.bricks;
      for (int a = 0; a < 3; ++a) {
        const double k = double(ch.origin[a]) / chunkSize - 0.5;
        EXPECT_NEAR(k, std::round(k), 1e-3) << "chunk " << c << " origin off the lattice";
      }
      for (int i = 0; i < ch.shape->getNumChildShapes(); ++i) {
        const btVector3& o = ch.shape->getChildTransform(i).getOrigin();
        children.push_back({c, i, ch.origin + Vec3f(o.x(), o.y(), o.z())});
      }
    }
    ASSERT_EQ(total, grid.brickCount());
    ASSERT_EQ(children.size(), bricks.size());

    // Bijection, brute force: each brick takes the one unused child at its pose with its shape.
    const size_t shapesBefore = shapes.distinctShapes();
    std::vector<bool> used(children.size(), false);
    std::map<ShapeKey, const btCollisionShape*> shapeOfKey;
    std::map<const btCollisionShape*, ShapeKey> keyOfShape;
    const Vec3f probe(1.f, 2.f, 3.f);
    for (size_t bi = 0; bi < bricks.size(); ++bi) {
      const Brick& b = bricks[bi];
      const btCollisionShape* expectedShape = shapes.shapeFor(b);  // existing shape: the build made it
      const float tol = 4.f * ulpOf(b.position.cwiseAbs().maxCoeff());
      const Vec3f rotated = b.rotation.apply(probe);
      int match = -1, candidates = 0;
      for (size_t k = 0; k < children.size(); ++k) {
        const ChildRef& cr = children[k];
        if ((cr.world - b.position).cwiseAbs().maxCoeff() > tol) continue;
        const btCompoundShape& compound = *chunks[cr.chunk].shape;
        if (compound.getChildShape(cr.child) != expectedShape) continue;
        const btVector3 p = compound.getChildTransform(cr.child).getBasis() * btVector3(probe.x(), probe.y(), probe.z());
        if ((Vec3f(p.x(), p.y(), p.z()) - rotated).cwiseAbs().maxCoeff() > 1e-5f) continue;
        ++candidates;
        if (!used[k] && match < 0) match = int(k);
      }
      ASSERT_EQ(candidates, 1) << "brick " << bi << " at pose/shape/rotation matches " << candidates << " children";
      ASSERT_GE(match, 0) << "brick " << bi;
      used[size_t(match)] = true;
      // Its chunk's cube holds its centre.
      const Vec3f& origin = chunks[children[size_t(match)].chunk].origin;
      for (int a = 0; a < 3; ++a) {
        EXPECT_GE(b.position[a], origin[a] - 0.5f * chunkSize - tol) << "brick " << bi << " axis " << a;
        EXPECT_LE(b.position[a], origin[a] + 0.5f * chunkSize + tol) << "brick " << bi << " axis " << a;
      }
      expectShapeMatches(expectedShape, b, ("brick " + std::to_string(bi)).c_str());
      // Shared shapes: one per key, no shape for two keys.
      const ShapeKey key = keyOf(b);
      EXPECT_EQ(shapeOfKey.emplace(key, expectedShape).first->second, expectedShape) << "brick " << bi << ": one key, two shapes";
      EXPECT_TRUE(keyOfShape.emplace(expectedShape, key).first->second == key) << "brick " << bi << ": one shape, two keys";
    }
    EXPECT_EQ(shapes.distinctShapes(), shapesBefore) << "shapeFor made a shape the build had not";
    EXPECT_EQ(shapes.distinctShapes(), shapeOfKey.size());
    std::set<ShapeKey> keys;
    for (const Brick& b : bricks) keys.insert(keyOf(b));
    EXPECT_EQ(shapes.distinctShapes(), keys.size());
    EXPECT_LT(keys.size(), bricks.size() * 3 / 4) << "the workload should share shapes";

    // A second build is equal, in the same order.
    BulletBrickShapes shapes2;
    const std::vector<BulletBrickChunk> again = buildBulletChunks(grid, chunkSize, shapes2);
    ASSERT_EQ(again.size(), chunks.size());
    for (size_t c = 0; c < chunks.size(); ++c) {
      ASSERT_EQ(again[c].origin, chunks[c].origin);
      ASSERT_EQ(again[c].bricks, chunks[c].bricks);
      for (int i = 0; i < int(chunks[c].bricks); ++i) {
        const btTransform &x = chunks[c].shape->getChildTransform(i), &y = again[c].shape->getChildTransform(i);
        EXPECT_TRUE(x.getOrigin() == y.getOrigin() && x.getBasis() == y.getBasis()) << "chunk " << c << " child " << i;
      }
    }
  }
}

// Counts the points Bullet reports with a negative distance (penetration).
struct PenetratingPoints : btCollisionWorld::ContactResultCallback {
  int n = 0;
  btScalar addSingleResult(btManifoldPoint& cp, const btCollisionObjectWrapper*, int, int, const btCollisionObjectWrapper*, int,
                           int) override {
    n += cp.getDistance() < 0;
    return 0;
  }
};

TEST(BulletBrickChunks, ContactTestFindsAContactIffBruteForceSaysOverlap) {
  constexpr float kBand = 0.01f;  // float at 1e4 (ulp 1e-3) and GJK/EPA tolerances, with room
  SeededRandom r(91);
  BrickGrid grid(BrickGrid::Config(4096));
  std::vector<Brick> bricks;
  for (int i = 0; i < 400; ++i) {
    Brick b = Brick::box(Vec3f::Zero(), Vec3f::Zero());
    const float x = float(r.uniform(-40, 40)), y = float(r.uniform(-40, 40)), z = float(r.uniform(-10, 10));
    b.position = kFar + Vec3f(x, y, z);
    const float hx = float(r.logUniform(0.1, 4)), hy = float(r.logUniform(0.1, 4)), hz = float(r.logUniform(0.1, 4));
    b.halfSize = Vec3f(hx, hy, hz);
    b.rotation = AxisRotation::fromIndex(int(r.below(24)));
    bricks.push_back(b);
    grid.placeBrick(b);
  }
  BulletBrickShapes shapes;
  std::vector<BulletBrickChunk> chunks = buildBulletChunks(grid, 8.f, shapes);
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  btDbvtBroadphase broadphase;
  std::vector<std::unique_ptr<btCollisionObject>> objects;
  {
    btCollisionWorld world(&dispatcher, &broadphase, &config);
    for (const BulletBrickChunk& c : chunks) {
      auto o = std::make_unique<btCollisionObject>();
      o->setCollisionShape(c.shape.get());
      o->setWorldTransform(btTransform(btQuaternion::getIdentity(), btVector3(c.origin.x(), c.origin.y(), c.origin.z())));
      world.addCollisionObject(o.get());
      objects.push_back(std::move(o));
    }

    int overlapping = 0, apart = 0, skipped = 0;
    for (int q = 0; q < 1200; ++q) {
      const float hx = float(r.logUniform(0.1, 2)), hy = float(r.logUniform(0.1, 2)), hz = float(r.logUniform(0.1, 2));
      const Vec3f half(hx, hy, hz);
      float x = float(r.uniform(-42, 42)), y = float(r.uniform(-42, 42)), z = float(r.uniform(-12, 12));
      if (q % 2) {
        // Half the queries next to a brick's face: around touching, inside and out.
        const Brick& b = bricks[r.below(uint32_t(bricks.size()))];
        const int axis = int(r.below(3));
        const float side = r.below(2) ? 1.f : -1.f;
        const float reach = b.rotation.applyToExtent(b.halfSize)[axis] + float(r.uniform(-0.5, 1.0)) * half.maxCoeff();
        Vec3f local = b.position - kFar;
        local[axis] += side * reach;
        x = local.x(), y = local.y(), z = local.z();
      }
      const Vec3f p = kFar + Vec3f(x, y, z);
      const float qa = float(r.normal()), qb = float(r.normal()), qc = float(r.normal()), qd = float(r.normal());
      const Quatf rot = Quatf(qa, qb, qc, qd).normalized();
      btBoxShape box(btVector3(half.x(), half.y(), half.z()));
      const float mQ = box.getMargin();

      // Brute force over every brick with our narrowphase.
      bool sureOverlap = false, anyTouch = false;
      LocalContact out[kMaxContactsPerBrick];
      const LocalPose pose{p, rot};
      for (const Brick& b : bricks) {
        Brick shrunk = b;
        shrunk.halfSize -= Vec3f::Constant(shapes.shapeFor(b)->getMargin());
        const int n = collideShapeBrick(QueryShape::box(half - Vec3f::Constant(mQ)), pose, shrunk, 0, 0.f, out);
        for (int i = 0; i < n; ++i) sureOverlap |= out[i].depth > kBand;
        const int m = collideShapeBrick(QueryShape::box(half + Vec3f::Constant(kBand)), pose, b, 0, 0.f, out);
        for (int i = 0; i < m; ++i) anyTouch |= out[i].depth > 0;
      }
      if (!sureOverlap && anyTouch) {
        ++skipped;
        continue;
      }
      btCollisionObject query;
      query.setCollisionShape(&box);
      query.setWorldTransform(btTransform(btQuaternion(rot.x(), rot.y(), rot.z(), rot.w()), btVector3(p.x(), p.y(), p.z())));
      PenetratingPoints cb;
      world.contactTest(&query, cb);
      EXPECT_EQ(cb.n > 0, sureOverlap) << "query " << q << " at (" << x << ", " << y << ", " << z << ") half (" << hx << ", "
                                       << hy << ", " << hz << "): Bullet " << cb.n << " penetrating points";
      (sureOverlap ? overlapping : apart) += 1;
    }
    std::printf("[ info ] contactTest vs brute force: %d overlapping, %d apart, %d within the band (skipped)\n", overlapping,
                apart, skipped);
    EXPECT_GE(overlapping, 200);
    EXPECT_GE(apart, 200);
    EXPECT_LE(skipped, 300);
    for (auto& o : objects) world.removeCollisionObject(o.get());
  }
}

TEST(BulletBrickChunks, RejectsChunkSizesThatAreNotPositiveAndFinite) {
  BrickGrid grid(BrickGrid::Config(64));
  grid.placeBrick(Brick::box(kFar, Vec3f::Constant(0.5f)));
  BulletBrickShapes shapes;
  for (const float bad : {0.f, -0.f, -1.f, -1e-30f, std::numeric_limits<float>::quiet_NaN(),
                          std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()}) {
    EXPECT_THROW(buildBulletChunks(grid, bad, shapes), InvalidInput) << "chunk size " << bad;
  }
  EXPECT_EQ(shapes.distinctShapes(), 0u) << "a rejected build made shapes";
  EXPECT_EQ(buildBulletChunks(grid, 8.f, shapes).size(), 1u);
}

}  // namespace
}  // namespace bw
