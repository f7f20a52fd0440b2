#include "collision/terrain/chunk_mesher.h"

#include <cstring>

namespace bw {
namespace {

struct FaceDef {
  int dx, dy, dz;         // neighbour direction (= outward normal)
  uint8_t corner[4][3];   // unit-cube corners, counter-clockwise seen from outside
};

// note: each winding was checked with (b - a) x (c - a) == outward normal.
constexpr FaceDef kFaces[6] = {
    {+1, 0, 0, {{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}}},
    {-1, 0, 0, {{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {0, 1, 0}}},
    {0, +1, 0, {{0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0}}},
    {0, -1, 0, {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}}},
    {0, 0, +1, {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}},
    {0, 0, -1, {{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}}},
};

constexpr int kLattice = kChunkSize + 1;  // 9 lattice points per edge

}  // namespace

void meshChunk(const ChunkNeighbourhood& n, float voxelSize, ChunkMesh& out) {
  out.clear();
  out.voxelSize = voxelSize;
  uint16_t vertexOf[kLattice * kLattice * kLattice];
  std::memset(vertexOf, 0xFF, sizeof(vertexOf));
  for (int y = 0; y < kChunkSize; ++y) {
    for (int z = 0; z < kChunkSize; ++z) {
      for (int x = 0; x < kChunkSize; ++x) {
        const Voxel v = n.v[y + 1][z + 1][x + 1];
        if (!v.isSolid()) continue;
        for (const FaceDef& f : kFaces) {
          if (n.v[y + 1 + f.dy][z + 1 + f.dz][x + 1 + f.dx].isSolid()) continue;
          uint16_t q[4];
          for (int k = 0; k < 4; ++k) {
            const int px = x + f.corner[k][0], py = y + f.corner[k][1], pz = z + f.corner[k][2];
            uint16_t& slot = vertexOf[px + kLattice * (pz + kLattice * py)];
            if (slot == 0xFFFF) {
              slot = uint16_t(out.vertices.size());
              out.vertices.push_back({uint8_t(px), uint8_t(py), uint8_t(pz)});
            }
            q[k] = slot;
          }
          out.indices.insert(out.indices.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
          out.materials.push_back(v.material);
          out.materials.push_back(v.material);
        }
      }
    }
  }
}

}  // namespace bw
