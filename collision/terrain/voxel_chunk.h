#pragma once
/// A chunk of 8^3 voxels, the unit of storage, broadphase data and meshing (article 001).
///
/// Voxels are stored Y-slice-major (index = x + 8*z + 64*y), the same order as the
/// broadphase bitmask bits, so a slice of a chunk maps to one uint64 of mask.
#include <cstdint>

#include "collision/terrain/voxel.h"

namespace bw {

/// Voxels per chunk edge (8, as in the article: small edits stay cheap, per-chunk overhead low).
inline constexpr int kChunkSize = 8;
/// log2(kChunkSize): voxel coordinate >> kChunkShift is the chunk coordinate.
inline constexpr int kChunkShift = 3;
/// Voxels per chunk.
inline constexpr int kChunkVoxels = kChunkSize * kChunkSize * kChunkSize;

/// Integer coordinates of a voxel or a chunk.
struct Int3 {
  int32_t x = 0, y = 0, z = 0;
  constexpr bool operator==(const Int3&) const = default;
};

/// Index of voxel (x, y, z) inside a chunk, each in [0, 8).
constexpr int chunkVoxelIndex(int x, int y, int z) { return x + (z << 3) + (y << 6); }

/// Chunk coordinates packed into one 64-bit key: 21 bits per axis, non-negative coordinates.
/// note: terrains are limited to 2^21 chunks (2^24 voxels) per axis, far beyond any world here.
constexpr uint64_t chunkKey(const Int3& c) {
  return uint64_t(uint32_t(c.x)) | (uint64_t(uint32_t(c.y)) << 21) | (uint64_t(uint32_t(c.z)) << 42);
}
/// Inverse of chunkKey.
constexpr Int3 chunkCoordFromKey(uint64_t k) {
  return {int32_t(k & 0x1FFFFF), int32_t((k >> 21) & 0x1FFFFF), int32_t((k >> 42) & 0x1FFFFF)};
}

// note: alignas(4) because VirtualPool keeps its free-list link (a uint32_t) inside free slots;
// a 2-byte-aligned 1030-byte element would put that link at misaligned addresses.
struct alignas(4) VoxelChunk {
  Voxel voxels[kChunkVoxels];  // 1024
  uint16_t nonAirCount = 0;    // 2  chunk is freed when this drops to zero
  uint16_t solidCount = 0;     // 2
  uint16_t waterCount = 0;     // 2
};                             // + 2 padding
static_assert(sizeof(VoxelChunk) == 1032);

}  // namespace bw
