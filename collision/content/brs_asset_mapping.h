#pragma once
/// How a .brs save's assets and orientations become our shapes and rotations: the procedural
/// ("PB_...") and fixed-shape ("B_...") asset tables, mapAsset resolving one asset name, the
/// folds from our canonical shapes to Brickadia's, and the table of our rotations matching
/// Brickadia's 24 orientations (see "Orientation" and "Shapes" in brs_reader.h). Kept apart from
/// the file format (brs_format.h) and the build step (brs_reader.cpp) because it is a table of
/// facts about the game's assets, not about the bytes. Internal to the reader: the public
/// entry points brsFixedAssets() and brsOrientation() are declared in brs_reader.h.
#include <array>
#include <cstdint>
#include <string>

#include "collision/bricks/brick.h"
#include "collision/core/axis_rotation.h"

namespace bw::brs {

// Our rotation for each Brickadia orientation, indexed direction * 4 + rotation.
const std::array<AxisRotation, 24>& orientationTable();

// Folds from our canonical shapes to Brickadia's (see the header's shape table).
AxisRotation foldMinus90AboutX();
AxisRotation fold180AboutX();

enum class Fold : uint8_t { None, SideWedge, Inverted };

// A 1x1 brick: the stand-in for fixed-shape assets we have no entry for.
inline constexpr uint32_t kUnknownHalfSize[3] = {5, 5, 6};

// How one asset of the file's table turns into our bricks (resolved once per asset, not per brick).
struct AssetMapping {
  BrickShape shape = BrickShape::Box;
  Fold fold = Fold::None;
  uint8_t sides = 12;
  bool procedural = false;  // a known PB_ asset
  bool fixed = false;       // a known B_ asset
  uint32_t fixedHalf[3] = {0, 0, 0};
};

AssetMapping mapAsset(const std::string& name);

}  // namespace bw::brs
