#pragma once
/// Read-only SoA view of body poses handed to the transform update.
///
/// The world keeps bodies as SoA (positions, rotations, flags); this view is how the
/// transform stage reads them without knowing the world's containers. Pointers are borrowed
/// for the duration of one update call.
#include <cstdint>

#include "collision/core/math_types.h"

namespace bw {

/// Body positions (double, world), rotations (float) and a moved flag per body.
struct BodyPoseView {
  const Vec3d* position = nullptr;  ///< count entries, world space (double: precision rule)
  const Quatf* rotation = nullptr;  ///< count entries, unit quaternions
  const uint8_t* moved = nullptr;   ///< count entries, 1 = pose changed since the last update
  uint32_t count = 0;               ///< number of bodies
};

}  // namespace bw
