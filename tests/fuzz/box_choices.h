#pragma once
// Boxes, points and rays chosen from fuzz bytes for the index and grid targets: sizes from
// 0.001 to 10^4 (thin plates among them), placed on lattices of four spacings around anchors
// from the origin to 3*10^7, and now and then a raw float (NaN, infinity, beyond 2^30) or an
// inverted box, so every edit can also be a bad one.
#include <array>

#include "collision/core/aabb.h"
#include "collision/core/ray.h"
#include "fuzz/fuzz_support.h"

namespace bw::fuzz {

inline constexpr std::array<float, 4> kAnchors = {0.f, 1e3f, -1e6f, 3e7f};
inline constexpr std::array<float, 4> kSpacings = {0.05f, 0.5f, 4.f, 64.f};
inline constexpr std::array<float, 9> kHalfSizes = {0.001f, 0.01f, 0.1f, 0.2f, 1.f, 7.f, 40.f, 500.f, 1e4f};

/// A point near one of the anchors (the same anchor for a whole input keeps boxes meeting).
inline Vec3f latticePoint(FuzzInput& in, float anchor) {
  const float step = in.pick(std::span<const float>(kSpacings));
  Vec3f p;
  for (int a = 0; a < 3; ++a) p[a] = anchor + float(int(in.byte()) - 128) * step;
  return p;
}

/// A box around a lattice point; about one in 32 is bad (a raw coordinate or inverted).
inline Aabb fuzzBox(FuzzInput& in, float anchor) {
  const Vec3f c = latticePoint(in, anchor);
  Vec3f h;
  for (int a = 0; a < 3; ++a) h[a] = in.pick(std::span<const float>(kHalfSizes));
  Aabb b{c - h, c + h};
  if (in.below(32) == 0) {
    const int axis = int(in.below(3));
    if (in.flag()) {
      (in.flag() ? b.min : b.max)[axis] = in.rawFloat();
    } else {
      std::swap(b.min[axis], b.max[axis]);
      b.min[axis] += 1.f;  // strictly inverted even for a flat box
    }
  }
  return b;
}

/// Whether an index must accept the box (finite, not inverted, inside +-2^30).
inline bool acceptableBox(const Aabb& b) {
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(b.min[a]) || !std::isfinite(b.max[a]) || b.min[a] > b.max[a]) return false;
    if (std::abs(b.min[a]) >= 1073741824.f || std::abs(b.max[a]) >= 1073741824.f) return false;
  }
  return true;
}

/// A ray from a lattice point in one of 26 lattice directions or a direction from bytes.
inline Ray fuzzRay(FuzzInput& in, float anchor) {
  const Vec3f from = latticePoint(in, anchor);
  Vec3f dir(float(int(in.below(3)) - 1), float(int(in.below(3)) - 1), float(int(in.below(3)) - 1));
  if (dir.isZero() || in.flag()) dir = Vec3f(in.lattice(-1, 1), in.lattice(-1, 1), in.lattice(-1, 1) + 1e-3f);
  const float length = in.flag() ? std::numeric_limits<float>::infinity() : in.lattice(0, 2000);
  return Ray::make(from, dir, length);
}

}  // namespace bw::fuzz
