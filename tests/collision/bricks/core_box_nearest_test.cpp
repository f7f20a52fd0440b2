// coreBoxNearest (collision/bricks/core_box_nearest.h) against an independent reference in
// double: the distance from a point of the segment to the box is convex along the segment, so a
// ternary search over the segment's parameter finds its least (to 1e-12 of the length). Seeded
// segments (a point, or up to 500 long) and boxes (0.1 to 500 per axis; brick rotations, which
// are signed permutations, and general ones), from far apart to nearly touching, 1e4 from the
// origin included. Segments that meet the box are declined.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <gtest/gtest.h>
#include <limits>
#include <optional>

#include "collision/bricks/core_box_nearest.h"
#include "collision/core/axis_rotation.h"
#include "collision/core/seeded_random.h"
#include "collision/support/sequenced_draws.h"

namespace bw {
namespace {

struct Box {
  Vec3f half, centre;
  Mat3f rotation;
  Eigen::Vector3d nearestPoint(const Eigen::Vector3d& p) const {
    const Eigen::Matrix3d r = rotation.cast<double>();
    const Eigen::Vector3d local = r.transpose() * (p - centre.cast<double>());
    return centre.cast<double>() + r * local.cwiseMax(-half.cast<double>()).cwiseMin(half.cast<double>());
  }
  double distance(const Eigen::Vector3d& p) const { return (p - nearestPoint(p)).norm(); }
};

// The least distance from the segment to the box, by ternary search (convex along the segment),
// and the direction from the box's nearest point to the segment's.
struct Reference {
  double distance;
  Eigen::Vector3d direction;
};
Reference referenceNearest(const Vec3f& p0, const Vec3f& p1, const Box& box) {
  const Eigen::Vector3d a = p0.cast<double>(), d = (p1 - p0).cast<double>();
  double lo = 0, hi = 1;
  for (int it = 0; it < 200; ++it) {
    const double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
    if (box.distance(a + d * m1) <= box.distance(a + d * m2)) {
      hi = m2;
    } else {
      lo = m1;
    }
  }
  Eigen::Vector3d best = a + d * (0.5 * (lo + hi));
  for (const Eigen::Vector3d& end : {a, Eigen::Vector3d(a + d)}) {
    if (box.distance(end) < box.distance(best)) best = end;
  }
  const Eigen::Vector3d q = box.nearestPoint(best);
  return {(best - q).norm(), (best - q).normalized()};
}

Box randomBox(SeededRandom& r, bool brickRotation, float far) {
  Box b;
  b.half = test::drawVec3([&](int) { return r.logUniform(0.1, 250); });
  b.centre = test::drawVec3([&](int) { return r.uniform(-1, 1); }) * far;
  if (brickRotation) {
    b.rotation = AxisRotation::fromIndex(int(r.below(24))).matrix();
  } else {
    b.rotation = test::drawQuat([&] { return r.normal(); }).normalized().toRotationMatrix();
  }
  return b;
}

TEST(CoreBoxNearest, MatchesTheLeastDistanceAlongTheSegment) {
  SeededRandom r(5101);
  int answered = 0, declined = 0;
  double worstDistance = 0, worstPoints = 0, worstNormal = 0;
  for (int k = 0; k < 4000; ++k) {
    const Box box = randomBox(r, k % 2 == 0, k % 3 == 0 ? 1e4f : 10.f);
    // A segment around a point near the box: its centre within 1.5 x the box's extent, its length
    // 0 (a sphere's core) to 500.
    const Vec3f mid = box.centre + box.rotation * test::drawVec3([&](int axis) { return r.uniform(-1.5, 1.5) * box.half[axis]; });
    const Vec3f dir = test::drawVec3([&](int) { return r.normal(); }).normalized();
    const float length = k % 4 == 0 ? 0.f : float(r.logUniform(0.01, 500));
    const Vec3f p0 = mid - dir * (0.5f * length), p1 = k % 4 == 0 ? p0 : Vec3f(mid + dir * (0.5f * length));
    const Reference ref = referenceNearest(p0, p1, box);
    const double exact = ref.distance;
    const std::optional<CoreBoxNearest> near = coreBoxNearest(p0, p1, box.half, box.rotation, box.centre);
    const double scale = double(box.half.sum() + length + (mid - box.centre).norm());
    if (exact < 1e-6 * scale) {  // meets the box (to the reference's rounding): declined
      if (exact == 0.0) {
        EXPECT_FALSE(near.has_value()) << "case " << k << ": the segment meets the box";
      }
      ++declined;
      continue;
    }
    ASSERT_TRUE(near.has_value()) << "case " << k << ": apart by " << exact;
    ++answered;
    // Points are floats where the box is (1e4 from the origin: spacing 1e-3); that rounding is
    // taken out of their error.
    const double placement = 4 * double(std::numeric_limits<float>::epsilon()) * double(box.centre.norm());
    const double dErr = std::abs(double(near->distance) - exact) / scale;
    const Eigen::Vector3d onCore = near->onCore.cast<double>(), onBox = near->onBox.cast<double>();
    const Eigen::Vector3d a = p0.cast<double>(), d = (p1 - p0).cast<double>();
    const double t = d.squaredNorm() > 0 ? std::clamp((onCore - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
    const double pErr = std::max(0.0, std::max(box.distance(onBox), (a + d * t - onCore).norm()) - placement) / scale;
    const double nErr = (near->normal.cast<double>() - ref.direction).norm();
    // A general rotation is a float quaternion's matrix, orthonormal to ~1e-7: the function and
    // the reference see boxes that differ by that of the scale, which turns the direction by that
    // over the distance.
    const double normalTol = 1e-5 + 1e-6 * scale / exact;
    worstDistance = std::max(worstDistance, dErr), worstPoints = std::max(worstPoints, pErr);
    worstNormal = std::max(worstNormal, nErr / normalTol);
    EXPECT_LT(dErr, 1e-6) << "case " << k << ": " << near->distance << " against " << exact;
    EXPECT_LT(pErr, 1e-6) << "case " << k;
    EXPECT_LT(nErr, normalTol) << "case " << k << ": distance / scale " << exact / scale;
  }
  std::printf("[ core-box  ] %d answered, %d meeting the box; worst relative distance error %.2e, points %.2e, "
              "normal %.2f of its tolerance\n",
              answered, declined, worstDistance, worstPoints, worstNormal);
  EXPECT_GT(answered, 2000);
  EXPECT_GT(declined, 200);
}

}  // namespace
}  // namespace bw
