#include "collision/terrain/triangle_contacts.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bw {
namespace {

/// Closest points between segments p0-p1 and q0-q1; returns the point on p0-p1.
Vec3f closestOnSegmentToSegment(const Vec3f& p0, const Vec3f& p1, const Vec3f& q0, const Vec3f& q1) {
  const Vec3f d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const float a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  float s = 0.f, t = 0.f;
  if (a <= 1e-12f) return p0;
  const float c = d1.dot(r);
  if (e <= 1e-12f) {
    s = std::clamp(-c / a, 0.f, 1.f);
  } else {
    const float b = d1.dot(d2), denom = a * e - b * b;
    s = denom > 1e-12f ? std::clamp((b * f - c * e) / denom, 0.f, 1.f) : 0.f;
    t = (b * s + f) / e;
    if (t < 0.f) s = std::clamp(-c / a, 0.f, 1.f);
    else if (t > 1.f) s = std::clamp((b - c) / a, 0.f, 1.f);
  }
  return p0 + d1 * s;
}

}  // namespace

/// Closest point of triangle (a, b, c) to p, by the Voronoi region of p (vertex, edge, face).
Vec3f closestPointOnTriangle(const Vec3f& p, const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  const Vec3f ab = b - a, ac = c - a, ap = p - a;
  const float d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.f && d2 <= 0.f) return a;
  const Vec3f bp = p - b;
  const float d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.f && d4 <= d3) return b;
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.f && d1 >= 0.f && d3 <= 0.f) return a + ab * (d1 / (d1 - d3));
  const Vec3f cp = p - c;
  const float d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.f && d5 <= d6) return c;
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.f && d2 >= 0.f && d6 <= 0.f) return a + ac * (d2 / (d2 - d6));
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0.f && (d4 - d3) >= 0.f && (d5 - d6) >= 0.f) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const float inv = 1.f / (va + vb + vc);
  return a + ab * (vb * inv) + ac * (vc * inv);
}

/// One-sided sphere/triangle contact. `n` is the triangle's unit outward normal.
bool sphereTriangle(const Vec3f& centre, float r, const Vec3f& a, const Vec3f& b, const Vec3f& c, const Vec3f& n,
                    float spec, TriangleContact& out) {
  const float sd = n.dot(centre - a);
  if (sd < -r || sd > r + spec) return false;  // wholly behind the face, or out of reach
  const Vec3f p = closestPointOnTriangle(centre, a, b, c);
  const Vec3f d = centre - p;
  const float dist2 = d.squaredNorm();
  const float tol = 1e-5f * (1.f + centre.cwiseAbs().maxCoeff());
  if (sd <= 0.f || dist2 <= tol * tol) {
    // Centre on or behind the face: a face contact only if it projects inside the triangle,
    // otherwise a neighbouring face of the closed surface owns this contact.
    if ((centre - sd * n - p).squaredNorm() > tol * tol) return false;
    out = {p, n, r - sd};
    return true;
  }
  const float dist = std::sqrt(dist2);
  if (dist > r + spec) return false;
  out = {p, d / dist, r - dist};
  return true;
}

/// Capsule/triangle: both end spheres (two points for a capsule lying on a face); if neither
/// touches, the sphere at the core point closest to the triangle (edge contacts).
int capsuleTriangle(const Vec3f& p0, const Vec3f& p1, float r, const Vec3f& a, const Vec3f& b, const Vec3f& c,
                    const Vec3f& n, float spec, TriangleContact (&out)[2]) {
  int k = 0;
  if (sphereTriangle(p0, r, a, b, c, n, spec, out[k])) ++k;
  if (sphereTriangle(p1, r, a, b, c, n, spec, out[k])) ++k;
  if (k) return k;
  Vec3f bestQ = p0;
  float best = std::numeric_limits<float>::infinity();
  auto consider = [&](const Vec3f& q) {
    const float d = (q - closestPointOnTriangle(q, a, b, c)).squaredNorm();
    if (d < best) best = d, bestQ = q;
  };
  consider(p0);
  consider(p1);
  consider(closestOnSegmentToSegment(p0, p1, a, b));
  consider(closestOnSegmentToSegment(p0, p1, b, c));
  consider(closestOnSegmentToSegment(p0, p1, c, a));
  const float s0 = n.dot(p0 - a), s1 = n.dot(p1 - a);
  if ((s0 < 0.f) != (s1 < 0.f)) consider(p0 + (p1 - p0) * (s0 / (s0 - s1)));  // crossing the plane
  return sphereTriangle(bestQ, r, a, b, c, n, spec, out[0]) ? 1 : 0;
}

}  // namespace bw
