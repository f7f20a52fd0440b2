#pragma once
/// Update records produced by the transform update and consumed by the render side.
///
/// They carry everything a render proxy needs to move (the fields of the article's
/// per-primitive and per-light transform commands), by value, so a record can be copied into
/// a command queue or an append batch and applied later on another thread.
#include <cstdint>
#include <type_traits>

#include "collision/core/aabb.h"
#include "collision/core/math_types.h"

namespace bw {

/// World-space bounds of a primitive: box centre in double (precision rule), extent in float.
struct WorldBounds {
  Vec3d origin;   // 24  box centre, world
  Vec3f extent;   // 12  box half extent along world axes
  float radius;   //  4  bounding-sphere radius around origin
};
static_assert(sizeof(WorldBounds) == 40);

/// Local-to-world matrix: float 3x3 rotation part and double translation (a 3x4 affine).
struct WorldMatrix {
  Mat3f linear;       // 36  rotation (no scale in brickworld)
  float unused = 0;   //  4  keeps translation 8-byte aligned and the padding defined
  Vec3d translation;  // 24  world position of the local origin
};
static_assert(sizeof(WorldMatrix) == 64);

/// One moved render primitive: what a primitive proxy needs to follow its component.
struct PrimitiveUpdate {
  Quatf previousRotation;     // 16  previous world rotation (motion vectors)
  Vec3d previousTranslation;  // 24  previous world translation
  WorldBounds worldBounds;    // 40
  WorldMatrix localToWorld;   // 64
  Aabb localBounds;           // 24
  uint32_t proxyId;           //  4  index of the proxy in the render scene
  uint32_t unused = 0;        //  4  explicit tail padding
};
static_assert(sizeof(PrimitiveUpdate) == 176, "PrimitiveUpdate is copied once per moved primitive");

/// One moved light: what a light scene entry needs to follow its component.
struct LightUpdate {
  WorldMatrix lightToWorld;  // 64
  Vec3d position;            // 24  world position of the light
  uint32_t lightId;          //  4  index of the light in the render scene
  uint32_t unused = 0;       //  4  explicit tail padding
};
static_assert(sizeof(LightUpdate) == 96, "LightUpdate is copied once per moved light");

static_assert(std::is_trivially_destructible_v<PrimitiveUpdate> && std::is_trivially_destructible_v<LightUpdate>,
              "records are plain values: copied into queues and batches, never destroyed explicitly");

}  // namespace bw
