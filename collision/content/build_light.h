#pragma once
/// A light that belongs to a build: where a save's light component or a generator puts one.
///
/// Lights ride on their grid: the world gives each one a render light attached to the grid's
/// body, so a moving ship carries its running lights. Units and frame are the build's (grid
/// local, Z up, our units: one stud = 0.4).
#include <cstdint>

#include "collision/core/math_types.h"

namespace bw {

/// Kind of a build light (what a renderer would make of it).
enum class BuildLightKind : uint8_t { Point = 0, Spot = 1 };

/// One light of a build (grid-local).
struct BuildLight {
  Vec3f position = Vec3f::Zero();  ///< grid-local position (a save: its brick's centre)
  float radius = 1.f;              ///< attenuation radius in our units (> 0)
  BuildLightKind kind = BuildLightKind::Point;
};

}  // namespace bw
