#pragma once
/// Rigid transform with double translation and float rotation, and the one place where
/// world (double) values are converted into a grid's or chunk's local (float) frame.
///
/// note: conversions subtract the translation in double *before* casting to float, so a grid
/// 1e7 units from the origin resolves local coordinates as finely as one at the origin.
#include "collision/core/aabb.h"
#include "collision/core/obb.h"
#include "collision/core/ray.h"

namespace bw {

struct RigidTransform {
  Vec3d translation = Vec3d::Zero();
  Quatf rotation = Quatf::Identity();

  static RigidTransform identity() { return {}; }

  /// Throws InvalidInput for non-finite translation or a non-unit rotation.
  void validate(const char* context) const;

  // --- world -> local (double in, float out) ---
  Vec3f pointToLocal(const Vec3d& world) const {
    const Vec3d d = world - translation;
    return (rotation.conjugate().cast<double>() * d).cast<float>();
  }
  Vec3f directionToLocal(const Vec3d& world) const {
    return (rotation.conjugate().cast<double>() * world).cast<float>();
  }
  Vec3f directionToLocal(const Vec3f& world) const { return rotation.conjugate() * world; }
  Quatf rotationToLocal(const Quatf& world) const { return rotation.conjugate() * world; }

  // --- local -> world (float in, double out) ---
  Vec3d pointToWorld(const Vec3f& local) const {
    return translation + rotation.cast<double>() * local.cast<double>();
  }
  Vec3f directionToWorld(const Vec3f& local) const { return rotation * local; }

  /// A world-space oriented box (centre in double) as an OBB in this local frame.
  Obb obbToLocal(const Vec3d& worldCenter, const Quatf& worldRotation, const Vec3f& half) const {
    return {pointToLocal(worldCenter), half, rotationToLocal(worldRotation).toRotationMatrix()};
  }
  /// A world ray (origin double) as a local ray; t keeps its meaning because rotations
  /// preserve length.
  Ray rayToLocal(const Vec3d& worldOrigin, const Vec3d& worldDir, float maxT) const {
    return Ray::make(pointToLocal(worldOrigin), directionToLocal(worldDir), maxT);
  }

  /// this * other: apply other first, then this.
  RigidTransform operator*(const RigidTransform& o) const {
    return {translation + rotation.cast<double>() * o.translation, (rotation * o.rotation).normalized()};
  }
  RigidTransform inverse() const {
    const Quatf inv = rotation.conjugate();
    return {-(inv.cast<double>() * translation), inv};
  }
};

}  // namespace bw
