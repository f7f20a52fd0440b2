#pragma once
/// Indexed triangle meshes as the kD tree and the queries see them: chunk meshes with 16-bit
/// indices and 3-byte lattice vertices (a blocky chunk's corners are voxel lattice points,
/// at most 9^3 of them), and large float meshes with 32-bit indices, behind one read-only view.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "collision/core/math_types.h"

namespace bw {

/// A chunk-local vertex on the voxel lattice: integer coordinates 0..8, scaled by the voxel
/// size when read. 3 bytes instead of 12, and exact (the blocky mesher only emits lattice points).
struct LatticePoint {
  uint8_t x, y, z;  // 3
  constexpr bool operator==(const LatticePoint&) const = default;
};
static_assert(sizeof(LatticePoint) == 3);

/// Read-only view of an indexed triangle mesh. Exactly one of indices16 / indices32 is set, and
/// exactly one of vertices (float) / lattice (LatticePoint * latticeScale).
struct TriangleMeshView {
  const Vec3f* vertices = nullptr;      ///< float vertex positions, or null
  const uint16_t* indices16 = nullptr;  ///< 3 per triangle, or null
  const uint32_t* indices32 = nullptr;  ///< 3 per triangle, or null
  uint32_t vertexCount = 0;             ///< number of vertices
  uint32_t triangleCount = 0;           ///< number of triangles
  const LatticePoint* lattice = nullptr;  ///< lattice vertex positions, or null
  float latticeScale = 1.f;             ///< position = lattice point * latticeScale

  /// Vertex index k (0..2) of triangle t.
  uint32_t index(uint32_t t, int k) const {
    return indices16 ? uint32_t(indices16[3 * t + k]) : indices32[3 * t + k];
  }
  /// Position of vertex i.
  Vec3f vertex(uint32_t i) const {
    if (vertices) return vertices[i];
    const LatticePoint& p = lattice[i];
    return Vec3f(float(p.x) * latticeScale, float(p.y) * latticeScale, float(p.z) * latticeScale);
  }
  /// The three corners of triangle t.
  void corners(uint32_t t, Vec3f& a, Vec3f& b, Vec3f& c) const {
    a = vertex(index(t, 0));
    b = vertex(index(t, 1));
    c = vertex(index(t, 2));
  }
};

/// A chunk's triangles: 3 bytes per vertex, 6 bytes of indices and 1 byte of material per
/// triangle. Winding is counter-clockwise seen from outside the solid, so
/// (b - a) x (c - a) points out of the terrain.
struct ChunkMesh {
  std::vector<LatticePoint> vertices;  ///< chunk-local lattice points (origin at the chunk's min corner)
  std::vector<uint16_t> indices;       ///< 3 per triangle
  std::vector<uint8_t> materials;      ///< 1 per triangle: the solid voxel's material id
  float voxelSize = 1.f;               ///< lattice spacing: position = point * voxelSize

  /// Number of triangles.
  uint32_t triangleCount() const { return uint32_t(materials.size()); }
  /// Chunk-local position of vertex i.
  Vec3f vertex(uint32_t i) const { return view().vertex(i); }
  /// Chunk-local position of corner k (0..2) of triangle t.
  Vec3f corner(uint32_t t, int k) const { return vertex(indices[3 * t + k]); }
  /// View for the kD tree and queries (valid until the mesh changes).
  TriangleMeshView view() const {
    TriangleMeshView v;
    v.indices16 = indices.data();
    v.vertexCount = uint32_t(vertices.size());
    v.triangleCount = triangleCount();
    v.lattice = vertices.data();
    v.latticeScale = voxelSize;
    return v;
  }
  /// Heap bytes in use (sizes, not capacities: what a tight copy would cost).
  size_t bytes() const { return vertices.size() * sizeof(LatticePoint) + indices.size() * 2 + materials.size(); }
  /// Empties the mesh, keeping capacity for reuse.
  void clear() {
    vertices.clear();
    indices.clear();
    materials.clear();
  }
};

}  // namespace bw
