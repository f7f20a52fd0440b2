#pragma once
/// One terrain voxel: a material and an occupancy, two bytes.
///
/// note: occupancy is the filled fraction in 1/255 units. Solids count as present for
/// collision as soon as occupancy > 0 (the blocky mesher fills the whole cell); for water it
/// is the water level inside the cell, which the buoyancy estimate uses.
#include <cstdint>

namespace bw {

/// Material ids: 0 is air, 1 is water, everything from 2 up is a solid material.
enum : uint8_t {
  kMaterialAir = 0,    ///< empty space
  kMaterialWater = 1,  ///< water: no triangles, only buoyancy contacts
  kMaterialFirstSolid = 2,  ///< first id of the solid materials
};

struct Voxel {
  uint8_t material = kMaterialAir;  // 1
  uint8_t occupancy = 0;            // 1  0..255, fraction of the cell filled

  /// A voxel with the given material; occupancy 0 or material air both normalise to air.
  static constexpr Voxel make(uint8_t material, uint8_t occupancy = 255) {
    return (material == kMaterialAir || occupancy == 0) ? Voxel{} : Voxel{material, occupancy};
  }
  /// True for a solid material with some occupancy: the voxel produces collision geometry.
  constexpr bool isSolid() const { return material >= kMaterialFirstSolid && occupancy != 0; }
  /// True for water with some occupancy: the voxel produces buoyancy.
  constexpr bool isWater() const { return material == kMaterialWater && occupancy != 0; }
  /// True when neither solid nor water.
  constexpr bool isAir() const { return !isSolid() && !isWater(); }
  constexpr bool operator==(const Voxel&) const = default;
};
static_assert(sizeof(Voxel) == 2);

}  // namespace bw
