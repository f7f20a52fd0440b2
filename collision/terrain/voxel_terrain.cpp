#include "collision/terrain/voxel_terrain.h"

#include <algorithm>
#include <string>

#include "collision/core/argument_checks.h"

namespace bw {
namespace {

uint32_t poolCapacityFor(const Int3& grid) {
  // note: the pool reserves address space only; cap it so a world-sized terrain does not
  // reserve more than 2^24 chunks (16 GB of address space, nothing resident until used).
  const uint64_t total = uint64_t(grid.x) * uint64_t(grid.y) * uint64_t(grid.z);
  return uint32_t(std::min<uint64_t>(total, uint64_t(1) << 24));
}

Int3 chunkGridFor(const Int3& size) {
  return {(size.x + kChunkSize - 1) >> kChunkShift, (size.y + kChunkSize - 1) >> kChunkShift,
          (size.z + kChunkSize - 1) >> kChunkShift};
}

const Int3& validatedSize(const Int3& s) {
  requireInRange(s.x, 1, VoxelTerrain::kMaxSize, "VoxelTerrain", "sizeInVoxels.x");
  requireInRange(s.y, 1, VoxelTerrain::kMaxSize, "VoxelTerrain", "sizeInVoxels.y");
  requireInRange(s.z, 1, VoxelTerrain::kMaxSize, "VoxelTerrain", "sizeInVoxels.z");
  return s;
}

void adjustCounts(VoxelChunk& c, Voxel after, int sign) {
  c.nonAirCount = uint16_t(c.nonAirCount + sign * (after.isAir() ? 0 : 1));
  c.solidCount = uint16_t(c.solidCount + sign * (after.isSolid() ? 1 : 0));
  c.waterCount = uint16_t(c.waterCount + sign * (after.isWater() ? 1 : 0));
}

}  // namespace

VoxelTerrain::VoxelTerrain(const Int3& sizeInVoxels)
    : size_(validatedSize(sizeInVoxels)),
      chunkGrid_(chunkGridFor(size_)),
      pool_(poolCapacityFor(chunkGrid_), "terrain voxel chunks") {}

Voxel VoxelTerrain::get(const Int3& v) const {
  if (!contains(v)) return Voxel{};
  const uint32_t idx = keys_.find(chunkKey({v.x >> kChunkShift, v.y >> kChunkShift, v.z >> kChunkShift}));
  if (idx == kInvalidIndex) return Voxel{};
  return pool_[idx].voxels[chunkVoxelIndex(v.x & 7, v.y & 7, v.z & 7)];
}

const VoxelChunk* VoxelTerrain::chunk(const Int3& c) const {
  if (c.x < 0 || c.y < 0 || c.z < 0 || c.x >= chunkGrid_.x || c.y >= chunkGrid_.y || c.z >= chunkGrid_.z) return nullptr;
  const uint32_t idx = keys_.find(chunkKey(c));
  return idx == kInvalidIndex ? nullptr : &pool_[idx];
}

void VoxelTerrain::set(const Int3& v, Voxel voxel) {
  if (!contains(v)) {
    throw InvalidInput("VoxelTerrain::set: voxel (" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " +
                       std::to_string(v.z) + ") is outside the terrain");
  }
  writeVoxel(v, Voxel::make(voxel.material, voxel.occupancy));
}

void VoxelTerrain::fillBox(const Int3& lo, const Int3& hi, Voxel voxel) {
  if (!contains(lo) || !contains(hi) || lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) {
    throw InvalidInput("VoxelTerrain::fillBox: box [lo, hi] is inverted or leaves the terrain");
  }
  voxel = Voxel::make(voxel.material, voxel.occupancy);
  // One key lookup per chunk, not per voxel: fills of whole layers touch millions of voxels.
  for (int cy = lo.y >> kChunkShift; cy <= hi.y >> kChunkShift; ++cy) {
    for (int cz = lo.z >> kChunkShift; cz <= hi.z >> kChunkShift; ++cz) {
      for (int cx = lo.x >> kChunkShift; cx <= hi.x >> kChunkShift; ++cx) {
        const uint64_t key = chunkKey({cx, cy, cz});
        uint32_t idx = keys_.find(key);
        if (idx == kInvalidIndex) {
          if (voxel.isAir()) continue;
          idx = pool_.allocate();
          keys_.insert(key, idx);
        }
        VoxelChunk& c = pool_[idx];
        const int x0 = std::max(lo.x - cx * kChunkSize, 0), x1 = std::min(hi.x - cx * kChunkSize, kChunkSize - 1);
        const int y0 = std::max(lo.y - cy * kChunkSize, 0), y1 = std::min(hi.y - cy * kChunkSize, kChunkSize - 1);
        const int z0 = std::max(lo.z - cz * kChunkSize, 0), z1 = std::min(hi.z - cz * kChunkSize, kChunkSize - 1);
        for (int y = y0; y <= y1; ++y) {
          for (int z = z0; z <= z1; ++z) {
            for (int x = x0; x <= x1; ++x) {
              Voxel& slot = c.voxels[chunkVoxelIndex(x, y, z)];
              adjustCounts(c, slot, -1);
              slot = voxel;
              adjustCounts(c, slot, +1);
            }
          }
        }
        if (c.nonAirCount == 0) {
          pool_.free(idx);
          keys_.erase(key);
        }
      }
    }
  }
}

void VoxelTerrain::writeVoxel(const Int3& v, Voxel voxel) {
  const uint64_t key = chunkKey({v.x >> kChunkShift, v.y >> kChunkShift, v.z >> kChunkShift});
  uint32_t idx = keys_.find(key);
  if (idx == kInvalidIndex) {
    if (voxel.isAir()) return;
    idx = pool_.allocate();
    keys_.insert(key, idx);
  }
  VoxelChunk& c = pool_[idx];
  Voxel& slot = c.voxels[chunkVoxelIndex(v.x & 7, v.y & 7, v.z & 7)];
  adjustCounts(c, slot, -1);
  slot = voxel;
  adjustCounts(c, slot, +1);
  if (c.nonAirCount == 0) {
    pool_.free(idx);
    keys_.erase(key);
  }
}

void VoxelTerrain::gatherNeighbourhood(const Int3& c, ChunkNeighbourhood& out) const {
  constexpr int N = ChunkNeighbourhood::kSize;
  // Each of the 27 chunks around c contributes one sub-box; look each up once.
  for (int dy = -1; dy <= 1; ++dy) {
    const int y0 = dy < 0 ? 0 : (dy == 0 ? 1 : N - 1), y1 = dy < 0 ? 0 : (dy == 0 ? N - 2 : N - 1);
    for (int dz = -1; dz <= 1; ++dz) {
      const int z0 = dz < 0 ? 0 : (dz == 0 ? 1 : N - 1), z1 = dz < 0 ? 0 : (dz == 0 ? N - 2 : N - 1);
      for (int dx = -1; dx <= 1; ++dx) {
        const int x0 = dx < 0 ? 0 : (dx == 0 ? 1 : N - 1), x1 = dx < 0 ? 0 : (dx == 0 ? N - 2 : N - 1);
        const VoxelChunk* src = chunk({c.x + dx, c.y + dy, c.z + dz});
        for (int y = y0; y <= y1; ++y) {
          for (int z = z0; z <= z1; ++z) {
            for (int x = x0; x <= x1; ++x) {
              // (x - 1) & 7 maps the border cells 0 and 9 onto the neighbour's voxels 7 and 0.
              out.v[y][z][x] = src ? src->voxels[chunkVoxelIndex((x - 1) & 7, (y - 1) & 7, (z - 1) & 7)] : Voxel{};
            }
          }
        }
      }
    }
  }
}

}  // namespace bw
