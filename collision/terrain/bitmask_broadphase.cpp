#include "collision/terrain/bitmask_broadphase.h"

#include <algorithm>
#include <cmath>

namespace bw {
namespace {

constexpr SliceMaskTables makeTables() {
  SliceMaskTables t{};
  for (int a = 0; a < kChunkSize; ++a) {
    for (int b = 0; b < kChunkSize; ++b) {
      uint64_t row = 0, rows = 0;
      for (int i = a; i <= b; ++i) {
        row |= uint64_t(1) << i;
        rows |= uint64_t(0xFF) << (i * 8);
      }
      t.xRange[a][b] = row * 0x0101010101010101ull;  // replicate the row byte into all 8 rows
      t.zRange[a][b] = rows;
    }
  }
  return t;
}
constexpr SliceMaskTables kTables = makeTables();

uint32_t poolCapacityFor(const Int3& grid) {
  const uint64_t total = uint64_t(grid.x) * uint64_t(grid.y) * uint64_t(grid.z);
  return uint32_t(std::min<uint64_t>(total, uint64_t(1) << 24));
}

}  // namespace

const SliceMaskTables& sliceMaskTables() { return kTables; }

BitmaskBroadphase::BitmaskBroadphase(const Int3& chunkGrid, const Int3& sizeInVoxels)
    : chunkGrid_(chunkGrid), size_(sizeInVoxels), masks_(poolCapacityFor(chunkGrid), "terrain chunk bitmasks") {}

void BitmaskBroadphase::setEntry(const Int3& c, ChunkMaskKind kind, const ChunkBitmask& bits) {
  const uint64_t key = chunkKey(c);
  const uint32_t old = entries_.find(key);
  const bool hadMask = old != kInvalidIndex && old != kTagAllSolid && old != kTagAllWater;
  switch (kind) {
    case ChunkMaskKind::Empty:
      if (hadMask) masks_.free(old);
      entries_.erase(key);
      return;
    case ChunkMaskKind::AllSolid:
    case ChunkMaskKind::AllWater:
      if (hadMask) masks_.free(old);
      entries_.insert(key, kind == ChunkMaskKind::AllSolid ? kTagAllSolid : kTagAllWater);
      return;
    case ChunkMaskKind::Masked: {
      const uint32_t idx = hadMask ? old : masks_.allocate();
      masks_[idx] = bits;
      entries_.insert(key, idx);
      return;
    }
  }
}

void BitmaskBroadphase::rebuildChunk(const VoxelTerrain& terrain, const Int3& c) {
  if (c.x < 0 || c.y < 0 || c.z < 0 || c.x >= chunkGrid_.x || c.y >= chunkGrid_.y || c.z >= chunkGrid_.z) return;
  ChunkNeighbourhood n;
  terrain.gatherNeighbourhood(c, n);
  ChunkBitmask bits;
  const ChunkMaskKind kind = buildChunkBitmask(n, bits);
  setEntry(c, kind, bits);
}

void BitmaskBroadphase::rebuildAround(const VoxelTerrain& terrain, const Int3& lo, const Int3& hi) {
  // A voxel belongs to the 10^3 neighbourhood of every chunk within one voxel of it.
  const Int3 clo{std::max((lo.x - 1) >> kChunkShift, 0), std::max((lo.y - 1) >> kChunkShift, 0),
                 std::max((lo.z - 1) >> kChunkShift, 0)};
  const Int3 chi{std::min((hi.x + 1) >> kChunkShift, chunkGrid_.x - 1), std::min((hi.y + 1) >> kChunkShift, chunkGrid_.y - 1),
                 std::min((hi.z + 1) >> kChunkShift, chunkGrid_.z - 1)};
  for (int y = clo.y; y <= chi.y; ++y) {
    for (int z = clo.z; z <= chi.z; ++z) {
      for (int x = clo.x; x <= chi.x; ++x) rebuildChunk(terrain, {x, y, z});
    }
  }
}

void BitmaskBroadphase::rebuildAll(const VoxelTerrain& terrain) {
  entries_.clear();
  masks_.forEachLive([&](uint32_t i) { masks_.free(i); });
  // Candidates: every chunk next to a stored chunk. The key map doubles as a visited set.
  ChunkKeyMap candidates;
  terrain.forEachChunk([&](const Int3& c, const VoxelChunk&) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dz = -1; dz <= 1; ++dz) {
        for (int dx = -1; dx <= 1; ++dx) {
          const Int3 n{c.x + dx, c.y + dy, c.z + dz};
          if (n.x < 0 || n.y < 0 || n.z < 0 || n.x >= chunkGrid_.x || n.y >= chunkGrid_.y || n.z >= chunkGrid_.z) continue;
          candidates.insert(chunkKey(n), 0);
        }
      }
    }
  });
  candidates.forEach([&](uint64_t key, uint32_t) { rebuildChunk(terrain, chunkCoordFromKey(key)); });
}

bool BitmaskBroadphase::voxelRangeOf(const Aabb& b, float voxelSize, VoxelRange& out) const {
  const double inv = 1.0 / double(voxelSize);
  const int size[3] = {size_.x, size_.y, size_.z};
  for (int i = 0; i < 3; ++i) {
    // Floor first, then expand by one whole voxel: (min - voxelSize) in float would round.
    // note: clamping in double before the int conversion keeps huge coordinates from overflowing.
    const double lo = std::floor(double(b.min[i]) * inv) - 1.0;
    const double hi = std::floor(double(b.max[i]) * inv) + 1.0;
    if (!(lo <= hi) || hi < 0.0 || lo > double(size[i] - 1)) return false;
    (&out.lo.x)[i] = int(std::max(lo, 0.0));
    (&out.hi.x)[i] = int(std::min(hi, double(size[i] - 1)));
  }
  return true;
}

TerrainOverlap BitmaskBroadphase::testEntry(uint32_t e, const ChunkBitmask* m, const Int3& lo, const Int3& hi) {
  if (e == kTagAllSolid) return {true, false};
  if (e == kTagAllWater) return {false, true};
  const uint64_t mask = kTables.xRange[lo.x][hi.x] & kTables.zRange[lo.z][hi.z];
  uint64_t solid = 0, water = 0;
  for (int y = lo.y; y <= hi.y; ++y) {
    solid |= m->solid[y] & mask;
    water |= m->water[y] & mask;
  }
  return {solid != 0, water != 0};
}

TerrainOverlap BitmaskBroadphase::overlapRange(const VoxelRange& r) const {
  TerrainOverlap result;
  for (int cy = r.lo.y >> kChunkShift; cy <= r.hi.y >> kChunkShift; ++cy) {
    for (int cz = r.lo.z >> kChunkShift; cz <= r.hi.z >> kChunkShift; ++cz) {
      for (int cx = r.lo.x >> kChunkShift; cx <= r.hi.x >> kChunkShift; ++cx) {
        const uint32_t e = entries_.find(chunkKey({cx, cy, cz}));
        if (e == kInvalidIndex) continue;
        const Int3 lo{std::max(r.lo.x - cx * kChunkSize, 0), std::max(r.lo.y - cy * kChunkSize, 0),
                      std::max(r.lo.z - cz * kChunkSize, 0)};
        const Int3 hi{std::min(r.hi.x - cx * kChunkSize, kChunkSize - 1), std::min(r.hi.y - cy * kChunkSize, kChunkSize - 1),
                      std::min(r.hi.z - cz * kChunkSize, kChunkSize - 1)};
        const ChunkBitmask* m = (e == kTagAllSolid || e == kTagAllWater) ? nullptr : &masks_[e];
        const TerrainOverlap o = testEntry(e, m, lo, hi);
        result.solid |= o.solid;
        result.water |= o.water;
        if (result.solid && result.water) return result;  // nothing more to learn
      }
    }
  }
  return result;
}

TerrainOverlap BitmaskBroadphase::overlap(const Aabb& localBox, float voxelSize) const {
  VoxelRange r;
  if (!voxelRangeOf(localBox, voxelSize, r)) return {};
  return overlapRange(r);
}

ChunkMaskKind BitmaskBroadphase::kind(const Int3& c) const {
  const uint32_t e = entries_.find(chunkKey(c));
  if (e == kInvalidIndex) return ChunkMaskKind::Empty;
  if (e == kTagAllSolid) return ChunkMaskKind::AllSolid;
  if (e == kTagAllWater) return ChunkMaskKind::AllWater;
  return ChunkMaskKind::Masked;
}

const ChunkBitmask* BitmaskBroadphase::masks(const Int3& c) const {
  const uint32_t e = entries_.find(chunkKey(c));
  if (e == kInvalidIndex || e == kTagAllSolid || e == kTagAllWater) return nullptr;
  return &masks_[e];
}

}  // namespace bw
