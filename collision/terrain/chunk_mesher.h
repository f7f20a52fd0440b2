#pragma once
/// Turns one chunk's voxels into collision triangles.
///
/// Algorithm: blocky face mesher. Every solid voxel face whose neighbour across the face is
/// not solid (air or water, possibly in a neighbouring chunk, read from the 10^3
/// neighbourhood) becomes one quad = two triangles, wound counter-clockwise seen from outside.
/// Corners sit on the voxel lattice and are shared through a 9^3 lattice-index table, so the
/// mesh has no T-junctions: every edge is shared by faces with opposite directed edges, and
/// the union of all chunk meshes is watertight (each face is emitted by exactly one chunk,
/// the one owning the solid voxel). No geometry leaves the chunk's closed box, which the
/// broadphase's one-voxel dilation bounds conservatively.
/// Faces are not merged: greedy merging would create T-junctions (cracks for rays).
/// Occupancy of solids is not used for shape (any occupancy > 0 fills the cell).
#include "collision/terrain/triangle_mesh.h"
#include "collision/terrain/voxel_terrain.h"

namespace bw {

/// Meshes the chunk at the centre of `n` into `out` (cleared first), positions in chunk-local
/// units of voxelSize. Deterministic: same voxels, same triangles in the same order.
void meshChunk(const ChunkNeighbourhood& n, float voxelSize, ChunkMesh& out);

}  // namespace bw
