#pragma once
/// Narrowphase between a query shape and one brick, in the grid's local frame.
///
/// Method (documented choice): box vs box-shaped brick uses Bullet's btBoxBoxDetector (up to 4
/// points per pair, the common case on brick floors; when they are apart and a speculative
/// margin is asked for, GJK gives the gap); every other pair uses Bullet's GJK/EPA
/// (btGjkEpaSolver2) on the exact brick vertices (one point per pair), with zero margins so
/// contacts are exact. A non-penetrating pair closer than `speculativeMargin` gives one contact
/// with negative depth (the gap), for speculative contacts.
#include <cstdint>
#include <vector>

#include "collision/bricks/brick.h"
#include "collision/bricks/contact.h"
#include "collision/bricks/query_shape.h"

namespace bw {

/// A contact in the grid frame: point on the brick, normal from the brick towards the shape.
struct LocalContact {
  Vec3f position;
  Vec3f normal;
  float depth;       ///< > 0 penetration, < 0 speculative gap
  uint32_t feature;  ///< brick id (or LOD subtree tag)
  uint32_t material;
  /// The part of the query shape the contact holds back: 0 the shape as a whole (GJK/EPA's
  /// deepest point, a box-box manifold point), 1 and 2 a capsule's ends, 1..8 a box's corners.
  /// Across bricks, only the deepest contact of each part 1.. is worth keeping.
  uint8_t shapePart = 0;
};

/// Pose of a query shape in the grid frame.
struct LocalPose {
  Vec3f position;
  Quatf rotation;
};

constexpr int kMaxContactsPerBrick = 4;

/// Appends up to kMaxContactsPerBrick contacts between shape (at pose) and brick b to out.
/// Returns how many were added.
int collideShapeBrick(const QueryShape& shape, const LocalPose& pose, const Brick& b, uint32_t feature,
                      float speculativeMargin, LocalContact* out);

/// Contacts between two convex query shapes (both posed in one frame), GJK/EPA with zero
/// margins; the normal points from b towards a, the point lies on b. Returns the count: 0..1,
/// or up to kMaxContactsPerBrick for two boxes (a face manifold, as against box bricks).
int collideShapes(const QueryShape& a, const LocalPose& poseA, const QueryShape& b, const LocalPose& poseB,
                  float speculativeMargin, LocalContact* out);

/// Time of impact of shape (rotation fixed) moving from `from` to `to` against brick b, as a
/// fraction in [0, 1] of the motion, with the normal (from the brick towards the shape) and the
/// contact point on the brick at impact, by conservative advancement on Bullet's exact GJK distance;
/// a shape already penetrating
/// the brick at `from` hits at fraction 0. False when it never touches.
bool sweepShapeBrick(const QueryShape& shape, const Quatf& rotation, const Vec3f& from, const Vec3f& to, const Brick& b,
                     float& fraction, Vec3f& normal, Vec3f& point);

/// Keeps, for each shape part above 0, only its deepest contact (the one that holds the part
/// back first); contacts of part 0 all stay. Compacts c[0, n) in order; returns the new count.
int keepDeepestPerShapePart(LocalContact* c, int n);

/// Most normal directions a reduced manifold keeps (a floor, a wall, ...).
constexpr int kManifoldNormalGroups = 4;

/// Reduces n contacts in place: grouped by normal direction (within ~25 degrees, at most
/// kManifoldNormalGroups groups in order of their deepest contact; further directions join the
/// nearest group), each group to at most maxOut points (its deepest, the farthest from it, the
/// largest triangle, the largest area added). The kept contacts come first, group by group;
/// returns their count (at most maxOut x kManifoldNormalGroups). Deterministic for a given input
/// order. n <= maxOut: nothing changes.
int reduceManifold(LocalContact* contacts, int n, int maxOut);

/// reduceManifold on world-space contacts out[begin, end) (positions taken relative to the first
/// one's, so far from the origin they keep their float precision); out is cut to the kept ones.
void reduceManifold(std::vector<Contact>& out, size_t begin, int maxOut);

}  // namespace bw
