#pragma once
/// Watertight ray/triangle intersection (Woop, Benthin and Wald, JCGT 2013), two-sided.
///
/// Why not Moller-Trumbore: its edge tests are computed per triangle in a different frame,
/// so a ray through an edge shared by two triangles can miss both; terrain meshes are made
/// of quads and rays along voxel/chunk borders hit those edges exactly. Here the edge
/// functions of a shared edge are computed from the same sheared coordinates in both
/// triangles, with a double-precision recomputation when one is exactly zero, and edges are
/// inclusive, so such a ray hits at least one of the two triangles.
#include <cmath>
#include <cstdint>

#include "collision/core/math_types.h"

namespace bw {

/// Per-ray constants of the watertight test.
struct WatertightRay {
  Vec3f origin;       ///< ray origin
  int kx, ky, kz;     ///< axis permutation: kz is the dominant direction axis
  float sx, sy, sz;   ///< shear constants

  /// Precomputes the shear for a non-zero direction.
  static WatertightRay make(const Vec3f& origin, const Vec3f& dir) {
    WatertightRay r;
    r.origin = origin;
    const Vec3f a = dir.cwiseAbs();
    r.kz = a.x() >= a.y() ? (a.x() >= a.z() ? 0 : 2) : (a.y() >= a.z() ? 1 : 2);
    r.kx = (r.kz + 1) % 3;
    r.ky = (r.kx + 1) % 3;
    // Keep the winding of the sheared triangle independent of the direction's sign.
    if (dir[r.kz] < 0.f) std::swap(r.kx, r.ky);
    r.sx = dir[r.kx] / dir[r.kz];
    r.sy = dir[r.ky] / dir[r.kz];
    r.sz = 1.0f / dir[r.kz];
    return r;
  }

  /// Hit parameter t (in units of |dir|) if the ray hits triangle (a, b, c) at t in
  /// [tMin, tMax]; edges and corners count as hits.
  bool intersect(const Vec3f& a, const Vec3f& b, const Vec3f& c, float tMin, float tMax, float& tHit) const {
    const Vec3f A = a - origin, B = b - origin, C = c - origin;
    const float ax = A[kx] - sx * A[kz], ay = A[ky] - sy * A[kz];
    const float bx = B[kx] - sx * B[kz], by = B[ky] - sy * B[kz];
    const float cx = C[kx] - sx * C[kz], cy = C[ky] - sy * C[kz];
    float u = cx * by - cy * bx;
    float v = ax * cy - ay * cx;
    float w = bx * ay - by * ax;
    if (u == 0.f || v == 0.f || w == 0.f) {
      // note: exact zero means the ray passes (nearly) through an edge; double products of
      // float inputs are exact, so the sign decided here is the same for both triangles.
      u = float(double(cx) * double(by) - double(cy) * double(bx));
      v = float(double(ax) * double(cy) - double(ay) * double(cx));
      w = float(double(bx) * double(ay) - double(by) * double(ax));
    }
    if ((u < 0.f || v < 0.f || w < 0.f) && (u > 0.f || v > 0.f || w > 0.f)) return false;
    const float det = u + v + w;
    if (det == 0.f) return false;  // degenerate or edge-on triangle
    const float t = (u * (sz * A[kz]) + v * (sz * B[kz]) + w * (sz * C[kz])) / det;
    if (!(t >= tMin && t <= tMax)) return false;
    tHit = t;
    return true;
  }
};

}  // namespace bw
