#include "collision/core/rigid_transform.h"

#include "collision/core/argument_checks.h"

namespace bw {

void RigidTransform::validate(const char* context) const {
  requireFinite(translation, context, "translation");
  requireUnitQuaternion(rotation, context, "rotation");
}

}  // namespace bw
