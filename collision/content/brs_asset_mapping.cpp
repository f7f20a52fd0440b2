#include "collision/content/brs_asset_mapping.h"

#include <string_view>

#include "collision/content/brs_reader.h"
#include "collision/core/argument_checks.h"

namespace bw::brs {
namespace {

// ---- orientation ----

using IMat = std::array<std::array<int, 3>, 3>;

IMat mul(const IMat& a, const IMat& b) {
  IMat r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) r[i][j] += a[i][k] * b[k][j];
  return r;
}

// D(d): takes local +Z to direction d (rows are output components); see the header.
IMat brsDirectionMatrix(int d) {
  switch (d) {
    case 0: return IMat{{{0, 0, 1}, {0, -1, 0}, {1, 0, 0}}};
    case 1: return IMat{{{0, 0, -1}, {0, 1, 0}, {1, 0, 0}}};
    case 2: return IMat{{{0, 1, 0}, {0, 0, 1}, {1, 0, 0}}};
    case 3: return IMat{{{0, -1, 0}, {0, 0, -1}, {1, 0, 0}}};
    case 4: return IMat{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
    default: return IMat{{{-1, 0, 0}, {0, 1, 0}, {0, 0, -1}}};
  }
}

AxisRotation rotationWithMatrix(const IMat& m) {
  for (int i = 0; i < AxisRotation::kCount; ++i) {
    const AxisRotation r = AxisRotation::fromIndex(i);
    bool same = true;
    for (int row = 0; row < 3 && same; ++row)
      for (int col = 0; col < 3 && same; ++col)
        same = (r.sourceAxis(row) == col ? r.sign(row) : 0) == m[row][col];
    if (same) return r;
  }
  throw InvalidInput("brsOrientation: matrix is not one of the 24 axis rotations");
}

}  // namespace

const std::array<AxisRotation, 24>& orientationTable() {
  static const std::array<AxisRotation, 24> table = [] {
    const IMat rz{{{0, -1, 0}, {1, 0, 0}, {0, 0, 1}}};
    std::array<AxisRotation, 24> t{};
    for (int d = 0; d < 6; ++d) {
      IMat m = brsDirectionMatrix(d);
      for (int r = 0; r < 4; ++r) {
        t[size_t(d * 4 + r)] = rotationWithMatrix(m);
        m = mul(m, rz);
      }
    }
    return t;
  }();
  return table;
}

// Folds from our canonical shapes to Brickadia's (see the header's shape table).
AxisRotation foldMinus90AboutX() { return rotationWithMatrix(IMat{{{1, 0, 0}, {0, 0, 1}, {0, -1, 0}}}); }
AxisRotation fold180AboutX() { return rotationWithMatrix(IMat{{{1, 0, 0}, {0, -1, 0}, {0, 0, -1}}}); }

namespace {

// ---- shapes ----

struct ProceduralAsset {
  std::string_view name;
  BrickShape shape;
  Fold fold;
};

constexpr ProceduralAsset kProcedural[] = {
    {"PB_DefaultBrick", BrickShape::Box, Fold::None},
    {"PB_DefaultTile", BrickShape::Box, Fold::None},
    {"PB_DefaultMicroBrick", BrickShape::Box, Fold::None},
    {"PB_DefaultStudded", BrickShape::Box, Fold::None},
    {"PB_DefaultRampInnerCorner", BrickShape::Box, Fold::None},
    {"PB_DefaultWedge", BrickShape::Wedge, Fold::None},
    {"PB_DefaultRamp", BrickShape::Wedge, Fold::None},
    {"PB_DefaultRampInverted", BrickShape::Wedge, Fold::Inverted},
    {"PB_DefaultSideWedge", BrickShape::Wedge, Fold::SideWedge},
    {"PB_DefaultSideWedgeTile", BrickShape::Wedge, Fold::SideWedge},
    {"PB_DefaultMicroWedge", BrickShape::Wedge, Fold::SideWedge},
    {"PB_DefaultRampCorner", BrickShape::CornerWedge, Fold::None},
    {"PB_DefaultMicroWedgeCorner", BrickShape::CornerWedge, Fold::None},
};

// Half sizes in Brickadia units (10 per stud, 4 per plate) of the fixed-shape assets.
constexpr BrsFixedAsset kFixed[] = {
    // Round and octagonal parts: prisms along local z.
    {"B_1x1_Round", {5, 5, 6}, BrickShape::Cylinder, 16},
    {"B_1x1F_Round", {5, 5, 2}, BrickShape::Cylinder, 16},
    {"B_2x2_Round", {10, 10, 6}, BrickShape::Cylinder, 16},
    {"B_2x2F_Round", {10, 10, 2}, BrickShape::Cylinder, 16},
    {"B_4x4_Round", {20, 20, 6}, BrickShape::Cylinder, 16},
    {"B_1x1_Cone", {5, 5, 6}, BrickShape::Cylinder, 16},
    {"B_2x2_Cone", {10, 10, 12}, BrickShape::Cylinder, 16},
    {"B_Chalice", {5, 5, 10}, BrickShape::Cylinder, 16},
    {"B_1x1F_Octo", {5, 5, 2}, BrickShape::Cylinder, 8},
    {"B_2x2F_Octo", {10, 10, 2}, BrickShape::Cylinder, 8},
    {"B_1x_Octo", {5, 5, 5}, BrickShape::Cylinder, 8},
    {"B_2x_Octo", {10, 10, 10}, BrickShape::Cylinder, 8},
    // Everything else collides as its bounding box.
    {"B_2x2F_Octo_Converter", {10, 10, 2}, BrickShape::Box, 0},
    {"B_2x2F_Octo_Converter_Inv", {10, 10, 2}, BrickShape::Box, 0},
    {"B_1x2f_Plate_Center", {10, 5, 2}, BrickShape::Box, 0},
    {"B_1x2f_Plate_Center_Inv", {10, 5, 2}, BrickShape::Box, 0},
    {"B_2x2f_Plate_Center", {10, 10, 2}, BrickShape::Box, 0},
    {"B_2x2f_Plate_Center_Inv", {10, 10, 2}, BrickShape::Box, 0},
    {"B_1x1_Brick_Side", {5, 5, 6}, BrickShape::Box, 0},
    {"B_1x1_Brick_Side_Lip", {5, 5, 6}, BrickShape::Box, 0},
    {"B_1x4_Brick_Side", {20, 5, 6}, BrickShape::Box, 0},
    {"B_Swirl_Plate", {5, 5, 4}, BrickShape::Box, 0},
    {"B_Handle", {5, 10, 6}, BrickShape::Box, 0},
    {"B_Fern", {10, 10, 2}, BrickShape::Box, 0},
    {"B_Flower", {10, 10, 2}, BrickShape::Box, 0},
    {"B_Small_Flower", {5, 5, 2}, BrickShape::Box, 0},
    {"B_Flame", {5, 5, 10}, BrickShape::Box, 0},
    {"B_Bone", {10, 10, 2}, BrickShape::Box, 0},
    {"B_BoneStraight", {10, 5, 2}, BrickShape::Box, 0},
    {"B_Sausage", {10, 5, 2}, BrickShape::Box, 0},
    {"B_Branch", {20, 11, 2}, BrickShape::Box, 0},
    {"B_Turkey_Body", {15, 10, 7}, BrickShape::Box, 0},
    {"B_Turkey_Leg", {10, 5, 3}, BrickShape::Box, 0},
    {"B_Bush", {15, 15, 16}, BrickShape::Box, 0},
    {"B_Leaf_Bush", {26, 26, 20}, BrickShape::Box, 0},
    {"B_Pine_Tree", {20, 20, 38}, BrickShape::Box, 0},
    {"B_Picket_Fence", {20, 5, 12}, BrickShape::Box, 0},
    {"B_Ladder", {12, 15, 12}, BrickShape::Box, 0},
    {"B_8x8_Lattice_Plate", {40, 40, 2}, BrickShape::Box, 0},
    {"B_SpawnPoint", {20, 20, 2}, BrickShape::Box, 0},
    {"B_CheckPoint", {20, 20, 2}, BrickShape::Box, 0},
    {"B_GoalPoint", {20, 20, 2}, BrickShape::Box, 0},
};

}  // namespace

AssetMapping mapAsset(const std::string& name) {
  AssetMapping m;
  for (const auto& p : kProcedural)
    if (p.name == name) {
      m.shape = p.shape;
      m.fold = p.fold;
      m.procedural = true;
      return m;
    }
  for (const auto& f : kFixed)
    if (name == f.name) {
      m.shape = f.shape;
      m.sides = f.shape == BrickShape::Cylinder ? f.sides : 12;
      m.fixed = true;
      for (int i = 0; i < 3; ++i) m.fixedHalf[i] = f.halfSize[i];
      return m;
    }
  return m;
}

}  // namespace bw::brs

namespace bw {

std::span<const BrsFixedAsset> brsFixedAssets() { return brs::kFixed; }

AxisRotation brsOrientation(int direction, int rotation) {
  if (direction < 0 || direction >= 6 || rotation < 0 || rotation >= 4)
    throw InvalidInput("brsOrientation: direction " + std::to_string(direction) + ", rotation " +
                       std::to_string(rotation) + " (expected 0..5, 0..3)");
  return brs::orientationTable()[size_t(direction * 4 + rotation)];
}

}  // namespace bw
