#pragma once
/// Convex shapes that collide against grids and terrain: sphere, box, capsule (along its local
/// z axis) and convex hull (points in its local frame, not owned).
#include <cstdint>

#include "collision/aabb.h"

namespace bw {

struct QueryShape {
  enum class Kind : uint8_t { Sphere, Box, Capsule, Hull };
  Kind kind = Kind::Box;
  Vec3f halfExtents = Vec3f::Constant(0.5f);  ///< Box
  float radius = 0.5f;                        ///< Sphere, Capsule
  float halfHeight = 0.5f;                    ///< Capsule: half length of the core segment
  const Vec3f* points = nullptr;              ///< Hull: local points (caller keeps them alive)
  uint32_t pointCount = 0;

  static QueryShape sphere(float r) { QueryShape s; s.kind = Kind::Sphere; s.radius = r; return s; }
  static QueryShape box(const Vec3f& half) { QueryShape s; s.kind = Kind::Box; s.halfExtents = half; return s; }
  static QueryShape capsule(float r, float halfHeight) {
    QueryShape s; s.kind = Kind::Capsule; s.radius = r; s.halfHeight = halfHeight; return s;
  }
  static QueryShape hull(const Vec3f* pts, uint32_t n) { QueryShape s; s.kind = Kind::Hull; s.points = pts; s.pointCount = n; return s; }

  /// Half extents of the shape's bounds in its own frame.
  Vec3f localHalfExtents() const;
  /// Largest extent (used by the collision LOD: subtrees < fraction x this are solid boxes).
  float size() const { return 2.f * localHalfExtents().maxCoeff(); }
  /// Throws InvalidInput for non-finite or non-positive sizes, or a hull without points.
  void validate(const char* context) const;
};

}  // namespace bw
