// A BrickGrid far from the world origin, and bricks far from the grid's own origin (split from
// the former collision extremes_test.cpp).
//
// Guarantees these tests establish (seeded, deterministic; each one can fail):
// - A grid placed anywhere up to 1e9 from the world origin (double translation, any rotation)
//   answers in grid-local terms like at the origin: contact depth and point within
//   8 eps(T), eps(T) = 2^-20 + |T| 2^-52 (local coordinates < 16), normal within 2e-4, ray hit
//   distance within 8 eps(T) / |cos(incidence)|, identical overlap sets. Measured: the
//   translation adds nothing measurable up to 1e9 (depth 2.1e-7, point 4.8e-7 at every offset).
// - Inside a grid, float spacing sets the precision: bricks at local distance L keep depth and
//   contact points within 4 ulp(L) (ulp(1e4) = 2^-10 ~ 9.8e-4), hit distances within
//   4 ulp(L) / |cos|, normals within 4 ulp(L) / radius. Keep grid-local coordinates below ~1e4
//   for millimetre-level contacts.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <gtest/gtest.h>
#include <string>
#include <vector>

#include "collision/bricks/brick_grid.h"
#include "collision/core/argument_checks.h"
#include "collision/core/seeded_random.h"
#include "collision/support/extremes_support.h"
#include "collision/support/sequenced_draws.h"

namespace bw {
namespace {

using namespace test;  // the shared brute-force helpers (collision/support/extremes_support.h)

// A small build: a floor of plates, a wedge, a cylinder and microbricks, all shifted by `offset`
// in the grid's own frame.
void buildFarTestGrid(BrickGrid& grid, const Vec3f& offset) {
  for (int x = 0; x < 8; ++x)
    for (int y = 0; y < 8; ++y) grid.placeBrick(Brick::box(offset + Vec3f(float(x), float(y), 0.f), Vec3f(0.5f, 0.5f, 0.1f)));
  Brick w = Brick::box(offset + Vec3f(3.f, 3.f, 0.6f), Vec3f(1.f, 2.f, 0.5f));
  w.shape = BrickShape::Wedge;
  w.rotation = AxisRotation::fromIndex(5);
  grid.placeBrick(w);
  Brick c = Brick::box(offset + Vec3f(6.f, 1.f, 0.7f), Vec3f(0.4f, 0.4f, 0.6f));
  c.shape = BrickShape::Cylinder;
  c.sides = 16;
  grid.placeBrick(c);
  for (int k = 0; k < 6; ++k) grid.placeBrick(Brick::box(offset + Vec3f(1.02f + 0.04f * k, 6.f, 0.12f), Vec3f::Constant(0.02f)));
}

struct LocalQuery {
  QueryShape shape;
  Vec3f position;  // relative to the build's offset
  Quatf rotation;
};

std::vector<LocalQuery> farQueries(std::vector<Vec3f>& hullPoints) {
  hullPoints.clear();
  for (int i = 0; i < 8; ++i) hullPoints.emplace_back((i & 1) ? 0.3f : -0.3f, (i & 2) ? 0.2f : -0.2f, (i & 4) ? 0.25f : -0.25f);
  std::vector<LocalQuery> out;
  out.push_back({QueryShape::box(Vec3f(0.5f, 0.5f, 0.25f)), Vec3f(2.3f, 4.6f, 0.1f + 0.25f - 0.01f), Quatf::Identity()});
  out.push_back({QueryShape::box(Vec3f(0.05f, 0.05f, 0.05f)), Vec3f(1.1f, 6.f, 0.14f + 0.05f - 0.004f), Quatf::Identity()});
  SeededRandom r(51);
  for (int k = 0; k < 40; ++k) {
    // Draws in a fixed order (collision/support/sequenced_draws.h).
    const Vec3f p = drawVec3([&](int axis) { return axis < 2 ? r.uniform(0, 7) : r.uniform(0.05, 1.2); });
    const Vec3f axis = drawVec3([&](int) { return r.normal(); }).normalized();
    const Quatf q(Eigen::AngleAxisf(float(r.uniform(0, 6.28)), axis));
    switch (k % 4) {
      case 0: out.push_back({QueryShape::sphere(0.3f), p, q}); break;
      case 1: out.push_back({QueryShape::box(Vec3f(0.4f, 0.3f, 0.2f)), p, q}); break;
      case 2: out.push_back({QueryShape::capsule(0.2f, 0.3f), p, q}); break;
      default: out.push_back({QueryShape::hull(hullPoints.data(), uint32_t(hullPoints.size())), p, q}); break;
    }
  }
  return out;
}

// Contacts of every query with maxContacts 64 (no reduction), in grid-local terms.
std::vector<std::vector<LocalContact>> contactsInGridTerms(const BrickGrid& grid, const RigidTransform& gridPose,
                                                           const Vec3f& offset, const std::vector<LocalQuery>& queries) {
  std::vector<std::vector<LocalContact>> out;
  ContactScratch scratch;
  ContactParams params;
  params.maxContacts = 64;  // no speculative margin: only penetrating contacts are compared
  for (const LocalQuery& q : queries) {
    const Vec3f local = offset + q.position;
    const RigidTransform shapePose{gridPose.pointToWorld(local), (gridPose.rotation * q.rotation).normalized()};
    std::vector<Contact> world;
    grid.collide(gridPose, q.shape, shapePose, params, scratch, world);
    std::vector<LocalContact> mine;
    for (const Contact& c : world) {
      // Back to the grid frame in double, relative to the build's offset.
      const Vec3d rel = gridPose.rotation.conjugate().cast<double>() * (c.position - gridPose.translation) - offset.cast<double>();
      mine.push_back({rel.cast<float>(), gridPose.directionToLocal(c.normal), c.depth, c.featureB, c.material});
    }
    out.push_back(mine);
  }
  return out;
}

// Largest differences between two contact sets (matched per feature, nearest point first).
struct ContactDiff {
  float depth = 0, normal = 0, position = 0;
  bool countMismatch = false;
};
void compareContacts(const std::vector<LocalContact>& a, const std::vector<LocalContact>& b, ContactDiff& d) {
  if (a.size() != b.size()) {
    d.countMismatch = true;
    return;
  }
  for (const LocalContact& x : a) {
    float best = kInf;
    const LocalContact* m = nullptr;
    for (const LocalContact& y : b)
      if (y.feature == x.feature && (y.position - x.position).norm() < best) best = (y.position - x.position).norm(), m = &y;
    if (!m) {
      d.countMismatch = true;
      return;
    }
    d.position = std::max(d.position, best);
    d.depth = std::max(d.depth, std::abs(m->depth - x.depth));
    d.normal = std::max(d.normal, (m->normal - x.normal).norm());
  }
}

// Tolerances (grid-local queries whose coordinates stay below M = 16):
// - world -> local: the world point carries |T| * 2^-53 of double rounding, the cast to float
//   half a float spacing at M (2^-20): one pose is off by at most eps(T) = 2^-20 + |T| 2^-52.
// - contact depth and point: the narrowphase is Lipschitz in the pose for these non-degenerate
//   cases: 8 eps(T) (measured: 2.1e-7 and 4.8e-7 at every offset, the same as a rotated pose at
//   the origin: the translation adds nothing measurable up to 1e9).
// - contact normal: 2e-4 (GJK/EPA normals of sphere/capsule/hull contacts move with the pose's
//   float rotation; measured 4e-6).
// - ray hit distance: 8 eps(T) / |cos| (slab and plane tests on a pose off by eps(T)).
// A plane offset by e moves an oblique ray's hit by e / |cos| along the ray: hit distances are
// compared after multiplying by |cos| of the angle to the hit face (grazing rays below 0.2 count
// as 0.2).
float obliquity(const Ray& ray, const GridRayHit& h) {
  return std::max(0.2f, std::abs(ray.dir.normalized().dot(h.normal)));
}

double poseEps(double translation) { return std::ldexp(1.0, -20) + translation * std::ldexp(1.0, -52); }

TEST(ExtremesFarFromOrigin, GridPlacedUpTo1e9AnswersLikeAtTheOrigin) {
  BrickGrid grid;
  buildFarTestGrid(grid, Vec3f::Zero());
  std::vector<Vec3f> hull;
  const std::vector<LocalQuery> queries = farQueries(hull);
  const RigidTransform origin{};
  const auto reference = contactsInGridTerms(grid, origin, Vec3f::Zero(), queries);
  int withContacts = 0;
  for (const auto& c : reference) withContacts += !c.empty();
  EXPECT_GT(withContacts, 15);
  ASSERT_GE(reference[0].size(), 4u) << "the resting box gets a manifold from every plate under it";
  ASSERT_FALSE(reference[1].empty()) << "the small box touches a microbrick";

  SeededRandom r(52);
  std::vector<Ray> rays;
  for (int k = 0; k < 200; ++k) {
    const Vec3f o = drawVec3([&](int axis) { return axis < 2 ? r.uniform(-2, 9) : r.uniform(1.5, 4); });
    const Vec3f target = drawVec3([&](int axis) { return axis < 2 ? r.uniform(0, 7) : r.uniform(0, 1); });
    rays.push_back(Ray::make(o, (target - o).normalized()));
  }
  std::vector<GridRayHit> refHits;
  for (const Ray& ray : rays) refHits.push_back(grid.raycast(ray, ~0u));
  std::vector<Aabb> boxes;
  std::vector<std::vector<uint32_t>> refOverlaps;
  for (int k = 0; k < 100; ++k) {
    const float half = float(r.logUniform(0.01, 2));
    const Vec3f centre = drawVec3([&](int axis) { return axis < 2 ? r.uniform(-1, 8) : r.uniform(-0.5, 1.5); });
    boxes.push_back(Aabb::fromCenterHalf(centre, Vec3f::Constant(half)));
    refOverlaps.emplace_back();
    grid.overlapBricks(boxes.back(), ~0u, refOverlaps.back());
    std::sort(refOverlaps.back().begin(), refOverlaps.back().end());
  }

  const Quatf tilt(Eigen::AngleAxisf(0.7f, Vec3f(1, 2, 3).normalized()));
  for (double d : {0.0, 1e3, 1e5, 1e7, 1e9}) {
    const RigidTransform pose{Vec3d(d, -0.6 * d, 0.35 * d), tilt};
    const double eps = poseEps(d);
    const auto got = contactsInGridTerms(grid, pose, Vec3f::Zero(), queries);
    ContactDiff diff;
    for (size_t q = 0; q < queries.size(); ++q) {
      compareContacts(reference[q], got[q], diff);
      ASSERT_FALSE(diff.countMismatch) << "offset " << d << " query " << q;
    }
    EXPECT_LT(diff.depth, 8 * eps) << "offset " << d;
    EXPECT_LT(diff.position, 8 * eps) << "offset " << d;
    EXPECT_LT(diff.normal, 2e-4) << "offset " << d;
    // Rays: world ray (double origin) into the grid frame, hit distance compared.
    float rayDiff = 0;
    for (size_t k = 0; k < rays.size(); ++k) {
      const Vec3d worldOrigin = pose.pointToWorld(rays[k].origin);
      const Vec3d worldDir = pose.rotation.cast<double>() * rays[k].dir.cast<double>();
      const GridRayHit h = grid.raycast(pose.rayToLocal(worldOrigin, worldDir, kInf), ~0u);
      ASSERT_EQ(h.hit(), refHits[k].hit()) << "offset " << d << " ray " << k;
      if (h.hit()) rayDiff = std::max(rayDiff, std::abs(h.t - refHits[k].t) * obliquity(rays[k], refHits[k]));
    }
    EXPECT_LT(rayDiff, 8 * eps) << "offset " << d;
    // Overlaps: the world box centre brought into the grid frame selects the same bricks.
    for (size_t k = 0; k < boxes.size(); ++k) {
      const Vec3f c = pose.pointToLocal(pose.pointToWorld(boxes[k].center()));
      std::vector<uint32_t> ids;
      grid.overlapBricks(Aabb::fromCenterHalf(c, boxes[k].halfExtent()), ~0u, ids);
      std::sort(ids.begin(), ids.end());
      ASSERT_EQ(ids, refOverlaps[k]) << "offset " << d << " box " << k;
    }
    std::printf("[ far      ] offset %.0e: max depth diff %.2e, point %.2e, normal %.2e, ray t %.2e (eps %.2e)\n", d,
                diff.depth, diff.position, diff.normal, rayDiff, eps);
  }
}

// Bricks far from the grid's own origin: float spacing at local distance L is
// ulp(L) = 2^(floor(log2 L) - 23) (~9.8e-4 at 1e4); brick and query positions round to it, so
// depths and contact points hold to a few ulp(L) and hit distances to a few ulp(L) / |cos|:
// 4 ulp(L) asserted.
TEST(ExtremesFarFromOrigin, BricksAtLocal1e4KeepFloatSpacingPrecision) {
  BrickGrid near, far;
  const Vec3f offset(1e4f, -1e4f, 1e4f);
  buildFarTestGrid(near, Vec3f::Zero());
  buildFarTestGrid(far, offset);
  std::vector<Vec3f> hull;
  const std::vector<LocalQuery> queries = farQueries(hull);
  const auto a = contactsInGridTerms(near, RigidTransform{}, Vec3f::Zero(), queries);
  const auto b = contactsInGridTerms(far, RigidTransform{}, offset, queries);
  const double ulpL = std::ldexp(1.0, 13 - 23);
  ContactDiff diff;
  int compared = 0;
  for (size_t q = 0; q < queries.size(); ++q) {
    if (a[q].size() != b[q].size()) {
      // A contact may appear or vanish only when it is within rounding of touching.
      for (const auto* set : {&a[q], &b[q]})
        for (const LocalContact& c : *set) ASSERT_LT(std::abs(c.depth), 4 * ulpL) << "query " << q;
      continue;
    }
    compareContacts(a[q], b[q], diff);
    ASSERT_FALSE(diff.countMismatch) << "query " << q;
    compared += !a[q].empty();
  }
  EXPECT_GT(compared, 15);
  EXPECT_LT(diff.depth, 4 * ulpL);
  EXPECT_LT(diff.position, 4 * ulpL);
  EXPECT_LT(diff.normal, 4 * ulpL / 0.2) << "a point error turns a normal by error / radius (radii >= 0.2)";
  // The small box still gets its microbrick contact at 1e4.
  ASSERT_FALSE(b[1].empty());
  EXPECT_NEAR(b[1][0].depth, a[1][0].depth, 4 * ulpL);
  SeededRandom r(53);
  float rayDiff = 0;
  for (int k = 0; k < 200; ++k) {
    const Vec3f o = drawVec3([&](int axis) { return axis < 2 ? r.uniform(-2, 9) : r.uniform(1.5, 4); });
    const Vec3f target = drawVec3([&](int axis) { return axis < 2 ? r.uniform(0, 7) : r.uniform(0, 1); });
    const Vec3f d = (target - o).normalized();
    const GridRayHit h0 = near.raycast(Ray::make(o, d), ~0u);
    const GridRayHit h1 = far.raycast(Ray::make(o + offset, d), ~0u);
    ASSERT_EQ(h0.hit(), h1.hit()) << "ray " << k;
    if (h0.hit()) rayDiff = std::max(rayDiff, std::abs(h0.t - h1.t) * obliquity(Ray::make(o, d), h0));
  }
  EXPECT_LT(rayDiff, 4 * ulpL);
  std::printf("[ local 1e4] max depth diff %.2e, point %.2e, normal %.2e, ray t %.2e (ulp %.2e)\n", diff.depth,
              diff.position, diff.normal, rayDiff, ulpL);
}

}  // namespace
}  // namespace bw
