#pragma once
/// Axis-aligned box in a grid-local (float) frame. Closed: touching boxes overlap.
#include <algorithm>
#include <limits>

#include "collision/core/math_types.h"

namespace bw {

struct Aabb {
  Vec3f min;  // 12
  Vec3f max;  // 12

  /// An inverted box that any merge replaces; overlaps nothing.
  static Aabb empty() {
    const float inf = std::numeric_limits<float>::infinity();
    return {Vec3f::Constant(inf), Vec3f::Constant(-inf)};
  }
  static Aabb fromCenterHalf(const Vec3f& c, const Vec3f& h) { return {c - h, c + h}; }

  bool isEmpty() const { return (min.array() > max.array()).any(); }
  Vec3f center() const { return (min + max) * 0.5f; }
  Vec3f extent() const { return max - min; }
  Vec3f halfExtent() const { return (max - min) * 0.5f; }
  float volume() const { return isEmpty() ? 0.f : extent().prod(); }

  void merge(const Aabb& o) {
    min = min.cwiseMin(o.min);
    max = max.cwiseMax(o.max);
  }
  void merge(const Vec3f& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  Aabb expanded(float r) const { return {min.array() - r, max.array() + r}; }
  Aabb expanded(const Vec3f& r) const { return {min - r, max + r}; }

  bool overlaps(const Aabb& o) const {
    return min.x() <= o.max.x() && o.min.x() <= max.x() && min.y() <= o.max.y() && o.min.y() <= max.y() &&
           min.z() <= o.max.z() && o.min.z() <= max.z();
  }
  bool contains(const Aabb& o) const {
    return (min.array() <= o.min.array()).all() && (o.max.array() <= max.array()).all();
  }
  bool contains(const Vec3f& p) const { return (min.array() <= p.array()).all() && (p.array() <= max.array()).all(); }
  bool operator==(const Aabb& o) const { return min == o.min && max == o.max; }
};

}  // namespace bw
