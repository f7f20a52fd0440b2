#pragma once
/// Bodies that start inside solid (a spawner box overlapping a monument's tower, a crate spawned
/// into a truck's bed): found when the world is built, and either pushed out along the shortest
/// way to free space at a bounded speed (settings.start_in_solid "push_out", the default) or
/// refused with an error naming the spawner or grid (start_in_solid "refuse").
///
/// A body starts in solid when its centre is inside a brick of another grid or a solid terrain
/// voxel, or when its shape overlaps a grid or terrain deeper than half its smallest extent
/// (shallower overlaps are left to the contact solver's capped push-out). The way out: shells
/// of growing radius (x1.3 from a quarter of that extent, out to kMaxDepenetrationSearch),
/// each tried along 26 directions (up first, then the four sideways, down, the 12 edge and 8
/// corner diagonals); in the first shell with a free pose, the first free direction is refined
/// by bisection to the nearest free distance. Free: centre outside solid and no overlap deeper
/// than the solver's slop, and clear of the primitives that stay where they are and of those
/// let go before it. While it moves out the body is a kinematic ghost (it passes through the
/// solid it leaves and through other bodies) and keeps its spawn velocity, so a crate spawned
/// in a moving truck's bed leaves with the truck; then it is dynamic again.
#include <cstdint>

#include "collision/core/math_types.h"

namespace bw {

/// One body on its way out of solid.
struct Depenetration {
  uint32_t body;
  Vec3d remaining;        ///< offset still to travel (m, world)
  Vec3f baseVelocity;     ///< its spawn velocity, kept while it moves out and restored after
  float inverseMass;      ///< saved while the body is kinematic
  Vec3f inverseInertia;
};

/// Farthest a body is searched for free space (m); a body deeper than this in solid is refused.
inline constexpr double kMaxDepenetrationSearch = 1000.0;

}  // namespace bw
