#pragma once
/// A body's pose with its rotation's absolute matrix, taken once to carry many grid-local boxes
/// into the world: a box's centre moves with the pose, its half extents go through |R| (the
/// edit wakes and the placement check do this for every edited brick on every holder).
#include "collision/core/aabb.h"
#include "collision/core/rigid_transform.h"
#include "world/broadphase.h"

namespace bw {

struct PoseBoxes {
  RigidTransform pose;
  Mat3f absRotation;

  explicit PoseBoxes(const RigidTransform& p) : pose(p), absRotation(p.rotation.toRotationMatrix().cwiseAbs()) {}
  WorldAabb worldBox(const Aabb& local) const {
    const Vec3d centre = pose.pointToWorld(local.center());
    const Vec3d half = (absRotation * local.halfExtent()).cast<double>();
    return {centre - half, centre + half};
  }
};

}  // namespace bw
