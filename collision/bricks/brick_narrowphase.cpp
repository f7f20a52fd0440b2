#include "collision/bricks/brick_narrowphase.h"

#include <BulletCollision/CollisionDispatch/btBoxBoxDetector.h>
#include <BulletCollision/CollisionShapes/btConvexPointCloudShape.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpa2.h>
#include <algorithm>
#include <btBulletCollisionCommon.h>
#include <string>
#include <vector>

#include "collision/bricks/brick_geometry.h"
#include "collision/core/argument_checks.h"

namespace bw {

namespace {

btVector3 bt(const Vec3f& v) { return {v.x(), v.y(), v.z()}; }
Vec3f fromBt(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

btTransform brickTransform(const Brick& b) {
  btMatrix3x3 m;
  const Mat3f r = b.rotation.matrix();
  m.setValue(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2));
  return btTransform(m, bt(b.position));
}

// A brick's exact shape as a zero-margin Bullet point cloud over its own vertex array (no
// allocation: the cloud does not copy the points).
struct BrickPointCloud {
  btVector3 verts[kMaxBrickVertices];
  btConvexPointCloudShape shape;
  explicit BrickPointCloud(const Brick& b) {
    Vec3f v[kMaxBrickVertices];
    const int n = canonicalBrickVertices(b, v);
    for (int i = 0; i < n; ++i) verts[i] = bt(v[i]);
    shape.setPoints(verts, n, false);
    shape.setMargin(0);
    shape.recalcLocalAabb();
  }
};

btTransform poseTransform(const LocalPose& p) {
  return btTransform(btQuaternion(p.rotation.x(), p.rotation.y(), p.rotation.z(), p.rotation.w()), bt(p.position));
}

struct BoxBoxCollector : btDiscreteCollisionDetectorInterface::Result {
  LocalContact* out;
  int count = 0;
  uint32_t feature, material;
  void setShapeIdentifiersA(int, int) override {}
  void setShapeIdentifiersB(int, int) override {}
  void addContactPoint(const btVector3& normalOnB, const btVector3& pointOnB, btScalar depth) override {
    // Bullet: normal from B (brick) to A (shape), point on B, depth < 0 when penetrating.
    if (count < kMaxContactsPerBrick && depth <= 0)
      out[count++] = {fromBt(pointOnB), fromBt(normalOnB), -float(depth), feature, material};
  }
};

// Collides a Bullet convex shape for the query against a Bullet convex shape for the brick.
// note: btGjkEpaSolver2::Distance works on the cores (margins excluded: a sphere is a point, a
// capsule a segment), so the gap is the core distance minus both margins; when the cores
// overlap, Penetration works on the full shapes. Both report the normal from the brick (shape
// 1) towards the query shape (shape 0), and witnesses[1] on the brick's core.
// note: the witnesses come back in world space but the normal in shape 0's local frame, so it
// is rotated by shape 0's basis here (found by a sweep test with a rotated capsule).
int gjkEpa(const btConvexShape& shape, const btTransform& trShape, const btConvexShape& brick, const btTransform& trBrick,
           uint32_t feature, uint32_t material, float margin, LocalContact* out) {
  btGjkEpaSolver2::sResults res;
  const btVector3 guess = trShape.getOrigin() - trBrick.getOrigin();
  const float margins = float(shape.getMargin() + brick.getMargin());
  if (btGjkEpaSolver2::Distance(&shape, trShape, &brick, trBrick, guess, res)) {
    const float gap = float(res.distance) - margins;
    if (gap >= margin) return 0;
    const Vec3f n = fromBt(trShape.getBasis() * res.normal).normalized();
    if (!n.allFinite()) return 0;
    const Vec3f onBrick = fromBt(res.witnesses[1]) + n * float(brick.getMargin());
    out[0] = {onBrick, n, -gap, feature, material};
    return 1;
  }
  if (!btGjkEpaSolver2::Penetration(&shape, trShape, &brick, trBrick, guess, res)) return 0;
  Vec3f n = fromBt(trShape.getBasis() * res.normal);
  if (!n.allFinite() || n.squaredNorm() < 1e-12f) return 0;
  out[0] = {fromBt(res.witnesses[1]), n.normalized(), -float(res.distance), feature, material};
  return 1;
}

}  // namespace


namespace {
int collideBoxes(const Vec3f& halfA, const btTransform& trA, const Vec3f& halfB, const btTransform& trB, uint32_t feature,
                 uint32_t material, float speculativeMargin, LocalContact* out);

// Runs f(btConvexShape&) with the query shape as a Bullet shape (no allocation).
template <class F>
auto withBulletShape(const QueryShape& shape, F&& f) {
  switch (shape.kind) {
    case QueryShape::Kind::Sphere: {
      btSphereShape s(shape.radius);
      return f(static_cast<btConvexShape&>(s));
    }
    case QueryShape::Kind::Capsule: {
      btCapsuleShapeZ s(shape.radius, 2 * shape.halfHeight);
      return f(static_cast<btConvexShape&>(s));
    }
    case QueryShape::Kind::Hull: {
      thread_local std::vector<btVector3> pts;
      pts.resize(shape.pointCount);
      for (uint32_t i = 0; i < shape.pointCount; ++i) pts[i] = bt(shape.points[i]);
      btConvexPointCloudShape s(pts.data(), int(shape.pointCount), btVector3(1, 1, 1), false);
      s.setMargin(0);
      s.recalcLocalAabb();
      return f(static_cast<btConvexShape&>(s));
    }
    default: {
      btBoxShape s(bt(shape.halfExtents));
      s.setMargin(0);
      return f(static_cast<btConvexShape&>(s));
    }
  }
}

}  // namespace

int collideShapes(const QueryShape& a, const LocalPose& poseA, const QueryShape& b, const LocalPose& poseB,
                  float speculativeMargin, LocalContact* out) {
  if (a.kind == QueryShape::Kind::Box && b.kind == QueryShape::Kind::Box)
    return collideBoxes(a.halfExtents, poseTransform(poseA), b.halfExtents, poseTransform(poseB), 0, 0, speculativeMargin, out);
  return withBulletShape(a, [&](btConvexShape& sa) {
    return withBulletShape(b, [&](btConvexShape& sb) {
      return gjkEpa(sa, poseTransform(poseA), sb, poseTransform(poseB), 0, 0, speculativeMargin, out);
    });
  });
}

bool sweepShapeBrick(const QueryShape& shape, const Quatf& rotation, const Vec3f& from, const Vec3f& to, const Brick& b,
                     float& fraction, Vec3f& normal, Vec3f& point) {
  // A sweep that starts in penetration hits at fraction 0 (like a ray starting inside a brick).
  LocalContact start[kMaxContactsPerBrick];
  const int n0 = collideShapeBrick(shape, LocalPose{from, rotation}, b, 0, 0.f, start);
  for (int i = 0; i < n0; ++i) {
    if (start[i].depth > 1e-4f) {
      fraction = 0.f;
      normal = start[i].normal;
      point = start[i].position;
      return true;
    }
  }
  BrickPointCloud cloud(b);
  const btConvexPointCloudShape& brick = cloud.shape;
  const btTransform trBrick = brickTransform(b);
  const btQuaternion q(rotation.x(), rotation.y(), rotation.z(), rotation.w());
  const Vec3f motion = to - from;
  // Conservative advancement: for a translating convex shape the distance to a convex brick is a
  // convex function of t, so stepping to the zero of its tangent (distance / approach speed)
  // never passes the first contact; a few exact GJK distances converge on it.
  // note: replaces btGjkConvexCast, which was seen to miss a hull sweeping through a cylinder.
  return withBulletShape(shape, [&](btConvexShape& s) {
    const float margins = float(s.getMargin() + brick.getMargin());
    const float tolerance = 1e-4f * (1.f + b.halfSize.maxCoeff());
    float t = 0.f;
    for (int it = 0; it < 64; ++it) {
      const btTransform trShape(q, bt(from + motion * t));
      btGjkEpaSolver2::sResults res;
      if (!btGjkEpaSolver2::Distance(&s, trShape, &brick, trBrick, trShape.getOrigin() - trBrick.getOrigin(), res)) {
        fraction = t;  // cores touch: within the tolerance of the previous step
        normal = -motion.normalized();
        point = from + motion * t;
        return true;
      }
      const float gap = float(res.distance) - margins;
      const Vec3f n = fromBt(trShape.getBasis() * res.normal).normalized();
      if (gap <= tolerance) {
        fraction = t;
        normal = n;
        point = fromBt(res.witnesses[1]) + n * float(brick.getMargin());
        return true;
      }
      const float approach = -n.dot(motion);
      if (!(approach > 0.f)) return false;  // moving away from (or along) the brick
      t += gap / approach;
      if (t > 1.f) return false;
    }
    return false;
  });
}

namespace {

// A speculative (separated) box-box contact from GJK is one closest point, and a tilted box that
// just touches has one or two. A tilted box closing on a thin plate faster than its size per
// step then has one contact: the solver stops that corner and the box turns about it, so its far
// corners swing through the plate within the step. The box's other corners facing the brick
// within the margin get their own contacts (each with its own gap along the first contact's
// normal) while their projection lies on the brick's box, so the whole face is held back.
// Appends to out[0, count); returns the new count (at most kMaxContactsPerBrick).
int addSpeculativeCorners(const Vec3f& halfA, const btTransform& trA, const Vec3f& halfB, const btTransform& trB, float margin,
                          LocalContact* out, int count) {
  const Vec3f n = out[0].normal, onBrick = out[0].position;  // on b's face
  struct Corner {
    float gap;
    Vec3f point;
  };
  Corner corners[8];
  int found = 0;
  for (int i = 0; i < 8; ++i) {
    const Vec3f local((i & 1) ? halfA.x() : -halfA.x(), (i & 2) ? halfA.y() : -halfA.y(), (i & 4) ? halfA.z() : -halfA.z());
    const Vec3f v = fromBt(trA * bt(local));
    const float gap = (v - onBrick).dot(n);
    if (gap >= margin || gap < 0.f) continue;  // out of reach, or penetrating (the detector's)
    const Vec3f onFace = v - n * gap;
    // On b's box (a little slack for rounding)?
    const Vec3f inB = fromBt(trB.invXform(bt(onFace)));
    if ((inB.cwiseAbs().array() > halfB.array() + 1e-3f * (1.f + halfB.maxCoeff())).any()) continue;
    const float slack = 1e-3f * (1.f + halfA.maxCoeff());
    if (std::any_of(out, out + count, [&](const LocalContact& c) { return (c.position - onFace).norm() < slack; })) continue;
    corners[found++] = {gap, onFace};
  }
  std::sort(corners, corners + found, [](const Corner& x, const Corner& y) { return x.gap < y.gap; });
  for (int i = 0; i < found && count < kMaxContactsPerBrick; ++i)
    out[count++] = {corners[i].point, n, -corners[i].gap, out[0].feature, out[0].material};
  return count;
}

// Box a against box b: Bullet's box-box detector gives the full manifold of touching boxes;
// separated boxes get GJK's closest point when a speculative margin is asked for; either way
// the corners of a facing a face of b within the margin are added (addSpeculativeCorners).
int collideBoxes(const Vec3f& halfA, const btTransform& trA, const Vec3f& halfB, const btTransform& trB, uint32_t feature,
                 uint32_t material, float speculativeMargin, LocalContact* out) {
  btBoxShape a(bt(halfA)), b(bt(halfB));
  btBoxBoxDetector det(&a, &b);
  btDiscreteCollisionDetectorInterface::ClosestPointInput in;
  in.m_transformA = trA;
  in.m_transformB = trB;
  BoxBoxCollector col;
  col.out = out;
  col.feature = feature;
  col.material = material;
  det.getClosestPoints(in, col, nullptr);
  if (speculativeMargin <= 0.f) return col.count;
  int n = col.count;
  if (n == 0) {
    // note: the detector reports touching boxes only; GJK measures the gap of separated ones
    // (on the boxes' shapes with zero margins, so the gap is exact).
    a.setMargin(0);
    b.setMargin(0);
    n = gjkEpa(a, trA, b, trB, feature, material, speculativeMargin, out);
    if (n == 0) return 0;
  }
  return n < kMaxContactsPerBrick ? addSpeculativeCorners(halfA, trA, halfB, trB, speculativeMargin, out, n) : n;
}

}  // namespace

int collideShapeBrick(const QueryShape& shape, const LocalPose& pose, const Brick& b, uint32_t feature,
                      float speculativeMargin, LocalContact* out) {
  const btTransform trShape = poseTransform(pose);
  const btTransform trBrick = brickTransform(b);
  if (shape.kind == QueryShape::Kind::Box && b.shape == BrickShape::Box)
    return collideBoxes(shape.halfExtents, trShape, b.halfSize, trBrick, feature, b.material, speculativeMargin, out);
  BrickPointCloud cloud(b);
  return withBulletShape(shape, [&](btConvexShape& s) {
    return gjkEpa(s, trShape, cloud.shape, trBrick, feature, b.material, speculativeMargin, out);
  });
}

int reduceManifold(LocalContact* c, int n, int maxOut) {
  if (n <= maxOut) return n;
  // 1. deepest; 2. farthest from it; 3. largest triangle; 4. largest area added (quad).
  auto swapTo = [&](int dst, int src) { std::swap(c[dst], c[src]); };
  int best = 0;
  for (int i = 1; i < n; ++i)
    if (c[i].depth > c[best].depth) best = i;
  swapTo(0, best);
  int kept = 1;
  while (kept < maxOut) {
    int pick = -1;
    float score = -1.f;
    for (int i = kept; i < n; ++i) {
      float s;
      if (kept == 1) {
        s = (c[i].position - c[0].position).squaredNorm();
      } else if (kept == 2) {
        s = (c[1].position - c[0].position).cross(c[i].position - c[0].position).squaredNorm();
      } else {
        // distance to the triangle's plane area proxy: sum of areas with each kept edge
        s = 0.f;
        for (int a = 0; a < kept; ++a) {
          const int bIdx = (a + 1) % kept;
          s = std::max(s, (c[bIdx].position - c[a].position).cross(c[i].position - c[a].position).squaredNorm());
        }
      }
      if (s > score) {
        score = s;
        pick = i;
      }
    }
    if (pick < 0) break;
    swapTo(kept++, pick);
  }
  return kept;
}

}  // namespace bw
