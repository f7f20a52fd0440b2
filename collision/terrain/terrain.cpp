#include "collision/terrain/terrain.h"

#include "collision/core/argument_checks.h"

namespace bw {
namespace {

float validatedVoxelSize(float s) {
  requireInRange(s, 1e-3, 1e3, "Terrain", "voxelSize");
  return s;
}

}  // namespace

Terrain::Terrain(const Int3& sizeInVoxels, float voxelSize, const RigidTransform& placement, size_t cacheBudgetBytes)
    : voxels_(sizeInVoxels),
      broadphase_(voxels_.chunkGrid(), voxels_.size()),
      cache_(cacheBudgetBytes),
      voxelSize_(validatedVoxelSize(voxelSize)),
      placement_(placement) {
  placement_.validate("Terrain: placement");
}

void Terrain::setPlacement(const RigidTransform& placement) {
  placement.validate("Terrain::setPlacement: placement");
  placement_ = placement;
  ++changes_;
}

void Terrain::setVoxel(const Int3& v, Voxel voxel) {
  voxels_.set(v, voxel);
  afterEdit(v, v);
}

void Terrain::fillBox(const Int3& lo, const Int3& hi, Voxel voxel) {
  voxels_.fillBox(lo, hi, voxel);
  afterEdit(lo, hi);
}

void Terrain::afterEdit(const Int3& lo, const Int3& hi) {
  broadphase_.rebuildAround(voxels_, lo, hi);
  cache_.invalidateAround(lo, hi);
  ++changes_;
}

RigidTransform Terrain::chunkTransform(const Int3& c) const {
  const double s = double(voxelSize_) * kChunkSize;
  return placement_ * RigidTransform{Vec3d(c.x * s, c.y * s, c.z * s), Quatf::Identity()};
}

Aabb Terrain::worldBoxToLocal(const Vec3d& worldMin, const Vec3d& worldMax) const {
  Aabb b = Aabb::empty();
  for (int k = 0; k < 8; ++k) {
    const Vec3d corner((k & 1) ? worldMax.x() : worldMin.x(), (k & 2) ? worldMax.y() : worldMin.y(),
                       (k & 4) ? worldMax.z() : worldMin.z());
    b.merge(placement_.pointToLocal(corner));
  }
  return b;
}

TerrainOverlap Terrain::overlapWorld(const Vec3d& worldMin, const Vec3d& worldMax) const {
  requireFinite(worldMin, "Terrain::overlapWorld", "worldMin");
  requireFinite(worldMax, "Terrain::overlapWorld", "worldMax");
  return overlapLocal(worldBoxToLocal(worldMin, worldMax));
}

}  // namespace bw
