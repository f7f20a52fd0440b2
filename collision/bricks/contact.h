#pragma once
/// Contact points produced by every narrowphase in brickworld (grids, terrain, primitives).
#include <cstdint>

#include "collision/core/math_types.h"

namespace bw {

/// One contact point between a query shape A and a static-structure shape B (a brick, a
/// terrain triangle, another body).
/// Convention: `normal` is a unit vector in world space pointing from B towards A (the
/// direction A must move to separate); `depth` > 0 means penetration, < 0 a speculative gap.
/// `position` is the world-space point on B's surface (double, per the precision rule).
struct Contact {
  Vec3d position;     // 24
  Vec3f normal;       // 12
  float depth;        // 4
  uint32_t featureB;  // 4  brick / triangle index on B, stable across frames (for warm starting)
  uint32_t material;  // 4  B's material id
};

}  // namespace bw
