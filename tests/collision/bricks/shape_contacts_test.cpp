// collideShapes (collision/bricks/brick_narrowphase.h) directly, against closed-form answers for
// seeded random poses and sizes 0.2 .. 500: sphere-sphere, sphere-box (face, edge and corner
// regions, both argument orders), box-box (a box pressed into or hovering over a larger box's
// face: four corner contacts) and capsule-box (a capsule standing on a face, and one lying on
// it). Convention checked everywhere: the normal points from b towards a, the point lies on b,
// depth > 0 is penetration and depth < 0 a speculative gap below the margin; beyond the margin
// there is no contact.
//
// Tolerances: Bullet's box-box detector (touching boxes) and GJK/EPA (sphere-sphere, capsules
// whose core enters the box) run in float; the gaps of separated boxes and of sphere and capsule
// cores outside a box are in closed form. Depth and points are asserted to within kRel of the
// pair's size (measured worst cases are printed), normals to 1e-3.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <gtest/gtest.h>
#include <string>

#include "collision/bricks/brick_narrowphase.h"
#include "collision/core/seeded_random.h"
#include "collision/support/sequenced_draws.h"

namespace bw {
namespace {

constexpr float kRel = 2e-4f;        // depth and point error / size of the pair
constexpr float kNormalTol = 1e-3f;  // |normal - expected|
// Sphere against box, the centre outside the box, is in closed form (collision/bricks/
// core_box_nearest.h): depth to 1e-5 of the size, point to 1e-4, normal to 1e-2 (measured worst
// over the seeded cases: 3.5e-6, 1.3e-5, 2.2e-3; the test's own float reference point and normal
// carry most of that). Through Bullet's float GJK/EPA they were 3.7e-5, 4.9e-3 and 0.48 (a normal
// off by that on 4 of 3000 pairs, printed then and allowed).
constexpr float kSphereBoxNormalTol = 1e-2f;
constexpr float kSphereBoxPointRel = 1e-4f;
constexpr float kSphereBoxDepthRel = 1e-5f;

// Draws in a fixed order (collision/support/sequenced_draws.h).
Quatf randomRotation(SeededRandom& r) { return test::drawQuat([&] { return r.normal(); }).normalized(); }
Vec3f randomUnit(SeededRandom& r) { return test::drawVec3([&](int) { return r.normal(); }).normalized(); }
Vec3f randomPosition(SeededRandom& r, float scale) { return test::drawVec3([&](int) { return r.uniform(-1, 1); }) * scale; }

struct Worst {
  const char* name;
  float depth = 0, point = 0, normal = 0;
  void add(float d, float p, float n) {
    depth = std::max(depth, d), point = std::max(point, p), normal = std::max(normal, n);
  }
  ~Worst() { std::printf("[ %-10s] worst relative depth error %.2e, point %.2e, normal %.2e\n", name, depth, point, normal); }
};

TEST(ShapeContacts, SphereSphereMatchesClosedForm) {
  SeededRandom r(2101);
  Worst worst{"sphere-sph"};
  for (int k = 0; k < 1000; ++k) {
    const float ra = float(r.logUniform(0.2, 500)), rb = float(r.logUniform(0.2, 500));
    const float size = std::max(ra, rb);
    const Vec3f pb = randomPosition(r, 2 * size), n = randomUnit(r);
    // From deep overlap (up to 90% of the smaller radius) to a gap of 5% of the smaller radius.
    const float depth = float(r.uniform(-0.05, 0.9)) * std::min(ra, rb);
    const Vec3f pa = pb + n * (ra + rb - depth);
    const float margin = 0.1f * std::min(ra, rb);
    LocalContact c[kMaxContactsPerBrick];
    // b's rotation first: GCC's order when both were call arguments (collision/support/sequenced_draws.h)
    const Quatf rotationB = randomRotation(r), rotationA = randomRotation(r);
    const int m = collideShapes(QueryShape::sphere(ra), {pa, rotationA}, QueryShape::sphere(rb), {pb, rotationB}, margin, c);
    ASSERT_EQ(m, 1) << "case " << k << " depth " << depth;
    const Vec3f expectedPoint = pb + n * rb;
    const float dErr = std::abs(c[0].depth - depth) / size, pErr = (c[0].position - expectedPoint).norm() / size,
                nErr = (c[0].normal - n).norm();
    worst.add(dErr, pErr, nErr);
    EXPECT_LT(dErr, kRel) << "case " << k << ": depth " << c[0].depth << " expected " << depth;
    EXPECT_LT(pErr, kRel) << "case " << k;
    EXPECT_LT(nErr, kNormalTol) << "case " << k;
    // Beyond the margin: nothing.
    const Vec3f farA = pb + n * (ra + rb + 1.5f * margin);
    EXPECT_EQ(collideShapes(QueryShape::sphere(ra), {farA, Quatf::Identity()}, QueryShape::sphere(rb), {pb, Quatf::Identity()},
                            margin, c),
              0)
        << "case " << k;
  }
}

// The closest point of a box (half extents h, at pose) to p, and whether p is outside it.
Vec3f closestOnBox(const Vec3f& h, const LocalPose& pose, const Vec3f& p) {
  const Vec3f local = pose.rotation.conjugate() * (p - pose.position);
  return pose.position + pose.rotation * local.cwiseMax(-h).cwiseMin(h);
}

TEST(ShapeContacts, SphereBoxMatchesClosedFormInFaceEdgeAndCornerRegions) {
  SeededRandom r(2201);
  Worst worst{"sphere-box"}, worstGap{"sph-box gap"};
  int regions[4] = {0, 0, 0, 0};  // by how many axes the centre is clamped on: face, edge, corner
  for (int k = 0; k < 1500; ++k) {
    const Vec3f h = test::drawVec3([&](int) { return r.logUniform(0.2, 500); });
    const LocalPose box{randomPosition(r, 100), randomRotation(r)};
    // A centre outside the box: pick a region (1..3 clamped axes), then offsets.
    const int clamped = 1 + int(r.below(3));
    Vec3f local;
    const uint32_t first = r.below(3);
    for (int a = 0; a < 3; ++a) {
      const bool out = (int((uint32_t(a) + 3 - first) % 3) < clamped);
      if (out) {
        const float sign = r.below(2) ? 1.f : -1.f;
        local[a] = sign * h[a] * float(1 + r.uniform(0.05, 0.5));
      } else {
        local[a] = h[a] * float(r.uniform(-0.9, 0.9));
      }
    }
    const Vec3f centre = box.position + box.rotation * local;
    const Vec3f q = closestOnBox(h, box, centre);
    const float dist = (centre - q).norm();
    ASSERT_GT(dist, 0.f);
    ++regions[clamped];
    // Radius: penetrating by 5..60% of the radius, or a gap of 2..10% of the distance (a gap far
    // below the shapes' size left GJK's float normal ill-conditioned: seen 0.48 off at 1e-3).
    const bool gap = r.below(5) == 0;
    const float radius = gap ? dist * float(r.uniform(0.9, 0.98)) : dist / float(1 - r.uniform(0.05, 0.6));
    const float depth = radius - dist;
    const Vec3f n = (centre - q) / dist;  // from the box towards the sphere
    const float size = std::max(radius, h.maxCoeff());
    const float margin = 0.1f * dist + 1e-3f * size;  // the gap's float error is ~1e-5 of the size
    LocalContact c[kMaxContactsPerBrick];
    // Sphere as a, box as b: normal from the box to the sphere, point on the box.
    int m = collideShapes(QueryShape::sphere(radius), {centre, randomRotation(r)}, QueryShape::box(h), box, margin, c);
    ASSERT_EQ(m, 1) << "case " << k;
    const float normalTol = kSphereBoxNormalTol, pointTol = kSphereBoxPointRel;
    Worst& w = gap ? worstGap : worst;
    float dErr = std::abs(c[0].depth - depth) / size, pErr = (c[0].position - q).norm() / size, nErr = (c[0].normal - n).norm();
    w.add(dErr, pErr, nErr);
    EXPECT_LT(dErr, kSphereBoxDepthRel) << "case " << k << " (" << clamped << " axes clamped): depth " << c[0].depth << " expected " << depth;
    EXPECT_LT(pErr, pointTol) << "case " << k << " (" << clamped << " axes clamped)";
    EXPECT_LT(nErr, normalTol) << "case " << k << " (" << clamped << " axes clamped)";
    // Box as a, sphere as b: normal from the sphere to the box, point on the sphere.
    m = collideShapes(QueryShape::box(h), box, QueryShape::sphere(radius), {centre, Quatf::Identity()}, margin, c);
    ASSERT_EQ(m, 1) << "case " << k;
    const Vec3f onSphere = centre - n * radius;
    dErr = std::abs(c[0].depth - depth) / size, pErr = (c[0].position - onSphere).norm() / size, nErr = (c[0].normal + n).norm();
    w.add(dErr, pErr, nErr);
    EXPECT_LT(dErr, kSphereBoxDepthRel) << "case " << k << " swapped";
    EXPECT_LT(pErr, pointTol) << "case " << k << " swapped";
    EXPECT_LT(nErr, normalTol) << "case " << k << " swapped";
  }
  for (int a = 1; a <= 3; ++a) EXPECT_GT(regions[a], 300) << a << " axes clamped";
}

// Box a (smaller footprint, yawed by any angle about b's face normal) pressed `depth` into the
// +z face of box b, or hovering above it within the speculative margin: four contacts, one per
// bottom corner of a, each on b's face under that corner, the normal b's face normal, the depth
// the same at every corner.
TEST(ShapeContacts, BoxOnBoxFaceGivesItsFourCornersAtTheRightDepth) {
  SeededRandom r(2301);
  Worst worst{"box-box"}, worstGap{"box-box gap"};
  int hovered = 0;
  for (int k = 0; k < 800; ++k) {
    const Vec3f hb = test::drawVec3([&](int axis) { return axis < 2 ? r.logUniform(0.5, 500) : r.logUniform(0.2, 500); });
    const LocalPose b{randomPosition(r, 100), randomRotation(r)};
    // a's footprint (its circumradius) fits inside b's face whatever the yaw.
    const float footprint = std::min(hb.x(), hb.y()) * float(r.uniform(0.2, 0.45));
    const float ax = footprint * float(r.uniform(0.3, 0.9)), ay = std::sqrt(footprint * footprint - ax * ax);
    const Vec3f ha(ax, ay, float(r.logUniform(0.2, 250)));
    const float size = std::max(ha.maxCoeff(), hb.maxCoeff());
    const bool hovering = r.below(4) == 0;
    // Penetration up to 20% of the thinnest half extent of either box (a resting or landing box;
    // deeper than a box's own width, the detector may pick a side face).
    const float thin = std::min(ha.minCoeff(), hb.z());
    // Hovering: a gap of at least 1e-4 of the size (below that, float rounding of the corners'
    // gaps along the first contact's normal can drop the extra speculative corners).
    const float depth =
        hovering ? -(float(r.uniform(0.001, 0.05)) * thin + 1e-4f * size) : float(r.uniform(0.01, 0.2)) * thin;
    const float margin = hovering ? -2.f * depth : 0.f;
    hovered += hovering;
    const float offsetY = float(r.uniform(-0.5, 0.5)) * (hb.y() - footprint);
    const float offsetX = float(r.uniform(-0.5, 0.5)) * (hb.x() - footprint);
    const Vec3f offset(offsetX, offsetY, hb.z() + ha.z() - depth);
    const Quatf yaw(Eigen::AngleAxisf(float(r.uniform(0, 6.2831853)), Vec3f::UnitZ()));
    const LocalPose a{b.position + b.rotation * offset, (b.rotation * yaw).normalized()};
    LocalContact c[kMaxContactsPerBrick];
    const int m = collideShapes(QueryShape::box(ha), a, QueryShape::box(hb), b, margin, c);
    // Hovering: the nearest pair of points (collision/bricks/box_box_gap.h), plus the other
    // corners of a's face within the margin along its normal: a's four corners, as when pressed in.
    // (While Bullet's GJK measured the gap, one hovering pair in 191 got no contact and 8 a first
    // normal off by up to 0.046, and the other corners' gaps carried that error.)
    ASSERT_EQ(m, 4) << "case " << k << " depth " << depth << (hovering ? " (hovering)" : "");
    const Vec3f n = b.rotation * Vec3f::UnitZ();
    bool matched[4] = {false, false, false, false};
    for (int i = 0; i < m; ++i) {
      // The corner of a's bottom face nearest this contact, projected onto b's top face.
      float best = 1e30f;
      int bestCorner = -1;
      for (int j = 0; j < 4; ++j) {
        const Vec3f corner = offset + yaw * Vec3f((j & 1) ? ax : -ax, (j & 2) ? ay : -ay, -ha.z());
        const Vec3f onFace = b.position + b.rotation * Vec3f(corner.x(), corner.y(), hb.z());
        const float d = (c[i].position - onFace).norm();
        if (d < best) best = d, bestCorner = j;
      }
      const float dErr = std::abs(c[i].depth - depth) / size, pErr = best / size, nErr = (c[i].normal - n).norm();
      (hovering ? worstGap : worst).add(dErr, pErr, nErr);
      // Touching boxes: the box-box detector, exact to float rounding. Hovering: the nearest
      // pair in closed form and the corners along its normal (measured worst depth 2.6e-6 of the size).
      EXPECT_LT(dErr, hovering ? 1e-5f : kRel) << "case " << k << " contact " << i << ": depth " << c[i].depth
                                               << " expected " << depth;
      EXPECT_LT(pErr, kRel) << "case " << k << " contact " << i << ": " << best << " from the nearest corner's footprint";
      EXPECT_LT(nErr, kNormalTol) << "case " << k << " contact " << i;
      EXPECT_FALSE(matched[bestCorner]) << "case " << k << ": two contacts at corner " << bestCorner;
      matched[bestCorner] = true;
    }
  }
  EXPECT_GT(hovered, 100);
}

// The other way round: a small box b (a brick) hovering under a large box a's face, within the
// margin. The nearest pair is one of b's top corners, and b's other three top corners face a
// within the margin too: four contacts at b's corners, each at the gap. (With one contact per
// brick at the same corner of each, a row of bricks flying at a giant box's face turned about
// that line into the face: WorldExtremes.TenKilometreBoxStopsAGrid.)
TEST(ShapeContacts, SmallBoxUnderALargeBoxFaceGivesItsFourCorners) {
  SeededRandom r(2302);
  Worst worst{"small-box gap"};
  for (int k = 0; k < 400; ++k) {
    const Vec3f hb = test::drawVec3([&](int) { return r.logUniform(0.1, 2); });
    const Vec3f ha = test::drawVec3([&](int) { return r.logUniform(5, 500); });
    const LocalPose b{randomPosition(r, 100), randomRotation(r)};
    const float size = std::max(ha.maxCoeff(), hb.maxCoeff());
    const float gap = float(r.uniform(0.001, 0.05)) * hb.minCoeff() + 1e-5f * size;
    // a's face over b's top face: a's centre above b, shifted within its face by less than the
    // face's half extent minus b's circumradius, so b's top face lies under it.
    const float room = std::min(ha.x(), ha.y()) - hb.head<2>().norm();
    const Vec3f shift(float(r.uniform(-0.5, 0.5)) * room, float(r.uniform(-0.5, 0.5)) * room, 0.f);
    const Quatf yaw(Eigen::AngleAxisf(float(r.uniform(0, 6.2831853)), Vec3f::UnitZ()));
    const Vec3f centreInB = Vec3f(0, 0, hb.z() + gap + ha.z()) + yaw * shift;
    const LocalPose a{b.position + b.rotation * centreInB, (b.rotation * yaw).normalized()};
    LocalContact c[kMaxContactsPerBrick];
    const int m = collideShapes(QueryShape::box(ha), a, QueryShape::box(hb), b, 2.f * gap, c);
    ASSERT_EQ(m, 4) << "case " << k;
    const Vec3f n = b.rotation * Vec3f::UnitZ();
    bool matched[4] = {false, false, false, false};
    for (int i = 0; i < m; ++i) {
      float best = 1e30f;
      int corner = -1;
      for (int j = 0; j < 4; ++j) {
        const Vec3f p = b.position + b.rotation * Vec3f((j & 1) ? hb.x() : -hb.x(), (j & 2) ? hb.y() : -hb.y(), hb.z());
        if ((c[i].position - p).norm() < best) best = (c[i].position - p).norm(), corner = j;
      }
      const float dErr = std::abs(-c[i].depth - gap) / size, pErr = best / size, nErr = (c[i].normal - n).norm();
      worst.add(dErr, pErr, nErr);
      EXPECT_LT(dErr, 1e-5f) << "case " << k << " contact " << i;
      EXPECT_LT(pErr, 1e-5f) << "case " << k << " contact " << i;
      EXPECT_LT(nErr, kNormalTol) << "case " << k << " contact " << i;
      EXPECT_FALSE(matched[corner]) << "case " << k << ": two contacts at corner " << corner;
      matched[corner] = true;
    }
  }
}

// A capsule (core segment along its local z) standing on b's +z face touches it at one point
// under its lower end; one lying on the face touches it along its segment's footprint. Both
// penetrate by `depth` or hover within the margin.
TEST(ShapeContacts, CapsuleOnBoxFaceStandingAndLyingMatchesClosedForm) {
  SeededRandom r(2401);
  Worst worst{"capsule-box"};
  for (int k = 0; k < 1000; ++k) {
    const float radius = float(r.logUniform(0.2, 250)), halfHeight = float(r.logUniform(0.2, 250));
    const bool lying = k % 2 == 1;
    const float reach = lying ? halfHeight + radius : radius;  // footprint's half length on the face
    const Vec3f hb = test::drawVec3([&](int axis) { return axis < 2 ? reach * float(r.uniform(1.2, 3)) : r.logUniform(0.2, 500); });
    const LocalPose b{randomPosition(r, 100), randomRotation(r)};
    const float size = std::max({radius, halfHeight, hb.maxCoeff()});
    const bool hovering = r.below(4) == 0;
    const float thin = std::min(radius, hb.z());
    const float depth = hovering ? -float(r.uniform(0.001, 0.05)) * thin : float(r.uniform(0.01, 0.5)) * thin;
    const float margin = hovering ? -2.f * depth : 0.f;
    const float offsetY = float(r.uniform(-0.9, 0.9)) * (hb.y() - reach);
    const float offsetX = float(r.uniform(-0.9, 0.9)) * (hb.x() - reach);
    const Vec3f offset(offsetX, offsetY, hb.z() + radius - depth + (lying ? 0.f : halfHeight));
    const float theta = float(r.uniform(0, 6.2831853));
    Quatf local(Eigen::AngleAxisf(theta, Vec3f::UnitZ()));
    if (lying) local = local * Quatf(Eigen::AngleAxisf(1.5707963f, Vec3f::UnitX()));  // axis along the face
    const LocalPose a{b.position + b.rotation * offset, (b.rotation * local).normalized()};
    LocalContact c[kMaxContactsPerBrick];
    const int m = collideShapes(QueryShape::capsule(radius, halfHeight), a, QueryShape::box(hb), b, margin, c);
    ASSERT_EQ(m, 1) << "case " << k << (lying ? " lying" : " standing") << (hovering ? ", hovering" : "");
    const Vec3f n = b.rotation * Vec3f::UnitZ();
    // The contact point in b's frame: on the face (z = hb.z) and, standing, under the axis; lying,
    // on the segment's footprint.
    const Vec3f p = b.rotation.conjugate() * (c[0].position - b.position);
    float pErr = std::abs(p.z() - hb.z());
    const Eigen::Vector2f foot(p.x() - offset.x(), p.y() - offset.y());
    if (lying) {
      const Eigen::Vector2f axis(-std::sin(theta), std::cos(theta));  // the capsule's z turned by the yaw
      const float along = std::clamp(foot.dot(axis), -halfHeight, halfHeight);
      pErr = std::max(pErr, (foot - axis * along).norm());
    } else {
      pErr = std::max(pErr, foot.norm());
    }
    pErr /= size;
    const float dErr = std::abs(c[0].depth - depth) / size, nErr = (c[0].normal - n).norm();
    worst.add(dErr, pErr, nErr);
    EXPECT_LT(dErr, kRel) << "case " << k << (lying ? " lying" : " standing") << ": depth " << c[0].depth << " expected " << depth;
    EXPECT_LT(pErr, kRel) << "case " << k << (lying ? " lying" : " standing");
    EXPECT_LT(nErr, kNormalTol) << "case " << k << (lying ? " lying" : " standing");
  }
}

}  // namespace
}  // namespace bw
