// Math types: axis rotations, OBB overlap, ray slab tests, precision rule, input validation.
#include <Eigen/Geometry>
#include <cmath>
#include <gtest/gtest.h>
#include <limits>
#include <random>
#include <set>
#include <utility>

#include "collision/core/argument_checks.h"
#include "collision/core/axis_rotation.h"
#include "collision/core/obb.h"
#include "collision/core/ray.h"
#include "collision/core/rigid_transform.h"

namespace bw {
namespace {

TEST(AxisRotation, TwentyFourDistinctExactRotations) {
  std::set<std::vector<float>> seen;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-100.f, 100.f);
  for (int i = 0; i < AxisRotation::kCount; ++i) {
    const AxisRotation r = AxisRotation::fromIndex(i);
    const Mat3f m = r.matrix();
    EXPECT_NEAR(m.determinant(), 1.f, 0.f);
    EXPECT_TRUE((m * m.transpose()).isIdentity(0.f));
    seen.insert(std::vector<float>(m.data(), m.data() + 9));
    for (int k = 0; k < 20; ++k) {
      const Vec3f v(u(rng), u(rng), u(rng));
      EXPECT_EQ(r.apply(v), Vec3f(m * v)) << "apply must be exact";
      EXPECT_EQ(r.inverse().apply(r.apply(v)), v);
      EXPECT_EQ(r.applyToExtent(v.cwiseAbs()), r.apply(v).cwiseAbs());
    }
    EXPECT_TRUE(r.quaternion().toRotationMatrix().isApprox(m, 1e-6f));
    EXPECT_EQ(r.quaternion().coeffs(), Quatf(m).normalized().coeffs()) << "the table holds what the matrix gives";
    // Local +Z ("up") points along the direction.
    Vec3f dir = Vec3f::Zero();
    dir[r.direction() / 2] = (r.direction() % 2 == 0) ? 1.f : -1.f;
    EXPECT_EQ(r.apply(Vec3f::UnitZ()), dir);
  }
  EXPECT_EQ(seen.size(), 24u);
  EXPECT_EQ(AxisRotation::identity().matrix(), Mat3f::Identity());
}

TEST(AxisRotation, CompositionMatchesMatrices) {
  for (int a = 0; a < 24; ++a)
    for (int b = 0; b < 24; ++b) {
      const AxisRotation ra = AxisRotation::fromIndex(a), rb = AxisRotation::fromIndex(b);
      EXPECT_EQ((ra * rb).matrix(), Mat3f(ra.matrix() * rb.matrix()));
    }
}

TEST(AxisRotation, SpinTurnsAboutTheDirection) {
  for (int d = 0; d < 6; ++d) {
    const AxisRotation r0 = AxisRotation::fromDirectionSpin(d, 0);
    const AxisRotation r1 = AxisRotation::fromDirectionSpin(d, 1);
    const Vec3f up = r0.apply(Vec3f::UnitZ());
    // r1 = quarter turn about `up` applied after r0: rotating r0's local X by +90 deg about up.
    const Vec3f x0 = r0.apply(Vec3f::UnitX());
    EXPECT_EQ(r1.apply(Vec3f::UnitX()), Vec3f(up.cross(x0)));
  }
  EXPECT_THROW(AxisRotation::fromIndex(24), InvalidInput);
  EXPECT_THROW(AxisRotation::fromDirectionSpin(6, 0), InvalidInput);
  EXPECT_THROW(AxisRotation::fromDirectionSpin(0, 4), InvalidInput);
}

// Exact reference for two boxes, in double: convex polyhedra intersect exactly when a corner of
// one lies in the other or an edge of one crosses a face of the other. Independent of the
// separating-axis formulas under test. (It replaced Bullet's GJK distance, which called 2 of
// 4,000 clearly overlapping pairs 0.06 and 0.16 apart: the draws clang's argument order gives.)
struct BoxD {
  Eigen::Vector3d center, half;
  Eigen::Matrix3d axes;  // columns: the box's axes in world terms

  Eigen::Vector3d toLocal(const Eigen::Vector3d& p) const { return axes.transpose() * (p - center); }
  bool contains(const Eigen::Vector3d& p) const { return (toLocal(p).cwiseAbs().array() <= half.array()).all(); }
  Eigen::Vector3d corner(int i) const {
    return center + axes * Eigen::Vector3d((i & 1) ? half.x() : -half.x(), (i & 2) ? half.y() : -half.y(),
                                           (i & 4) ? half.z() : -half.z());
  }
  BoxD grown(double by) const { return {center, half + Eigen::Vector3d::Constant(by), axes}; }
};

// Does segment p-q cross one of b's six faces?
bool segmentCrossesAFace(const BoxD& b, const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  const Eigen::Vector3d lp = b.toLocal(p), lq = b.toLocal(q);
  for (int k = 0; k < 3; ++k)
    for (double side : {-1.0, 1.0}) {
      const double dp = side * lp[k] - b.half[k], dq = side * lq[k] - b.half[k];
      if ((dp > 0) == (dq > 0)) continue;  // both on one side of the face's plane
      const Eigen::Vector3d x = lp + (lq - lp) * (dp / (dp - dq));
      const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
      if (std::abs(x[k1]) <= b.half[k1] && std::abs(x[k2]) <= b.half[k2]) return true;
    }
  return false;
}

bool boxesIntersect(const BoxD& a, const BoxD& b) {
  for (int i = 0; i < 8; ++i)
    if (b.contains(a.corner(i)) || a.contains(b.corner(i))) return true;
  for (const auto& [s, o] : {std::pair{&a, &b}, std::pair{&b, &a}})
    for (int i = 0; i < 8; ++i)
      for (int bit = 1; bit < 8; bit <<= 1)  // the 12 edges: corner i to the corner across one axis
        if (!(i & bit) && segmentCrossesAFace(*o, s->corner(i), s->corner(i | bit))) return true;
  return false;
}

// Differential test of the OBB/AABB separating-axis test against the exact reference: pairs
// apart by more than 1e-3 (the OBB grown by 1e-3 misses the box: a 1e-3 neighbourhood lies
// inside the grown box) must not overlap, pairs overlapping by more (the OBB shrunk by 1e-3
// still meets the box) must; the few within 1e-3 of touching are rounding's to decide.
TEST(Obb, OverlapMatchesExactBoxIntersectionOnRandomPoses) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> pos(-3.f, 3.f), size(0.05f, 2.5f), ang(-3.2f, 3.2f);
  constexpr double kBand = 1e-3;
  int overlapping = 0, separated = 0;
  for (int i = 0; i < 4000; ++i) {
    const Aabb box = Aabb::fromCenterHalf(Vec3f(pos(rng), pos(rng), pos(rng)), Vec3f(size(rng), size(rng), size(rng)));
    const Vec3f axis = Vec3f(pos(rng), pos(rng), pos(rng)).normalized();
    const Quatf q(Eigen::AngleAxisf(ang(rng), axis.allFinite() ? axis : Vec3f::UnitX()));
    const Obb obb{Vec3f(pos(rng), pos(rng), pos(rng)), Vec3f(size(rng), size(rng), size(rng)), q.toRotationMatrix()};

    const BoxD a{obb.center.cast<double>(), obb.half.cast<double>(), obb.axes.cast<double>()};
    const BoxD b{box.center().cast<double>(), box.halfExtent().cast<double>(), Eigen::Matrix3d::Identity()};
    if (!boxesIntersect(a.grown(kBand), b)) {
      EXPECT_FALSE(overlaps(obb, box)) << "apart by more than " << kBand << " at case " << i;
      ++separated;
    } else if (boxesIntersect(a.grown(-kBand), b)) {
      EXPECT_TRUE(overlaps(obb, box)) << "overlapping by more than " << kBand << " at case " << i;
      ++overlapping;
    }
  }
  EXPECT_GT(overlapping, 500);
  EXPECT_GT(separated, 500);
  EXPECT_GT(overlapping + separated, 3900) << "few pairs are within the band of touching";
}

// Reference slab test in double precision with explicit handling of every case.
bool referenceRayBox(const Vec3f& o, const Vec3f& d, float maxT, const Aabb& b, double& tEntry) {
  double t0 = 0, t1 = maxT;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d[i]) < std::numeric_limits<float>::min()) {
      if (o[i] < b.min[i] || o[i] > b.max[i]) return false;
      continue;
    }
    double a = (double(b.min[i]) - o[i]) / d[i], c = (double(b.max[i]) - o[i]) / d[i];
    if (a > c) std::swap(a, c);
    t0 = std::max(t0, a);
    t1 = std::min(t1, c);
    if (t0 > t1) return false;
  }
  tEntry = t0;
  return true;
}

TEST(Ray, SlabTestNeverNaNAndMatchesReference) {
  std::mt19937 rng(9);
  std::uniform_int_distribution<int> grid(-4, 4);
  const float dirChoices[] = {0.f, -0.f, 1.f, -1.f, 0.5f, 1e-40f, -1e-40f, 3e38f, 1e-3f};
  int hits = 0;
  for (int i = 0; i < 200000; ++i) {
    // Lattice-aligned origins and boxes so rays lie exactly in slab planes often.
    const Aabb box{Vec3f(float(grid(rng)), float(grid(rng)), float(grid(rng))), Vec3f::Zero()};
    const Aabb b{box.min, box.min + Vec3f(float(1 + grid(rng) % 3 + 3), 1.f, 2.f)};
    const Vec3f o(float(grid(rng)), float(grid(rng)), float(grid(rng)));
    const Vec3f d(dirChoices[rng() % 9], dirChoices[rng() % 9], dirChoices[rng() % 9]);
    if (d.isZero()) continue;
    const Ray r = Ray::make(o, d, 100.f);
    EXPECT_TRUE(r.invDir.allFinite());
    float t = -1;
    double tr = -1;
    const bool hit = intersectRayAabb(r, b, 0.f, r.maxT, t);
    const bool ref = referenceRayBox(o, d, r.maxT, b, tr);
    ASSERT_EQ(hit, ref) << "case " << i;
    if (hit) {
      ++hits;
      ASSERT_FALSE(std::isnan(t));
      ASSERT_NEAR(t, tr, 1e-5 * std::max(1.0, std::abs(tr)));
    }
  }
  EXPECT_GT(hits, 10000);
}

TEST(RigidTransform, LocalCoordinatesFarFromOriginKeepFullPrecision) {
  for (double offset : {0.0, 1e3, 1e5, 1e7, 1e9}) {
    RigidTransform grid{Vec3d(offset, -offset, offset * 0.5), Quatf(Eigen::AngleAxisf(0.3f, Vec3f::UnitY()))};
    const Vec3f local(0.001f, 12.5f, -3.25f);
    const Vec3d world = grid.pointToWorld(local);
    const Vec3f back = grid.pointToLocal(world);
    // Double carries ~1e-16 relative; at 1e9 that is ~1e-7 absolute, below float's resolution at 12.5.
    EXPECT_LT((back - local).norm(), 2e-6f) << "offset " << offset;
  }
  const RigidTransform a{Vec3d(1, 2, 3), Quatf(Eigen::AngleAxisf(0.7f, Vec3f(1, 1, 0).normalized()))};
  const RigidTransform b{Vec3d(-4, 0.5, 9), Quatf(Eigen::AngleAxisf(-1.1f, Vec3f::UnitZ()))};
  const Vec3f p(0.3f, -0.2f, 5.f);
  // (a * b) applies b first: p in b's frame -> a's frame -> world.
  const Vec3d viaParts = a.pointToWorld(b.pointToWorld(p).cast<float>());
  EXPECT_LT(((a * b).pointToWorld(p) - viaParts).norm(), 1e-5);
  // The inverse maps world to local.
  const Vec3d q(7, 8, 9);
  EXPECT_LT((a.inverse().pointToWorld(q.cast<float>()).cast<float>() - a.pointToLocal(q)).norm(), 1e-5f);
  EXPECT_LT((a.inverse() * a).translation.norm(), 1e-6);
}

TEST(InputValidation, NonFiniteValuesAreRejectedWithTheirName) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  try {
    requireFinite(Vec3f(1, nan, 2), "Grid::placeBrick", "position");
    FAIL();
  } catch (const InvalidInput& e) {
    EXPECT_STREQ(e.what(), "Grid::placeBrick: position.y is NaN");
  }
  EXPECT_THROW(requireFinite(Vec3d(inf, 0, 0), "x", "y"), InvalidInput);
  EXPECT_THROW(requireFinite(-inf, "x", "y"), InvalidInput);
  EXPECT_NO_THROW(requireFinite(Vec3f(1e38f, -1e-45f, 0), "x", "y"));
  EXPECT_THROW(requireInRange(0.0, 0.01, 1000, "Brick", "size"), InvalidInput);
  EXPECT_THROW(requireUnitQuaternion(Quatf(2, 0, 0, 0), "Body", "rotation"), InvalidInput);
  RigidTransform t;
  t.translation.z() = std::nan("");
  EXPECT_THROW(t.validate("World::addGrid"), InvalidInput);
}

}  // namespace
}  // namespace bw
