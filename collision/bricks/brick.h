#pragma once
/// A brick: one convex shape of a grid, in the grid's local (float) frame.
///
/// Shapes (canonical, before rotation, inside the box [-halfSize, +halfSize]):
/// - Box.
/// - Wedge (ramp): the bottom face (z = -h.z) is the full rectangle; the top edge runs along y at
///   x = -h.x, z = +h.z; the slope faces +x and up.
/// - CornerWedge: the bottom face is the full rectangle; a single apex at (-h.x, -h.y, +h.z).
/// - Cylinder: a prism along z whose cross-section is a regular N-gon inscribed in the ellipse
///   of radii (h.x, h.y), with vertices at angles 2*pi*k/N (N = `sides`, 3..64).
/// `rotation` (one of the 24 axis-aligned rotations) then turns the shape about its centre, and
/// `position` places the centre. Every shape reaches all six faces of its box when N is a
/// multiple of 4, so its local AABB is the rotated box; brickBounds() computes it exactly for
/// any N.
#include <cstdint>

#include "collision/core/aabb.h"
#include "collision/core/axis_rotation.h"

namespace bw {

enum class BrickShape : uint8_t { Box = 0, Wedge = 1, CornerWedge = 2, Cylinder = 3 };

struct Brick {
  Vec3f position;         // 12  centre, grid-local
  Vec3f halfSize;         // 24  half extents of the canonical shape (> 0)
  uint32_t filter = 1;    // 28  collision filter bits
  uint8_t material = 0;   // 29  material id (density and friction tables live in the world)
  AxisRotation rotation;  // 30
  BrickShape shape = BrickShape::Box;  // 31
  uint8_t sides = 12;     // 32  cylinder sides (ignored by other shapes)

  /// An unrotated box brick.
  static Brick box(const Vec3f& position, const Vec3f& halfSize) {
    Brick b;
    b.position = position;
    b.halfSize = halfSize;
    return b;
  }
};
static_assert(sizeof(Brick) == 32, "bricks are 32 bytes in their pool");

/// Smallest and largest brick half size accepted by grids (0.002 .. 2^28 units).
constexpr float kMinBrickHalfSize = 0.002f;
constexpr float kMaxBrickHalfSize = 268435456.f;

/// Throws InvalidInput naming `context` and the field when a brick is not valid: non-finite
/// values, half sizes outside [kMinBrickHalfSize, kMaxBrickHalfSize], an unknown shape, or a
/// cylinder with fewer than 3 or more than 64 sides.
void validateBrick(const Brick& b, const char* context);

}  // namespace bw
