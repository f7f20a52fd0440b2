#pragma once
/// The render thread's scene: primitive proxies and lights, stored SoA by render id.
///
/// Owned by the render thread: only it applies updates. Every update overwrites the whole
/// state of one proxy or light (no accumulation), and each id is updated at most once per
/// frame, so the order in which a frame's updates arrive does not change the final state.
/// That is why per-object and batched submission can end in byte-identical scenes.
/// Each field is its own array of padding-free values, so "byte-identical" is well defined:
/// identicalTo() compares the arrays with memcmp and stateHash() hashes the same bytes.
#include <cstdint>
#include <vector>

#include "collision/core/aabb.h"
#include "collision/core/math_types.h"
#include "transforms/transform_records.h"

namespace bw {

/// Primitive proxies and lights of the render side (see file comment).
class RenderScene {
 public:
  /// primitiveCount proxies at the origin; one light per attenuation radius (radius > 0).
  RenderScene(uint32_t primitiveCount, std::vector<float> lightAttenuationRadii);

  /// Moves a proxy; throws InvalidInput on an unknown proxy id.
  void applyPrimitive(const PrimitiveUpdate& update);
  /// Moves a light (position, matrix, influence bounds); throws InvalidInput on an unknown id.
  void applyLight(const LightUpdate& update);
  /// Recomputes a light's radius from its attenuation (idempotent: the radius is unchanged
  /// by motion, which is exactly why sending it per move is wasted work).
  void applyLightRadius(uint32_t lightId);
  /// Adds proxies (at the origin, like the first ones) up to primitiveCount: the world adds
  /// render chunks when bricks are placed in new cells or a grid splits into bodies. Never
  /// shrinks (a proxy no longer needed is hidden and reused); InvalidInput if asked to.
  void growPrimitives(uint32_t primitiveCount);

  /// Number of primitive proxies.
  uint32_t primitiveCount() const { return static_cast<uint32_t>(boundsOrigin_.size()); }
  /// Number of lights.
  uint32_t lightCount() const { return static_cast<uint32_t>(lightAttenuation_.size()); }

  /// True if every state array is byte-identical to other's.
  bool identicalTo(const RenderScene& other) const;
  /// FNV-1a 64 over the bytes of every state array.
  uint64_t stateHash() const;
  /// Bytes of state (what identicalTo compares).
  size_t stateBytes() const;

  /// World bounds centre of a proxy.
  const Vec3d& boundsOrigin(uint32_t id) const { return boundsOrigin_[id]; }
  /// World bounds half extent of a proxy.
  const Vec3f& boundsExtent(uint32_t id) const { return boundsExtent_[id]; }
  /// Bounding-sphere radius of a proxy.
  float boundsRadius(uint32_t id) const { return boundsRadius_[id]; }
  /// Local bounds of a proxy.
  const Aabb& localBounds(uint32_t id) const { return localBounds_[id]; }
  /// False for a hidden proxy (empty local bounds: a render chunk whose bricks are all gone).
  bool visible(uint32_t id) const { return !localBounds_[id].isEmpty(); }
  /// Rotation part of a proxy's local-to-world matrix.
  const Mat3f& localToWorldLinear(uint32_t id) const { return linear_[id]; }
  /// Translation of a proxy's local-to-world matrix.
  const Vec3d& localToWorldTranslation(uint32_t id) const { return translation_[id]; }
  /// Previous world translation of a proxy (motion vectors).
  const Vec3d& previousTranslation(uint32_t id) const { return previousTranslation_[id]; }
  /// Previous world rotation of a proxy.
  const Quatf& previousRotation(uint32_t id) const { return previousRotation_[id]; }
  /// World position of a light.
  const Vec3d& lightPosition(uint32_t id) const { return lightPosition_[id]; }
  /// Rotation part of a light's light-to-world matrix.
  const Mat3f& lightToWorldLinear(uint32_t id) const { return lightLinear_[id]; }
  /// Radius of a light (its attenuation radius).
  float lightRadius(uint32_t id) const { return lightRadius_[id]; }
  /// 1 / radius of a light.
  float lightInvRadius(uint32_t id) const { return lightInvRadius_[id]; }
  /// Low corner of a light's influence box.
  const Vec3d& lightInfluenceMin(uint32_t id) const { return lightInfluenceMin_[id]; }
  /// High corner of a light's influence box.
  const Vec3d& lightInfluenceMax(uint32_t id) const { return lightInfluenceMax_[id]; }

 private:
  template <typename F>
  void forEachStateArray(F&& f) const;

  // primitive proxies, by proxy id
  std::vector<Vec3d> boundsOrigin_;         // 24
  std::vector<Vec3f> boundsExtent_;         // 12
  std::vector<float> boundsRadius_;         //  4
  std::vector<Aabb> localBounds_;           // 24
  std::vector<Mat3f> linear_;               // 36
  std::vector<Vec3d> translation_;          // 24
  std::vector<Vec3d> previousTranslation_;  // 24
  std::vector<Quatf> previousRotation_;     // 16
  // lights, by light id
  std::vector<Mat3f> lightLinear_;          // 36
  std::vector<Vec3d> lightTranslation_;     // 24
  std::vector<Vec3d> lightPosition_;        // 24
  std::vector<Vec3d> lightInfluenceMin_;    // 24  position - radius (culling box)
  std::vector<Vec3d> lightInfluenceMax_;    // 24  position + radius
  std::vector<float> lightRadius_;          //  4
  std::vector<float> lightInvRadius_;       //  4
  std::vector<float> lightAttenuation_;     //  4  registration input, constant
};

}  // namespace bw
