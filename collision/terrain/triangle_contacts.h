#pragma once
/// Closed-form contacts between round shapes and one terrain triangle, in a chunk's local
/// frame. One-sided: a triangle is a face of a solid, its normal (b - a) x (c - a) points out.
#include "collision/core/math_types.h"

namespace bw {

/// A contact in a chunk's local frame, before conversion to world space.
/// note: not named LocalContact: that is the grid's contact (brick_narrowphase.h), and two
/// classes of one name in namespace bw broke the one-definition rule: the linker kept one
/// copy-assignment for both, and a terrain contact was copied as the larger grid one (40 bytes
/// out of 28: a stack overflow ASan caught when the scene fuzz target first ran quarry).
struct TriangleContact {
  Vec3f point;   ///< on the triangle
  Vec3f normal;  ///< unit, from the terrain towards the shape
  float depth;   ///< > 0 penetration, < 0 speculative gap
};

/// Closest point of triangle (a, b, c) to p, by the Voronoi region of p (vertex, edge, face).
Vec3f closestPointOnTriangle(const Vec3f& p, const Vec3f& a, const Vec3f& b, const Vec3f& c);

/// Sphere (centre, r) against triangle (a, b, c) with unit outward normal n. Reports a contact
/// when the gap is below `spec`. A centre on or behind the face (but less than r behind) gives
/// a face contact along n only if it projects inside the triangle; otherwise a neighbouring
/// face of the closed surface owns that contact.
bool sphereTriangle(const Vec3f& centre, float r, const Vec3f& a, const Vec3f& b, const Vec3f& c, const Vec3f& n,
                    float spec, TriangleContact& out);

/// Capsule with core segment p0-p1 and radius r: the two end spheres (two points for a capsule
/// lying on a face); if neither touches, the sphere at the core point closest to the triangle
/// (edge and crossing contacts). Returns the number of contacts written (0..2).
int capsuleTriangle(const Vec3f& p0, const Vec3f& p1, float r, const Vec3f& a, const Vec3f& b, const Vec3f& c,
                    const Vec3f& n, float spec, TriangleContact (&out)[2]);

}  // namespace bw
