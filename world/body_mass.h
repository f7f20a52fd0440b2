#pragma once
/// Mass properties of the world's dynamic bodies: primitives of uniform density, and grids in a
/// body frame at their centre of mass along their principal axes.
#include "collision/bricks/brick_grid.h"
#include "collision/bricks/query_shape.h"
#include "collision/core/rigid_transform.h"

namespace bw {

/// Inverse mass (1/kg) and principal inverse inertia (1/(kg m^2), about the shape's own axes:
/// a capsule's core along z) of a sphere, capsule or box of `density` kg/m^3.
void primitiveMass(const QueryShape& shape, float density, float& inverseMass, Vec3f& inverseInertia);

/// A dynamic grid's body frame: where the body sits in the grid's frame (centre of mass,
/// principal axes as a right-handed rotation), its inverse mass and principal inverse inertia.
struct GridBodyFrame {
  RigidTransform bodyInGrid;
  float inverseMass = 0.f;
  Vec3f inverseInertia = Vec3f::Zero();
};
GridBodyFrame gridBodyFrame(const MassProperties& mass);

}  // namespace bw
