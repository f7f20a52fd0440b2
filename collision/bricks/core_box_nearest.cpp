#include "collision/bricks/core_box_nearest.h"

#include <algorithm>
#include <cmath>

namespace bw {

namespace {

// Closest points of segments [p1, q1] and [p2, q2] (the clamped closest points of their lines;
// parallel segments take the first one's start, or its clamp).
void closestOnSegments(const Vec3d& p1, const Vec3d& q1, const Vec3d& p2, const Vec3d& q2, Vec3d& c1, Vec3d& c2) {
  const Vec3d d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0.0, t = 0.0;
  if (a <= 0.0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r), b = d1.dot(d2), denom = a * e - b * b;
    s = denom > 1e-12 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
    t = (b * s + f) / e;
    if (t < 0.0) t = 0.0, s = std::clamp(-c / a, 0.0, 1.0);
    else if (t > 1.0) t = 1.0, s = std::clamp((b - c) / a, 0.0, 1.0);
  }
  c1 = p1 + d1 * s;
  c2 = p2 + d2 * t;
}

// Whether the segment [a, b] meets the box [-h, h] (slab test, ends included).
bool segmentMeetsBox(const Vec3d& a, const Vec3d& b, const Vec3d& h) {
  double t0 = 0.0, t1 = 1.0;
  const Vec3d d = b - a;
  for (int i = 0; i < 3; ++i) {
    if (d[i] == 0.0) {
      if (std::abs(a[i]) > h[i]) return false;
      continue;
    }
    double lo = (-h[i] - a[i]) / d[i], hi = (h[i] - a[i]) / d[i];
    if (lo > hi) std::swap(lo, hi);
    t0 = std::max(t0, lo), t1 = std::min(t1, hi);
    if (t0 > t1) return false;
  }
  return true;
}

}  // namespace

std::optional<CoreBoxNearest> coreBoxNearest(const Vec3f& p0, const Vec3f& p1, const Vec3f& half, const Mat3f& rotation,
                                             const Vec3f& centre) {
  // In the box's frame, in double.
  const Mat3d rt = rotation.cast<double>().transpose();
  const Vec3d h = half.cast<double>(), c = centre.cast<double>();
  const Vec3d a = rt * (p0.cast<double>() - c), b = rt * (p1.cast<double>() - c);
  if (segmentMeetsBox(a, b, h)) return std::nullopt;
  double best2 = INFINITY;
  Vec3d onCore = Vec3d::Zero(), onBox = Vec3d::Zero();
  auto offer = [&](const Vec3d& core, const Vec3d& box) {
    const double d2 = (core - box).squaredNorm();
    if (d2 < best2) best2 = d2, onCore = core, onBox = box;  // ties keep the first offered
  };
  offer(a, a.cwiseMax(-h).cwiseMin(h));
  if (b != a) {
    offer(b, b.cwiseMax(-h).cwiseMin(h));
    for (int k = 0; k < 3; ++k) {  // the 4 edges along axis k
      for (int q = 0; q < 4; ++q) {
        Vec3d from, to;
        from[k] = -h[k], to[k] = h[k];
        const int i = (k + 1) % 3, j = (k + 2) % 3;
        from[i] = to[i] = (q & 1) ? h[i] : -h[i];
        from[j] = to[j] = (q & 2) ? h[j] : -h[j];
        Vec3d core, box;
        closestOnSegments(a, b, from, to, core, box);
        offer(core, box);
      }
    }
  }
  const double distance = std::sqrt(best2);
  const double scale = a.norm() + (b - a).norm() + h.sum();
  if (!(distance > 1e-9 * scale)) return std::nullopt;
  const Mat3d r = rt.transpose();
  return CoreBoxNearest{float(distance), (c + r * onCore).cast<float>(), (c + r * onBox).cast<float>(),
                        (r * ((onCore - onBox) / distance)).cast<float>()};
}

}  // namespace bw
