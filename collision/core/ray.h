#pragma once
/// A ray segment in a grid-local (float) frame, with the reciprocal direction precomputed
/// so that slab tests never produce NaN.
#include <cmath>
#include <cstdint>
#include <limits>

#include "collision/core/aabb.h"

namespace bw {

struct Ray {
  Vec3f origin;
  Vec3f dir;       ///< need not be normalised; t is measured in units of |dir|
  float maxT;      ///< +inf for an unlimited ray
  Vec3f invDir;    ///< 1/dir on non-parallel axes, 0 on parallel ones
  uint8_t parallelMask;  ///< bit i set: dir[i] is zero or denormal, the ray never leaves its slab

  /// note: an axis whose 1/dir is not finite (zero or denormal component) is flagged parallel
  /// and tested by containment of the origin instead of (slab - origin) * inf, which is NaN
  /// when the origin lies exactly on the slab plane. A denormal component moves the ray by
  /// < 1e-38 per unit of t, far below float resolution, so treating it as zero is exact
  /// for every representable grid coordinate.
  static Ray make(const Vec3f& origin, const Vec3f& dir, float maxT = std::numeric_limits<float>::infinity()) {
    Ray r{origin, dir, maxT, Vec3f::Zero(), 0};
    for (int i = 0; i < 3; ++i) {
      const float inv = 1.0f / dir[i];
      if (std::isfinite(inv)) {
        r.invDir[i] = inv;
      } else {
        r.parallelMask |= uint8_t(1u << i);
      }
    }
    return r;
  }
  Vec3f at(float t) const { return origin + dir * t; }
};

/// Slab test of a ray segment [tMin, tMax] against a closed box. On a hit returns true and the
/// entry parameter (clamped to tMin, so a ray starting inside reports tMin).
inline bool intersectRayAabb(const Ray& r, const Aabb& b, float tMin, float tMax, float& tEntry) {
  float t0 = tMin, t1 = tMax;
  for (int i = 0; i < 3; ++i) {
    if (r.parallelMask & (1u << i)) {
      if (r.origin[i] < b.min[i] || r.origin[i] > b.max[i]) return false;
      continue;
    }
    float a = (b.min[i] - r.origin[i]) * r.invDir[i];
    float c = (b.max[i] - r.origin[i]) * r.invDir[i];
    if (a > c) std::swap(a, c);
    t0 = a > t0 ? a : t0;
    t1 = c < t1 ? c : t1;
    if (t0 > t1) return false;
  }
  tEntry = t0;
  return true;
}

}  // namespace bw
