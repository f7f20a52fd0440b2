#include "collision/terrain/chunk_bitmask.h"

namespace bw {
namespace {

constexpr int N = ChunkNeighbourhood::kSize;

/// Dilates 10x10 rows of 10 bits by one cell in all 27 directions and packs the inner 8^3.
void dilateAndPack(uint16_t (&rows)[N][N], uint64_t (&out)[kChunkSize]) {
  // X: each row OR its shifted copies. Bits 10 and -1 fall outside and are never read.
  for (auto& slice : rows) {
    for (uint16_t& r : slice) r = uint16_t(r | (r << 1) | (r >> 1));
  }
  // Z: only inner rows z = 1..8 are needed from here on.
  uint16_t zDilated[N][kChunkSize];
  for (int y = 0; y < N; ++y) {
    for (int z = 1; z <= kChunkSize; ++z) zDilated[y][z - 1] = uint16_t(rows[y][z - 1] | rows[y][z] | rows[y][z + 1]);
  }
  // Y, then keep bits 1..8 of each row (the chunk's own voxels) as one byte per row.
  for (int y = 1; y <= kChunkSize; ++y) {
    uint64_t slice = 0;
    for (int z = 0; z < kChunkSize; ++z) {
      const uint32_t r = uint32_t(zDilated[y - 1][z] | zDilated[y][z] | zDilated[y + 1][z]);
      slice |= uint64_t((r >> 1) & 0xFFu) << (z * 8);
    }
    out[y - 1] = slice;
  }
}

}  // namespace

ChunkMaskKind buildChunkBitmask(const ChunkNeighbourhood& n, ChunkBitmask& out) {
  uint16_t solid[N][N];
  uint16_t water[N][N];
  int solidCount = 0, waterCount = 0;
  for (int y = 0; y < N; ++y) {
    for (int z = 0; z < N; ++z) {
      uint16_t s = 0, w = 0;
      for (int x = 0; x < N; ++x) {
        const Voxel v = n.v[y][z][x];
        s = uint16_t(s | (uint16_t(v.isSolid()) << x));
        w = uint16_t(w | (uint16_t(v.isWater()) << x));
      }
      solid[y][z] = s;
      water[y][z] = w;
      solidCount += __builtin_popcount(s);
      waterCount += __builtin_popcount(w);
    }
  }
  constexpr int kAll = N * N * N;
  if (solidCount == 0 && waterCount == 0) return ChunkMaskKind::Empty;
  if (solidCount == kAll) return ChunkMaskKind::AllSolid;
  if (waterCount == kAll) return ChunkMaskKind::AllWater;
  dilateAndPack(solid, out.solid);
  dilateAndPack(water, out.water);
  return ChunkMaskKind::Masked;
}

}  // namespace bw
