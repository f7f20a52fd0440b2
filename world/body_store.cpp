#include "world/body_store.h"

#include "collision/core/argument_checks.h"
#include "world/world_tuning.h"

namespace bw {

uint32_t BodyStore::add(const Vec3d& pos, const Quatf& rot, MotionType m, const BodyShape& s, float invMass,
                        const Vec3f& invInertia, const RigidTransform& shapeFrame) {
  requireFinite(pos, "BodyStore::add", "position");
  requireUnitQuaternion(rot, "BodyStore::add", "rotation");
  if (m == MotionType::Dynamic && !(invMass > 0.f && std::isfinite(invMass)))
    throw InvalidInput("BodyStore::add: a dynamic body needs a finite, positive mass");
  requireFinite(invInertia, "BodyStore::add", "inverse inertia");
  position.push_back(pos);
  rotation.push_back(rot.normalized());
  linearVelocity.push_back(Vec3f::Zero());
  angularVelocity.push_back(Vec3f::Zero());
  inverseMass.push_back(m == MotionType::Dynamic ? invMass : 0.f);
  inverseInertia.push_back(m == MotionType::Dynamic ? invInertia : Vec3f::Zero());
  motion.push_back(m);
  shape.push_back(s);
  shapeFromBody.push_back(shapeFrame);
  friction.push_back(tuning::kDefaultFriction);
  return uint32_t(position.size() - 1);
}

}  // namespace bw
