#pragma once
/// The one vocabulary of convex query shapes, for grids (BrickGrid::collide, sweeps), terrain
/// (terrainContacts, terrainWaterContact) and primitive pairs: sphere, box, capsule (its core
/// segment along the local z axis, everywhere) and convex hull (points in its local frame, not
/// owned). A shape is placed by a RigidTransform (world) or a LocalPose (grid-local).
#include <cstdint>

#include "collision/core/aabb.h"

namespace bw {

struct QueryShape {
  enum class Kind : uint8_t { Sphere, Box, Capsule, Hull };
  Kind kind = Kind::Box;
  Vec3f halfExtents = Vec3f::Constant(0.5f);  ///< Box
  float radius = 0.5f;                        ///< Sphere, Capsule
  float halfHeight = 0.5f;                    ///< Capsule: half length of the core segment
  const Vec3f* points = nullptr;              ///< Hull: local points (caller keeps them alive)
  uint32_t pointCount = 0;
  float hullVolume = 0.f;                     ///< Hull: its volume if known (0: computed on demand)
  Vec3f hullHalfExtents = Vec3f::Zero();      ///< Hull: largest |coordinate| of its points per axis (set by hull())

  static QueryShape sphere(float r) { QueryShape s; s.kind = Kind::Sphere; s.radius = r; return s; }
  static QueryShape box(const Vec3f& half) { QueryShape s; s.kind = Kind::Box; s.halfExtents = half; return s; }
  static QueryShape capsule(float r, float halfHeight) {
    QueryShape s; s.kind = Kind::Capsule; s.radius = r; s.halfHeight = halfHeight; return s;
  }
  /// note: the points' bounds are found here, once: a hull's localHalfExtents walked every point
  /// on each grid query (a fifth of carrier_fleet's start, a carrier's hull against its deck).
  static QueryShape hull(const Vec3f* pts, uint32_t n, float volume = 0.f) {
    QueryShape s; s.kind = Kind::Hull; s.points = pts; s.pointCount = n; s.hullVolume = volume;
    for (uint32_t i = 0; i < n; ++i) s.hullHalfExtents = s.hullHalfExtents.cwiseMax(pts[i].cwiseAbs());
    return s;
  }
  /// The same with the points' bounds known already (what hull(pts, n) finds, kept by the caller).
  static QueryShape hull(const Vec3f* pts, uint32_t n, float volume, const Vec3f& halfExtents) {
    QueryShape s; s.kind = Kind::Hull; s.points = pts; s.pointCount = n; s.hullVolume = volume; s.hullHalfExtents = halfExtents;
    return s;
  }

  /// Half extents of the shape's bounds in its own frame.
  Vec3f localHalfExtents() const;
  /// Largest extent (used by the collision LOD: subtrees < fraction x this are solid boxes).
  float size() const { return 2.f * localHalfExtents().maxCoeff(); }
  /// Volume in cubic units (a hull without hullVolume gets its convex hull's volume computed).
  float volume() const;
  /// Throws InvalidInput for non-finite or non-positive sizes, or a hull without points.
  void validate(const char* context) const;
};

/// Volume of the convex hull of `count` points (0 when they are coplanar).
float convexHullVolume(const Vec3f* points, uint32_t count);

}  // namespace bw
