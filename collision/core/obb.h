#pragma once
/// Oriented box in a grid-local (float) frame: centre, half extents, and an orthonormal
/// rotation whose columns are the box axes.
#include "collision/core/aabb.h"

namespace bw {

struct Obb {
  Vec3f center;
  Vec3f half;   ///< half extents along the box axes (>= 0)
  Mat3f axes;   ///< columns are the box's local x, y, z axes

  static Obb fromAabb(const Aabb& b) { return {b.center(), b.halfExtent(), Mat3f::Identity()}; }

  /// Tight axis-aligned bounds.
  Aabb bounds() const {
    const Vec3f r = axes.cwiseAbs() * half;
    return {center - r, center + r};
  }
};

/// Separating-axis test between an OBB and an AABB (15 axes). Closed boxes: touching overlaps.
/// note: edge-edge axes get a small epsilon so near-parallel edges (cross product ~0) can
/// never separate boxes that the face axes say overlap.
bool overlaps(const Obb& a, const Aabb& b);

/// The same test with slack for the float rounding of its own arithmetic (a few ulps of the
/// largest coordinate involved), for culling a tree node: the 15 axes' projections are not
/// monotone in the box, so at 10^6 m a node's tight bounds could test separated while an
/// element inside them tests overlapping (found by the OctoBVH fuzz target: a flat box rotated
/// against a flat element, both at x = -1002816). Never false when overlaps(a, c) is true for
/// some box c inside b.
bool mayOverlap(const Obb& a, const Aabb& b);

}  // namespace bw
