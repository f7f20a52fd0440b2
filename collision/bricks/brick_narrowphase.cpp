#include "collision/bricks/brick_narrowphase.h"

#include <BulletCollision/CollisionDispatch/btBoxBoxDetector.h>
#include <BulletCollision/CollisionShapes/btConvexPointCloudShape.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpa2.h>
#include <algorithm>
#include <limits>
#include <optional>
#include <btBulletCollisionCommon.h>
#include <string>
#include <vector>

#include "collision/bricks/box_box_gap.h"
#include "collision/bricks/brick_geometry.h"
#include "collision/bricks/core_box_nearest.h"
#include "collision/core/argument_checks.h"

namespace bw {

namespace {

btVector3 bt(const Vec3f& v) { return {v.x(), v.y(), v.z()}; }
Vec3f fromBt(const btVector3& v) { return {v.x(), v.y(), v.z()}; }
Mat3f fromBt(const btMatrix3x3& m) {
  Mat3f r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = m[i][j];
  return r;
}

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

// A brick far larger than the query shape, clipped to the region around the shape: GJK on the
// whole brick works with support points hundreds of metres away and, in float, loses the
// closest features (a box touching a 500 m ramp measured 6 mm away, along a wrong normal, or not
// at all). The part of the brick inside `region` has the same closest features and penetration
// as the whole brick for anything inside the region, and its vertices lie near the shape.
// Vertices are relative to the region's centre, where the transforms are shifted too.
struct ClippedBrickCloud {
  btVector3 verts[kMaxBrickVertices];
  btConvexPointCloudShape shape;
  int count = 0;
  // Returns false when the brick has too many faces (big cylinders: they keep the whole-brick
  // path) or nothing of it lies in the region.
  bool build(const Brick& b, const Aabb& region) {
    BrickPlane canonical[kMaxBrickPlanes];
    if (canonicalBrickPlanes(b, canonical) > 12) return false;
    // note: clipBrickToBox walks edges against faces; the plane-triple search it replaced
    // (816 triples, each a 3x3 inverse) was 61% of a two-way grid pair query.
    Vec3f v[kMaxBrickVertices];
    count = clipBrickToBox(b, region, v, kMaxBrickVertices);
    if (count < 4) return false;
    for (int i = 0; i < count; ++i) verts[i] = bt(v[i]);
    shape.setPoints(verts, count, false);
    shape.setMargin(0);
    shape.recalcLocalAabb();
    return true;
  }
};

// A brick is clipped when it is this many times larger than the query shape (with its margin).
constexpr float kClipBrickRatio = 8.f;

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
  const bool separated = btGjkEpaSolver2::Distance(&shape, trShape, &brick, trBrick, guess, res);
  if (separated) {
    const float gap = float(res.distance) - margins;
    if (gap >= margin) return 0;
    const Vec3f n = fromBt(trShape.getBasis() * res.normal).normalized();
    if (n.allFinite()) {
      const Vec3f onBrick = fromBt(res.witnesses[1]) + n * float(brick.getMargin());
      out[0] = {onBrick, n, -gap, feature, material};
      return 1;
    }
    // note: cores exactly touching (a distance of 0) give GJK no direction, and EPA (which
    // needs overlapping cores) is no use either: the lifted measurement below finds it.
    if (margins > 0.f) return 0;
  }
  if (!separated && btGjkEpaSolver2::Penetration(&shape, trShape, &brick, trBrick, guess, res)) {
    const Vec3f n = fromBt(trShape.getBasis() * res.normal);
    if (n.allFinite() && n.squaredNorm() > 1e-12f) {
      out[0] = {fromBt(res.witnesses[1]), n.normalized(), -float(res.distance), feature, material};
      return 1;
    }
  }
  // Touching (GJK without a direction) or overlapping a thin brick where EPA finds no
  // polytope: measured again with the shape lifted off the brick, the lift taken back out of
  // the gap along the normal found (exact for a face contact). Touching needs only a tiny lift
  // away from the brick's centre; an overlap needs a lift by the shape's own size, tried along
  // that direction and the six axes (box bricks' face normals), the least overlap winning as
  // in a separating-axis test. (Returning nothing here let a box that had just landed on a
  // plate fall through it in the next step.)
  // note: only for shapes without a margin (boxes, hulls): a sphere's or capsule's core
  // touching the brick means the shape overlaps it by its radius, and a lifted measurement
  // there found sideways normals on micro bricks that let a fast sphere through a wall.
  if (margins > 0.f) return 0;
  btVector3 lo, hi, shapeLo, shapeHi;
  brick.getAabb(trBrick, lo, hi);
  shape.getAabb(trShape, shapeLo, shapeHi);
  const btScalar size = (shapeHi - shapeLo).length();
  const btScalar lift = separated ? 1e-3f * (1.f + size) : size + 1e-3f;
  btVector3 candidates[7] = {trShape.getOrigin() - (lo + hi) * 0.5f, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  bool found = false;
  float bestGap = -std::numeric_limits<float>::infinity();
  for (int k = 0; k < (separated ? 1 : 7); ++k) {
    btVector3 away = candidates[k];
    if (away.length2() < 1e-12f) away = btVector3(0, 0, 1);
    away.normalize();
    btTransform lifted = trShape;
    lifted.setOrigin(trShape.getOrigin() + away * lift);
    btGjkEpaSolver2::sResults r;
    if (!btGjkEpaSolver2::Distance(&shape, lifted, &brick, trBrick, guess, r)) continue;
    const Vec3f n = fromBt(lifted.getBasis() * r.normal).normalized();
    if (!n.allFinite()) continue;
    const float gap = float(r.distance) - margins - float(lift) * n.dot(fromBt(away));
    if (found && gap <= bestGap) continue;
    found = true;
    bestGap = gap;
    out[0] = {fromBt(r.witnesses[1]) + n * float(brick.getMargin()), n, -gap, feature, material};
  }
  return found && bestGap < margin ? 1 : 0;
}

}  // namespace


namespace {
bool isCore(QueryShape::Kind k) { return k == QueryShape::Kind::Sphere || k == QueryShape::Kind::Capsule; }

// The nearest points of a sphere's or capsule's core (its centre, or its segment along its local
// z) and a box; nullopt when the core touches or enters the box.
std::optional<CoreBoxNearest> coreNearestBox(const QueryShape& shape, const LocalPose& pose, const Vec3f& half,
                                             const Mat3f& rotation, const Vec3f& centre) {
  const Vec3f axis =
      shape.kind == QueryShape::Kind::Capsule ? Vec3f(pose.rotation * Vec3f(0.f, 0.f, shape.halfHeight)) : Vec3f::Zero();
  return coreBoxNearest(pose.position - axis, pose.position + axis, half, rotation, centre);
}

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
  // A sphere or capsule and a box, the core apart from the box: in closed form, either order.
  const bool coreA = isCore(a.kind) && b.kind == QueryShape::Kind::Box, coreB = a.kind == QueryShape::Kind::Box && isCore(b.kind);
  if (coreA || coreB) {
    const QueryShape& core = coreA ? a : b;
    const LocalPose& corePose = coreA ? poseA : poseB;
    const LocalPose& boxPose = coreA ? poseB : poseA;
    if (const std::optional<CoreBoxNearest> near = coreNearestBox(core, corePose, (coreA ? b : a).halfExtents,
                                                                  boxPose.rotation.toRotationMatrix(), boxPose.position)) {
      const float gap = near->distance - core.radius;
      if (gap >= speculativeMargin) return 0;
      // The point on b: the box's nearest point, or the core shape's surface nearest the box.
      out[0] = coreA ? LocalContact{near->onBox, near->normal, -gap, 0, 0}
                     : LocalContact{near->onCore - near->normal * core.radius, -near->normal, -gap, 0, 0};
      return 1;
    }
  }
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

// Sorts one pair's few corners (at most 8) by insertion, which leaves equal keys where std::sort
// did (libstdc++ sorts up to 16 elements by insertion: the state hashes are unchanged);
// std::sort on these arrays trips GCC 12's -Warray-bounds at -O3, a false positive.
template <class T, class Less>
void sortSmall(T* items, int count, Less less) {
  for (int i = 1; i < count; ++i)
    for (int j = i; j > 0 && less(items[j], items[j - 1]); --j) std::swap(items[j], items[j - 1]);
}

// A speculative (separated) box-box contact is one nearest pair of points, and a tilted box that
// just touches has one or two. A tilted box closing on a thin plate faster than its size per
// step then has one contact: the solver stops that corner and the box turns about it, so its far
// corners swing through the plate within the step. So the other corners facing a face across the
// gap within the margin get their own contacts, each with its own gap along the first contact's
// normal: a's corners over b's face, and b's corners under a's face (a small brick under a large
// box, or a row of small bricks flying at a wall: with one contact each, at the same corner of
// every brick, the row turned about that line into the wall). Nearest first. Appends to
// out[0, count); returns the new count (at most kMaxContactsPerBrick).
int addSpeculativeCorners(const Vec3f& halfA, const btTransform& trA, const Vec3f& halfB, const btTransform& trB, float margin,
                          LocalContact* out, int count) {
  const Vec3f n = out[0].normal, onB = out[0].position;  // from b to a; on b
  const Vec3f onA = onB - n * out[0].depth;               // on a (depth = -gap)
  struct Corner {
    float gap;
    Vec3f point;  // on b
  };
  Corner corners[16];
  int found = 0;
  const float slack = 1e-3f * (1.f + std::min(halfA.maxCoeff(), halfB.maxCoeff()));  // one spot
  // The corners of one box facing the other's face across the gap: only when the normal is a
  // face normal of the other (within 1 degree), as that face is then the plane the corners face,
  // through the other's nearest point; each corner's gap is measured along the normal to it, and
  // its projection must lie on the face. (Across an edge or a corner, the plane across the normal
  // is not the other's surface: a corner given a gap to it could go into it.) `toFace` is the
  // direction from the corners towards the face.
  auto facing = [&](const Vec3f& half, const btTransform& tr, const Vec3f& faceHalf, const btTransform& faceTr,
                    const Vec3f& onFace, const Vec3f& toFace, bool cornersOnB) {
    const btMatrix3x3& basis = faceTr.getBasis();
    int axis = 0;
    float alignment = 0.f;
    for (int k = 0; k < 3; ++k) {
      const float d = std::abs(toFace.dot(fromBt(basis.getColumn(k))));
      if (d > alignment) alignment = d, axis = k;
    }
    if (!(alignment > 0.99985f)) return;
    const Vec3f m = fromBt(basis.getColumn(axis)) * (toFace.dot(fromBt(basis.getColumn(axis))) > 0.f ? 1.f : -1.f);
    for (int i = 0; i < 8; ++i) {
      const Vec3f local((i & 1) ? half.x() : -half.x(), (i & 2) ? half.y() : -half.y(), (i & 4) ? half.z() : -half.z());
      const Vec3f v = fromBt(tr * bt(local));
      const float gap = (onFace - v).dot(m) / toFace.dot(m);
      if (gap >= margin || gap < 0.f) continue;  // out of reach, or penetrating (the detector's)
      const Vec3f projected = v + toFace * gap;
      const Vec3f inFace = fromBt(faceTr.invXform(bt(projected)));
      if ((inFace.cwiseAbs().array() > faceHalf.array() + 1e-3f * (1.f + faceHalf.maxCoeff())).any()) continue;
      const Vec3f point = cornersOnB ? v : projected;
      if (std::any_of(out, out + count, [&](const LocalContact& c) { return (c.position - point).norm() < slack; })) continue;
      corners[found++] = {gap, point};
    }
  };
  facing(halfA, trA, halfB, trB, onB, -n, false);  // a's corners onto b's face
  facing(halfB, trB, halfA, trA, onA, n, true);    // b's corners onto a's face
  sortSmall(corners, found, [](const Corner& x, const Corner& y) { return x.gap < y.gap; });  // nearest first
  for (int i = 0; i < found && count < kMaxContactsPerBrick; ++i) {
    // Two corners at one spot (a's corner on b's corner) count once.
    if (std::any_of(out, out + count, [&](const LocalContact& c) { return (c.position - corners[i].point).norm() < slack; })) continue;
    out[count++] = {corners[i].point, n, -corners[i].gap, out[0].feature, out[0].material};
  }
  return count;
}

// Box a against box b: Bullet's box-box detector gives the full manifold of touching boxes;
// separated boxes get GJK's closest point when a speculative margin is asked for; either way
// the corners of a facing a face of b within the margin are added (addSpeculativeCorners).
int collideBoxes(const Vec3f& halfA, const btTransform& trA, const Vec3f& halfB, const btTransform& trB, uint32_t feature,
                 uint32_t material, float speculativeMargin, LocalContact* out) {
  std::optional<BoxPair> pair;
  if (speculativeMargin > 0.f) {
    // Beyond the margin along a face axis, by more than float rounding of the detector's own
    // tests: no contact of any kind, and Bullet's detector (which would find them apart) and the
    // gap measure are not asked. Most box pairs a broadphase hands over are that far apart.
    // (A float test first, for the many far apart; then the exact one in double.)
    const Mat3f rotationA = fromBt(trA.getBasis()), rotationB = fromBt(trB.getBasis());
    const Vec3f centreA = fromBt(trA.getOrigin()), centreB = fromBt(trB.getOrigin());
    if (boxesFartherApartThan(halfA, rotationA, centreA, halfB, rotationB, centreB, speculativeMargin)) return 0;
    pair = boxPair(halfA, rotationA, centreA, halfB, rotationB, centreB);
    if (pair->faceSeparation >= double(speculativeMargin) + 1e-5 * pair->scale) return 0;
  }
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
    // note: the detector reports touching boxes only. A separated pair's gap and nearest points
    // come in closed form (collision/bricks/box_box_gap.h); GJK measures what that declines
    // (touching to double rounding, or a near tie of two axes), on zero-margin shapes.
    if (const std::optional<BoxGap> g = separatedBoxGap(*pair)) {
      if (g->gap >= speculativeMargin) return 0;
      out[0] = {g->onB, g->normal, -g->gap, feature, material};
      n = 1;
    } else {
      a.setMargin(0);
      b.setMargin(0);
      n = gjkEpa(a, trA, b, trB, feature, material, speculativeMargin, out);
      if (n == 0) return 0;
    }
  }
  return n < kMaxContactsPerBrick ? addSpeculativeCorners(halfA, trA, halfB, trB, speculativeMargin, out, n) : n;
}

// GJK gives one point per pair. A capsule resting on its side needs both ends, and one that
// falls tilted needs its far end held back as it swings down: each end of the core, as a
// sphere of the capsule's radius, adds its own contact (with its own normal and gap) when it
// is within the margin and not where a contact already is.
int addCapsuleEnds(const QueryShape& capsule, const btTransform& trCapsule, const btConvexShape& brick, const btTransform& trBrick,
                   float margin, LocalContact* out, int count) {
  const btVector3 axis = trCapsule.getBasis().getColumn(2) * capsule.halfHeight;
  btSphereShape end(capsule.radius);
  const float slack = 1e-3f * (1.f + capsule.radius + capsule.halfHeight);
  for (float sign : {-1.f, 1.f}) {
    if (count >= kMaxContactsPerBrick) break;
    btTransform trEnd(btMatrix3x3::getIdentity(), trCapsule.getOrigin() + axis * sign);
    LocalContact c;
    if (gjkEpa(end, trEnd, brick, trBrick, out[0].feature, out[0].material, margin, &c) == 0) continue;
    if (std::any_of(out, out + count, [&](const LocalContact& o) { return (o.position - c.position).norm() < slack; })) continue;
    c.shapePart = sign < 0.f ? 1 : 2;
    out[count++] = c;
  }
  return count;
}

// The same for a box against a brick that is not a box (wedge, corner, cylinder), where Bullet's
// box-box manifold does not apply. GJK/EPA gives the deepest point and its normal; the box's
// corners are measured against that contact's plane, and those within the margin and no deeper
// than it, whose projection onto the plane lies on the brick, get contacts of their own, lowest
// first. So a box landing flat on a ramp is held at its corners, penetrating or not, and the
// corners on the far side of the box (hidden behind the near ones) are never used.
int addBoxCorners(const Vec3f& half, const btTransform& trBox, const Brick& brick, float margin, LocalContact* out, int count) {
  const Vec3f n = out[0].normal, onBrick = out[0].position;
  const float deepest = out[0].depth;
  const float tolerance = 1e-3f * (1.f + half.maxCoeff());
  // note: GJK's witness on a brick hundreds of metres long is off by ~1e-5 of its size, so a
  // corner may measure slightly deeper than the "deepest" point.
  const float depthSlack = tolerance + 2e-5f * brick.halfSize.maxCoeff();
  LocalContact corners[8];
  int found = 0;
  for (int i = 0; i < 8; ++i) {
    const Vec3f local((i & 1) ? half.x() : -half.x(), (i & 2) ? half.y() : -half.y(), (i & 4) ? half.z() : -half.z());
    const Vec3f v = fromBt(trBox * bt(local));
    const float gap = (v - onBrick).dot(n);
    if (gap >= margin || gap < -(deepest + depthSlack)) continue;
    const Vec3f onFace = v - n * gap;
    if (!brickContains(brick, onFace, tolerance)) continue;
    if (std::any_of(out, out + count, [&](const LocalContact& o) { return (o.position - onFace).norm() < tolerance; })) continue;
    corners[found++] = {onFace, n, -gap, out[0].feature, out[0].material, uint8_t(1 + i)};
  }
  sortSmall(corners, found, [](const LocalContact& x, const LocalContact& y) { return x.depth > y.depth; });
  for (int i = 0; i < found && count < kMaxContactsPerBrick; ++i) out[count++] = corners[i];
  return count;
}

}  // namespace

namespace {
// A sphere's or capsule's core apart from a box brick: its contact in closed form
// (collision/bricks/core_box_nearest.h), and a capsule's ends as spheres of its radius, as
// addCapsuleEnds does by GJK. -1 when the core touches or enters the brick: GJK/EPA measures
// that penetration.
int coreContacts(const QueryShape& shape, const LocalPose& pose, const Brick& b, uint32_t feature, float margin,
                 LocalContact* out) {
  const bool capsule = shape.kind == QueryShape::Kind::Capsule;
  const Vec3f axis = capsule ? Vec3f(pose.rotation * Vec3f(0.f, 0.f, shape.halfHeight)) : Vec3f::Zero();
  const Mat3f rotation = b.rotation.matrix();
  auto contact = [&](const CoreBoxNearest& near, LocalContact& c) {
    const float gap = near.distance - shape.radius;
    if (gap >= margin) return false;
    c = {near.onBox, near.normal, -gap, feature, b.material};
    return true;
  };
  const std::optional<CoreBoxNearest> core = coreNearestBox(shape, pose, b.halfSize, rotation, b.position);
  if (!core) return -1;
  if (!contact(*core, out[0])) return 0;
  int count = 1;
  if (!capsule) return count;
  const float slack = 1e-3f * (1.f + shape.radius + shape.halfHeight);
  for (float sign : {-1.f, 1.f}) {
    if (count >= kMaxContactsPerBrick) break;
    const Vec3f end = pose.position + axis * sign;
    const std::optional<CoreBoxNearest> near = coreBoxNearest(end, end, b.halfSize, rotation, b.position);
    LocalContact c;
    if (!near || !contact(*near, c)) continue;
    if (std::any_of(out, out + count, [&](const LocalContact& o) { return (o.position - c.position).norm() < slack; })) continue;
    c.shapePart = sign < 0.f ? 1 : 2;
    out[count++] = c;
  }
  return count;
}

// A lower bound on the gap between the shape and the brick (0 when they may touch): the larger
// of the distance between their grid-frame bounds and their separation along the shape's own
// axes (the shape lies in its oriented box, the brick in its bounds). Cheap beside GJK, and
// most candidates of a query box grown by a speculative margin are farther than the margin.
float gapLowerBound(const QueryShape& shape, const LocalPose& pose, const Brick& b) {
  const Aabb brick = brickBounds(b);
  const Vec3f bc = brick.center(), bh = brick.halfExtent();
  const Mat3f R = pose.rotation.toRotationMatrix();
  const Vec3f h = shape.localHalfExtents();
  const Vec3f d = pose.position - bc;
  const Vec3f apart = (d.cwiseAbs() - R.cwiseAbs() * h - bh).cwiseMax(0.f);
  float bound = apart.norm();
  for (int j = 0; j < 3; ++j) {
    const Vec3f u = R.col(j);
    bound = std::max(bound, std::abs(u.dot(d)) - h[j] - u.cwiseAbs().dot(bh));
  }
  return bound;
}
}  // namespace

int collideShapeBrick(const QueryShape& shape, const LocalPose& pose, const Brick& b, uint32_t feature,
                      float speculativeMargin, LocalContact* out) {
  // Farther than the margin by more than GJK's tolerance: no contact (what GJK would find).
  const float slack = 1e-3f * (1.f + shape.localHalfExtents().maxCoeff() + b.halfSize.maxCoeff());
  if (gapLowerBound(shape, pose, b) > std::max(speculativeMargin, 0.f) + slack) return 0;
  const btTransform trShape = poseTransform(pose);
  const btTransform trBrick = brickTransform(b);
  const float reach = shape.localHalfExtents().norm() + std::max(speculativeMargin, 0.f);
  const bool huge = b.halfSize.maxCoeff() > kClipBrickRatio * reach;
  if (huge && b.shape == BrickShape::Box) {
    // A huge box brick is axis-aligned in the grid frame (rotations are signed permutations):
    // its part around the shape is the overlap of two boxes, itself a box near the shape.
    const Aabb whole = brickBounds(b), region = Aabb::fromCenterHalf(pose.position, Vec3f::Constant(2.f * reach));
    const Aabb part{whole.min.cwiseMax(region.min), whole.max.cwiseMin(region.max)};
    if (part.isEmpty()) return 0;
    Brick near = b;
    near.position = part.center();
    near.halfSize = part.halfExtent().cwiseMax(Vec3f::Constant(kMinBrickHalfSize));
    near.rotation = AxisRotation::identity();
    return collideShapeBrick(shape, pose, near, feature, speculativeMargin, out);
  }
  if (!huge && b.shape == BrickShape::Box && isCore(shape.kind)) {
    const int n = coreContacts(shape, pose, b, feature, speculativeMargin, out);
    if (n >= 0) return n;
  }
  if (!huge && shape.kind == QueryShape::Kind::Box && b.shape == BrickShape::Box)
    return collideBoxes(shape.halfExtents, trShape, b.halfSize, trBrick, feature, b.material, speculativeMargin, out);
  // The brick as a Bullet shape: whole, or (huge) its part around the shape in coordinates
  // centred there, with the shape's transform shifted to match.
  ClippedBrickCloud clipped;
  const Aabb region = Aabb::fromCenterHalf(pose.position, Vec3f::Constant(2.f * reach));
  const bool clip = huge && clipped.build(b, region);
  std::optional<BrickPointCloud> whole;
  if (!clip) whole.emplace(b);
  const btConvexShape& brickShape = clip ? static_cast<const btConvexShape&>(clipped.shape) : whole->shape;
  const btVector3 offset = clip ? bt(region.center()) : btVector3(0, 0, 0);
  const btTransform trS(trShape.getBasis(), trShape.getOrigin() - offset);
  const btTransform trB = clip ? btTransform::getIdentity() : trBrick;
  int n = withBulletShape(shape, [&](btConvexShape& s) {
    return gjkEpa(s, trS, brickShape, trB, feature, b.material, speculativeMargin, out);
  });
  if (n == 0) return 0;
  if (shape.kind == QueryShape::Kind::Capsule) n = addCapsuleEnds(shape, trS, brickShape, trB, speculativeMargin, out, n);
  for (int i = 0; i < n; ++i) out[i].position += fromBt(offset);
  if (shape.kind == QueryShape::Kind::Box) return addBoxCorners(shape.halfExtents, trShape, b, speculativeMargin, out, n);
  return n;
}

int keepDeepestPerShapePart(LocalContact* c, int n) {
  float deepest[256];
  bool seen[256] = {};
  for (int i = 0; i < n; ++i) {
    const uint8_t p = c[i].shapePart;
    if (p == 0) continue;
    if (!seen[p] || c[i].depth > deepest[p]) deepest[p] = c[i].depth;
    seen[p] = true;
  }
  int w = 0;
  for (int i = 0; i < n; ++i) {
    const uint8_t p = c[i].shapePart;
    if (p != 0) {
      if (c[i].depth != deepest[p]) continue;
      deepest[p] = std::numeric_limits<float>::infinity();  // the first of equal depths only
    }
    c[w++] = c[i];
  }
  return w;
}

namespace {

// Reduces c[0, n) to at most maxOut points in place: the deepest, the farthest from it, the one
// making the largest triangle, then the one adding the largest area. Returns the count.
int reduceByArea(LocalContact* c, int n, int maxOut) {
  if (n <= maxOut) return n;
  int best = 0;
  for (int i = 1; i < n; ++i)
    if (c[i].depth > c[best].depth) best = i;
  std::swap(c[0], c[best]);
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
    std::swap(c[kept++], c[pick]);
  }
  return kept;
}

}  // namespace

int reduceManifold(LocalContact* c, int n, int maxOut) {
  if (n <= maxOut) return n;
  // Contacts are grouped by normal direction (the floor, a wall, a neighbouring brick's edge)
  // in order of each group's deepest contact, and each group is reduced on its own (deepest,
  // farthest, largest triangle, largest area). Reduced together, a shape over many bricks lost
  // the contacts that mattered: a box falling beside a wall kept only wall contacts, and a
  // capsule landing across bricks kept far-away contacts on neighbouring brick edges instead of
  // the one under its other end. At most kManifoldNormalGroups groups: a contact of yet another
  // direction joins the group of the nearest one.
  constexpr float kSameDirection = 0.9f;  // cos of ~25 degrees
  thread_local std::vector<LocalContact> sorted;
  thread_local std::vector<int8_t> group;
  sorted.assign(c, c + n);
  group.assign(size_t(n), -1);
  // Groups in order of their deepest contact: visit contacts deepest first (ties by index).
  thread_local std::vector<int> order;
  order.resize(size_t(n));
  for (int i = 0; i < n; ++i) order[size_t(i)] = i;
  std::stable_sort(order.begin(), order.end(), [&](int x, int y) { return sorted[size_t(x)].depth > sorted[size_t(y)].depth; });
  Vec3f groupNormal[kManifoldNormalGroups];
  int groups = 0;
  for (int i : order) {
    for (int g = 0; g < groups && group[size_t(i)] < 0; ++g)
      if (groupNormal[g].dot(sorted[size_t(i)].normal) > kSameDirection) group[size_t(i)] = int8_t(g);
    if (group[size_t(i)] < 0 && groups < kManifoldNormalGroups) {
      groupNormal[groups] = sorted[size_t(i)].normal;
      group[size_t(i)] = int8_t(groups++);
    }
    if (group[size_t(i)] < 0) {  // more directions than groups: the nearest direction's group
      int nearest = 0;
      for (int g = 1; g < groups; ++g)
        if (groupNormal[g].dot(sorted[size_t(i)].normal) > groupNormal[nearest].dot(sorted[size_t(i)].normal)) nearest = g;
      group[size_t(i)] = int8_t(nearest);
    }
  }
  int out = 0;
  for (int g = 0; g < groups; ++g) {
    const int first = out;
    for (int i = 0; i < n; ++i)
      if (group[size_t(i)] == g) c[out++] = sorted[size_t(i)];
    out = first + reduceByArea(c + first, out - first, maxOut);
  }
  return out;
}

void reduceManifold(std::vector<Contact>& out, size_t begin, int maxOut) {
  const size_t n = out.size() - begin;
  if (n <= size_t(maxOut)) return;
  thread_local std::vector<LocalContact> local;
  local.resize(n);
  const Vec3d origin = out[begin].position;
  for (size_t i = 0; i < n; ++i) {
    const Contact& c = out[begin + i];
    local[i] = {(c.position - origin).cast<float>(), c.normal, c.depth, c.featureB, c.material, 0};
  }
  const int kept = reduceManifold(local.data(), int(n), maxOut);
  for (int i = 0; i < kept; ++i)
    out[begin + size_t(i)] = {origin + local[size_t(i)].position.cast<double>(), local[size_t(i)].normal, local[size_t(i)].depth,
                              local[size_t(i)].feature, local[size_t(i)].material};
  out.resize(begin + size_t(kept));
}

}  // namespace bw
