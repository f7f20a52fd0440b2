#pragma once
/// Eigen-based scalar and vector types used everywhere in brickworld.
///
/// Precision rule (DESIGN.md): world positions are double (Vec3d), rotations are float
/// quaternions (Quatf), and everything inside a grid or terrain chunk is float in that
/// grid's local frame. The only place that converts between the two is rigid_transform.h.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace bw {

using Vec3f = Eigen::Vector3f;   ///< grid-local / chunk-local position or direction
using Vec3d = Eigen::Vector3d;   ///< world position
using Quatf = Eigen::Quaternionf;///< rotation (unit quaternion)
using Mat3f = Eigen::Matrix3f;
using Mat3d = Eigen::Matrix3d;
using Mat4f = Eigen::Matrix4f;

}  // namespace bw
