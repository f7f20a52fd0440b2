#include "collision/core/obb.h"

#include <cmath>

namespace bw {

bool overlaps(const Obb& a, const Aabb& b) {
  const Vec3f bc = b.center();
  const Vec3f bh = b.halfExtent();
  const Mat3f& R = a.axes;  // a's axes expressed in b's (world-aligned) frame
  const Vec3f t = a.center - bc;
  Mat3f absR;
  constexpr float eps = 1e-6f;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) absR(i, j) = std::abs(R(i, j)) + eps;

  // b's face axes (world x, y, z)
  for (int i = 0; i < 3; ++i) {
    const float ra = absR.row(i).dot(a.half);
    if (std::abs(t[i]) > ra + bh[i]) return false;
  }
  // a's face axes
  for (int j = 0; j < 3; ++j) {
    const float rb = absR.col(j).dot(bh);
    if (std::abs(R.col(j).dot(t)) > a.half[j] + rb) return false;
  }
  // cross products of b's axis i with a's axis j
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      const float ra = a.half[j1] * absR(i, j2) + a.half[j2] * absR(i, j1);
      const float rb = bh[i1] * absR(i2, j) + bh[i2] * absR(i1, j);
      const float d = t[i2] * R(i1, j) - t[i1] * R(i2, j);
      if (std::abs(d) > ra + rb) return false;
    }
  }
  return true;
}

}  // namespace bw
