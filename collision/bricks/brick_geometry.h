#pragma once
/// Exact geometry of brick shapes: vertices, face planes, bounds, mass moments, ray clipping.
/// Canonical shapes are described in brick.h; everything here is exact for every shape and
/// rotation (rotations are signed permutations).
#include <cmath>
#include <cstdint>

#include "collision/bricks/brick.h"
#include "collision/core/ray.h"

namespace bw {

constexpr int kMaxBrickVertices = 128;  ///< a 64-sided cylinder
constexpr int kMaxBrickPlanes = 66;

/// Plane n . x <= d bounding a brick's canonical shape (n unit length).
struct BrickPlane {
  Vec3f n;
  float d;
};

/// Vertices of the canonical (unrotated, centred) shape. Returns the count.
int canonicalBrickVertices(const Brick& b, Vec3f* out);
/// Face planes of the canonical shape (the shape is their intersection). Returns the count.
int canonicalBrickPlanes(const Brick& b, BrickPlane* out);
/// Vertices of the part of brick b inside the box `region` (grid frame), relative to the
/// region's centre (computed in double: a brick hundreds of metres long and a small region far
/// from its centre), for GJK on huge bricks: b's vertices inside the region, the region's
/// corners inside b, b's edges through the region's faces and the region's edges through b's
/// faces, duplicates (within 1e-6 of the region's size) dropped. At most maxOut; 0 when they do
/// not meet. For bricks of up to 12 face planes (callers keep bigger cylinders whole).
int clipBrickToBox(const Brick& b, const Aabb& region, Vec3f* out, int maxOut);
/// Vertices in the grid frame (rotated and placed). Returns the count.
int brickVertices(const Brick& b, Vec3f* out);
/// Exact grid-local bounds of the brick's shape.
Aabb brickBounds(const Brick& b);

/// Volume-weighted moments of a shape at density 1: volume, first moment (volume x centroid)
/// and second moment (integral of x x^T), all in the frame they were computed in.
struct ShapeMoments {
  double volume = 0;
  Vec3d first = Vec3d::Zero();
  Mat3d second = Mat3d::Zero();
  void operator+=(const ShapeMoments& o) {
    volume += o.volume;
    first += o.first;
    second += o.second;
  }
  void operator-=(const ShapeMoments& o) {
    volume -= o.volume;
    first -= o.first;
    second -= o.second;
  }
};
/// A running sum of moments as bricks come and go, with Neumaier's compensation on each of its
/// 13 entries. note: a plain sum keeps the rounding of everything it ever held: a 10^4 m slab
/// placed and removed again left 1e-4 of error in a 7e4 mass (the grid-edit fuzz target), and
/// a grid of small bricks that lost its big foundation could be left with any mass at all.
class MomentSum {
 public:
  void add(const ShapeMoments& m) { accumulate(m, 1.0); }
  void subtract(const ShapeMoments& m) { accumulate(m, -1.0); }
  void clear() { sum_ = comp_ = ShapeMoments{}; }
  /// Takes another running sum out of this one (its sum and its compensation): what
  /// subtracting each of its terms would leave, to the same eps^2 of the larger.
  void subtract(const MomentSum& o) {
    accumulate(o.sum_, -1.0);
    accumulate(o.comp_, -1.0);
  }
  /// The sum with its compensation applied.
  ShapeMoments value() const {
    ShapeMoments v = sum_;
    v += comp_;
    return v;
  }

 private:
  // note: Knuth's branch-free two-sum: the same exact rounding error of s + x as Neumaier's
  // ordered form (both exact, so the same bits), without its data-dependent branch (a moment
  // entry's sign and size vary brick to brick: mispredicted half the time on a bulk move).
  static void twoSum(double& s, double& c, double x) {
    const double t = s + x;
    const double xIn = t - s, sIn = t - xIn;
    c += (s - sIn) + (x - xIn);
    s = t;
  }
  void accumulate(const ShapeMoments& m, double sign) {
    twoSum(sum_.volume, comp_.volume, sign * m.volume);
    for (int i = 0; i < 3; ++i) twoSum(sum_.first[i], comp_.first[i], sign * m.first[i]);
    for (int i = 0; i < 9; ++i) twoSum(sum_.second.data()[i], comp_.second.data()[i], sign * m.second.data()[i]);
  }
  ShapeMoments sum_, comp_;
};

/// Moments of the canonical shape (about its box centre, unrotated).
ShapeMoments canonicalBrickMoments(const Brick& b);
/// Moments of the placed brick about `reference` in the grid frame, scaled by density.
ShapeMoments brickMoments(const Brick& b, double density, const Vec3d& reference);
/// The same through the canonical moments and rotation matrix for every shape (brickMoments
/// takes a shortcut for boxes with the same result bits; kept to check that).
ShapeMoments generalBrickMoments(const Brick& b, double density, const Vec3d& reference);

/// Exact ray/brick-shape intersection in the grid frame: entry t within [0, tMax] and the
/// outward normal of the entered face (grid frame). A ray starting inside reports t = 0 and the
/// normal opposing the ray direction.
bool rayBrick(const Brick& b, const Ray& gridRay, float tMax, float& t, Vec3f& normal);

/// True when point p (grid frame) is inside the brick's shape (closed).
bool brickContains(const Brick& b, const Vec3f& p, float tolerance = 0.f);

}  // namespace bw
