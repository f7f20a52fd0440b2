#pragma once
/// The gap between two separated boxes in closed form, for speculative box-box contacts.
///
/// Why: a box within the speculative margin of a box brick but not touching it was measured by
/// Bullet's GJK: ~6,000 instructions a call, 258k calls in 100 frames of ship_refit, half of that
/// scene's contact generation. GJK also stops at its float tolerance: on 4,096 seeded crate-sized
/// pairs (bench_grid BoxGap_*) its gap was off by up to 9.4 cm and its normal by up to 0.64.
///
/// How: the nearest points of two separated boxes are a vertex of one and a point of the other,
/// or points inside two edges. Candidates: the 16 vertices, each against the other box (a clamp
/// in its frame); then, if none is shown nearest, the crossings of edges seen along the axis of
/// largest separation (across a pair of edges: the two edges farthest along it; across a face:
/// the edges of the two faces that face each other). The nearest candidate is the answer when a
/// lower bound meets its distance: the separation along that axis (with the candidate lying
/// along it), or along the candidate's own direction. Exact to double rounding of the inputs,
/// read as orthonormal rotations. nullopt for touching or overlapping boxes, and for a near tie
/// of two axes that picked other edges (none in the 6,500 seeded separated pairs of its test): the caller
/// measures those another way.
#include <optional>

#include "collision/core/math_types.h"

namespace bw {

struct BoxGap {
  float gap;      ///< > 0
  Vec3f onB;      ///< the nearest point of box b
  Vec3f normal;   ///< unit, from b towards a: onB + normal * gap is the nearest point of a
};

/// Two boxes as separatedBoxGap measures them: in b's frame, in double, rotations made
/// orthonormal, with the largest separation along a face axis. That separation is a lower bound
/// on their gap (to double rounding of the inputs): a speculative-contact caller that finds it
/// over its margin needs nothing more, and most box pairs a broadphase hands over are that far.
struct BoxPair {
  Mat3d rb;                  ///< b's rotation
  Mat3d r;                   ///< a's axes in b's frame
  Vec3d c;                   ///< a's centre in b's frame
  Vec3d a, b;                ///< half extents
  Vec3d centreB;
  double scale;              ///< |c| + the half extents' sums: what rounding is relative to
  double faceSeparation;     ///< the largest separation along one of the 6 face axes (<= the gap)
  Vec3d faceDirection;       ///< that axis, from b towards a
};

// Boxes below are given by half extents, rotation (columns: the box's axes) and centre, in one
// frame.

/// True when the 6 face axes, in float, show the boxes farther apart than `distance` by more
/// than 1e-4 of the pair's size (the centre difference's 1-norm + the half extents' sums): far
/// more than float rounding (relative 1e-7 a step) and float rotations' distance from
/// orthonormal (~1e-7) can move a separation, so the boxes' BoxPair::faceSeparation (exact to
/// double rounding of the same inputs) is then over `distance` too. A cheap first test, before
/// a BoxPair is made.
bool boxesFartherApartThan(const Vec3f& halfA, const Mat3f& rotationA, const Vec3f& centreA, const Vec3f& halfB,
                           const Mat3f& rotationB, const Vec3f& centreB, float distance);

BoxPair boxPair(const Vec3f& halfA, const Mat3f& rotationA, const Vec3f& centreA, const Vec3f& halfB, const Mat3f& rotationB,
                const Vec3f& centreB);

std::optional<BoxGap> separatedBoxGap(const BoxPair& pair);

inline std::optional<BoxGap> separatedBoxGap(const Vec3f& halfA, const Mat3f& rotationA, const Vec3f& centreA, const Vec3f& halfB,
                                             const Mat3f& rotationB, const Vec3f& centreB) {
  return separatedBoxGap(boxPair(halfA, rotationA, centreA, halfB, rotationB, centreB));
}

}  // namespace bw
