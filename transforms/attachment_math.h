#pragma once
/// The arithmetic of attachment transforms, shared by the SoA update, the object-style
/// baseline and the serial test reference.
///
/// note: every path calls these same inline functions (and the build uses -ffp-contract=off),
/// so all three produce bit-identical records; that is what the differential tests rely on.
#include "collision/core/aabb.h"
#include "transforms/transform_records.h"

namespace bw {

/// World pose of a child from its parent's world pose and its local offset (float, in the
/// parent's frame); composed in double so offsets stay exact far from the origin.
inline void composeAttachmentPose(const Vec3d& parentTranslation, const Quatf& parentRotation,
                                  const Vec3f& localTranslation, const Quatf& localRotation,
                                  Vec3d& worldTranslation, Quatf& worldRotation) {
  worldTranslation = parentTranslation + parentRotation.cast<double>() * localTranslation.cast<double>();
  worldRotation = (parentRotation * localRotation).normalized();
}

/// Local-to-world matrix of a world pose.
inline WorldMatrix makeWorldMatrix(const Vec3d& translation, const Quatf& rotation) {
  WorldMatrix m;
  m.linear = rotation.toRotationMatrix();
  m.translation = translation;
  return m;
}

/// World bounds of a local box under a local-to-world matrix (box of the rotated box). An empty
/// local box (a hidden primitive: a render chunk whose bricks were all removed) gives a point
/// at the local origin with zero extent and radius, never the infinities of its corners.
inline WorldBounds makeWorldBounds(const Aabb& local, const WorldMatrix& m) {
  if (local.isEmpty()) return WorldBounds{m.translation, Vec3f::Zero(), 0.f};
  const Vec3f c = local.center();
  const Vec3f h = local.halfExtent();
  WorldBounds b;
  b.origin = m.translation + (m.linear * c).cast<double>();
  b.extent = m.linear.cwiseAbs() * h;
  b.radius = h.norm();
  return b;
}

/// The full primitive record for one moved primitive.
inline PrimitiveUpdate makePrimitiveUpdate(uint32_t proxyId, const Aabb& localBounds, const Vec3d& translation,
                                           const Quatf& rotation, const Vec3d& previousTranslation,
                                           const Quatf& previousRotation) {
  PrimitiveUpdate u;
  u.previousRotation = previousRotation;
  u.previousTranslation = previousTranslation;
  u.localToWorld = makeWorldMatrix(translation, rotation);
  u.worldBounds = makeWorldBounds(localBounds, u.localToWorld);
  u.localBounds = localBounds;
  u.proxyId = proxyId;
  return u;
}

/// The full light record for one moved light.
inline LightUpdate makeLightUpdate(uint32_t lightId, const Vec3d& translation, const Quatf& rotation) {
  LightUpdate u;
  u.lightToWorld = makeWorldMatrix(translation, rotation);
  u.position = translation;
  u.lightId = lightId;
  return u;
}

}  // namespace bw
