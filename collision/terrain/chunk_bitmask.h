#pragma once
/// Dilated broadphase bitmasks of one chunk (article 001, "Bit broadphase: construction").
///
/// A bit is set when a voxel, or any of its 26 neighbours, is solid (resp. water): whatever
/// geometry a voxel produces can spill into its neighbours, so the dilated mask bounds every
/// triangle the mesher can emit without running the mesher.
///
/// Bit layout, one uint64 per Y slice, 8 bits per X row:
///
///   solid[y]:  bit 63 ............................................ bit 0
///              | row z=7 | row z=6 | ... | row z=1 | row z=0 |
///              each row byte: bit x (x = 0 in the least significant bit)
///
/// so voxel (x, y, z) is bit (z * 8 + x) of solid[y]. 128 bytes per chunk = 2 bits per voxel.
#include <cstdint>

#include "collision/terrain/voxel_terrain.h"

namespace bw {

/// What a chunk's broadphase entry holds; only Masked chunks keep bits.
enum class ChunkMaskKind : uint8_t {
  Empty,     ///< the 10^3 neighbourhood is all air: the chunk is dropped from the broadphase
  AllSolid,  ///< the 10^3 neighbourhood is all solid: touches solid everywhere, no triangles
  AllWater,  ///< the 10^3 neighbourhood is all water: touches water everywhere, no triangles
  Masked,    ///< anything else: the solid and water masks below are meaningful
};

struct ChunkBitmask {
  uint64_t solid[kChunkSize];  // 64  one Y slice per word
  uint64_t water[kChunkSize];  // 64
};
static_assert(sizeof(ChunkBitmask) == 128);

/// Bit of voxel (x, z) inside a Y slice word.
constexpr uint64_t sliceBit(int x, int z) { return uint64_t(1) << (z * 8 + x); }

/// Builds the dilated masks from a 10^3 neighbourhood with bit operations: rows of 10 bits are
/// dilated along X with shifts, then OR-ed with neighbouring rows (Z), then neighbouring
/// slices (Y), and the inner 8^3 bits are kept. Writes `out` only for ChunkMaskKind::Masked.
ChunkMaskKind buildChunkBitmask(const ChunkNeighbourhood& n, ChunkBitmask& out);

}  // namespace bw
