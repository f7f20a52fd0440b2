#pragma once
/// Bodies in structure-of-arrays form: one vector per field, indexed by body id.
///
/// A body's frame is its centre of mass with principal axes; `position`/`rotation` are that
/// frame in the world (double position, float rotation). Its collision shape (a primitive or a
/// brick grid) sits at `shapeFromBody` inside that frame. Static bodies have zero inverse mass;
/// kinematic ones too, but move with their scripted velocities.
#include <cstdint>
#include <vector>

#include "collision/bricks/query_shape.h"
#include "collision/core/ids.h"
#include "collision/core/rigid_transform.h"
#include "world/scene_description.h"

namespace bw {

/// What collides for a body: a primitive, a brick grid or a voxel terrain (indices into the
/// world's grids and terrains).
struct BodyShape {
  QueryShape primitive;             ///< used when neither grid nor terrain is set
  uint32_t grid = kInvalidIndex;
  uint32_t terrain = kInvalidIndex;
  bool isGrid() const { return grid != kInvalidIndex; }
  bool isTerrain() const { return terrain != kInvalidIndex; }
};

/// Every body of a world, one array per field (index = body id). SI units: metres, seconds,
/// kilograms, radians.
struct BodyStore {
  std::vector<Vec3d> position;            ///< m, world: a dynamic body's centre of mass, else its shape's origin
  std::vector<Quatf> rotation;            ///< world orientation of the body frame (principal axes for dynamic grids)
  std::vector<Vec3f> linearVelocity;      ///< m/s, world
  std::vector<Vec3f> angularVelocity;     ///< rad/s, world frame
  std::vector<float> inverseMass;         ///< 1/kg; 0 for static and kinematic bodies
  std::vector<Vec3f> inverseInertia;      ///< 1/(kg m^2), principal, body frame; 0 when not dynamic
  std::vector<MotionType> motion;
  std::vector<BodyShape> shape;
  std::vector<RigidTransform> shapeFromBody;  ///< the shape's frame expressed in the body frame
  std::vector<float> friction;            ///< Coulomb coefficient; a pair uses sqrt(fa * fb)

  uint32_t size() const { return uint32_t(position.size()); }
  /// Appends a body; returns its id.
  uint32_t add(const Vec3d& pos, const Quatf& rot, MotionType m, const BodyShape& s, float invMass, const Vec3f& invInertia,
               const RigidTransform& shapeFrame = RigidTransform{});
  /// World pose of the body's collision shape.
  RigidTransform shapePose(uint32_t i) const { return RigidTransform{position[i], rotation[i]} * shapeFromBody[i]; }
  /// How the body moves through the world: a static body stays put whatever velocity it was
  /// given; an asleep one moves with the velocity it fell asleep with (its carrier's).
  Vec3f movingLinear(uint32_t i) const { return motion[i] == MotionType::Static ? Vec3f::Zero() : linearVelocity[i]; }
  Vec3f movingAngular(uint32_t i) const { return motion[i] == MotionType::Static ? Vec3f::Zero() : angularVelocity[i]; }
  /// Whether the body moves through the world / turns (exactly: any component not zero).
  bool translates(uint32_t i) const { return !(movingLinear(i).array() == 0.f).all(); }
  bool turns(uint32_t i) const { return !(movingAngular(i).array() == 0.f).all(); }
  /// Whether two bodies move alike: the same translation and no turn (two bodies turning alike
  /// about their own centres still move apart), so their relative pose stays as it is.
  bool movesAlike(uint32_t a, uint32_t b) const { return movingLinear(a) == movingLinear(b) && !turns(a) && !turns(b); }
  /// World-frame inverse inertia tensor.
  Mat3f inverseInertiaWorld(uint32_t i) const {
    const Mat3f R = rotation[i].toRotationMatrix();
    return R * inverseInertia[i].asDiagonal() * R.transpose();
  }
};

}  // namespace bw
