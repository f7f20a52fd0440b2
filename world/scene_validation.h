#pragma once
/// Checks a SceneDescription built in code against the ranges scene files are parsed with
/// (scene_limits in scene_description.h). World's constructor calls it before building
/// anything, so NaN, infinite, zero or negative values, zero-mass dynamic bodies and
/// out-of-range settings are refused with a SceneError naming the field, e.g.
///   scene 'drop': spawners[0].density: expected a number in [0.001, 100000], got 0
#include "world/scene_description.h"

namespace bw {

/// Throws SceneError (scene_file.h) for the first value out of range.
void validateScene(const SceneDescription& scene);

}  // namespace bw
