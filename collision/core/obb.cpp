#include "collision/core/obb.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bw {

namespace {

// The separating-axis test; an axis separates when the projections' gap exceeds slack.
bool satOverlap(const Obb& a, const Aabb& b, float slack) {
  const Vec3f bc = b.center();
  const Vec3f bh = b.halfExtent();
  const Mat3f& R = a.axes;  // a's axes expressed in b's (world-aligned) frame
  const Vec3f t = a.center - bc;
  Mat3f absR;
  constexpr float eps = 1e-6f;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) absR(i, j) = std::abs(R(i, j)) + eps;

  // b's face axes (world x, y, z): a's bounds against b's faces as they are. note: not through
  // t: at the scale of a huge b (a 8.6e8 m element) t rounds by tens of metres, and a box 0.3 m
  // short of b tested overlapping (the OctoBVH fuzz target; the tree's own AABB pre-test said
  // no). This way the world axes answer exactly what Aabb::overlaps(a.bounds()) answers.
  const Aabb ab = a.bounds();
  if (((ab.min.array() - slack) > b.max.array()).any() || ((ab.max.array() + slack) < b.min.array()).any()) return false;
  // a's face axes
  for (int j = 0; j < 3; ++j) {
    const float rb = absR.col(j).dot(bh);
    if (std::abs(R.col(j).dot(t)) > a.half[j] + rb + slack) return false;
  }
  // cross products of b's axis i with a's axis j
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      const float ra = a.half[j1] * absR(i, j2) + a.half[j2] * absR(i, j1);
      const float rb = bh[i1] * absR(i2, j) + bh[i2] * absR(i1, j);
      const float d = t[i2] * R(i1, j) - t[i1] * R(i2, j);
      if (std::abs(d) > ra + rb + slack) return false;
    }
  }
  return true;
}

}  // namespace

bool overlaps(const Obb& a, const Aabb& b) { return satOverlap(a, b, 0.f); }

bool mayOverlap(const Obb& a, const Aabb& b) {
  // Every quantity the test compares is a sum of a few products of values no larger than the
  // largest coordinate or extent (rotation entries are <= 1); each rounding is half an ulp of
  // that, so 16 ulps of it cover the centre, difference, projection and sum roundings together.
  const float scale = std::max({a.center.cwiseAbs().maxCoeff(), b.min.cwiseAbs().maxCoeff(), b.max.cwiseAbs().maxCoeff(),
                                a.half.maxCoeff()});
  return satOverlap(a, b, scale * (16.f * std::numeric_limits<float>::epsilon()));
}

}  // namespace bw
