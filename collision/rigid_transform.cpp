#include "collision/rigid_transform.h"

#include "collision/input_validation.h"

namespace bw {

void RigidTransform::validate(const char* context) const {
  requireFinite(translation, context, "translation");
  requireUnitQuaternion(rotation, context, "rotation");
}

}  // namespace bw
