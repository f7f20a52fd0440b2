#pragma once
/// Object-style baseline for the transform update: the layout article 000 complains about.
///
/// One heap object per component, a virtual update per component, and children reached by
/// chasing parent and child pointers. Each component also carries the cold state a game-engine
/// component drags through the cache (names, tags, flags, settings), modelled as a fixed block.
/// It computes exactly the same records as TransformUpdate (same attachment_math functions),
/// so benchmarks compare layouts and tests can compare results.
/// Thread safety: update() runs roots in parallel; a root's subtree is updated by one thread.
#include <cstdint>
#include <memory>
#include <vector>

#include "jobs/job_system.h"
#include "transforms/attachment_store.h"
#include "transforms/body_pose_view.h"
#include "transforms/transform_update_sink.h"

namespace bw {

/// Everything an engine component carries besides its transform; never read by the update.
struct ComponentColdState {
  char bytes[256];  // 256  the order of size of a scene component's non-transform fields
};

/// A component riding on a body, or on another component (pointer-linked hierarchy).
class SceneComponent {
 public:
  /// A component on `body`, attached to `parent` (nullptr: directly on the body).
  SceneComponent(uint32_t body, SceneComponent* parent, const Vec3f& localTranslation, const Quatf& localRotation);
  /// Components are owned by ObjectStyleScene, one heap object each.
  virtual ~SceneComponent() = default;
  SceneComponent(const SceneComponent&) = delete;
  SceneComponent& operator=(const SceneComponent&) = delete;

  /// Recomputes this component if it or its parent moved, then recurses into its children.
  virtual void updateComponentToWorld(const BodyPoseView& bodies, bool parentMoved, TransformUpdateSink& sink);
  /// Registers a child so updates propagate to it.
  void addChild(SceneComponent* child) { children_.push_back(child); }

  /// World translation after the last update.
  const Vec3d& worldTranslation() const { return worldTranslation_; }
  /// World rotation after the last update.
  const Quatf& worldRotation() const { return worldRotation_; }

 protected:
  /// Tells the render side about the new transform (one record).
  virtual void sendRenderTransform(const Vec3d& previousTranslation, const Quatf& previousRotation,
                                   TransformUpdateSink& sink) = 0;

 private:
  [[maybe_unused]] ComponentColdState cold_{};  // never read: the weight it puts in the cache is the point
  SceneComponent* parent_;
  std::vector<SceneComponent*> children_;
  uint32_t body_;
  bool dirty_ = true;
  Vec3f localTranslation_;
  Quatf localRotation_;
  Vec3d worldTranslation_ = Vec3d::Zero();
  Quatf worldRotation_ = Quatf::Identity();
};

/// A render primitive component (has local bounds and a proxy id).
class PrimitiveComponent final : public SceneComponent {
 public:
  /// See SceneComponent; proxyId indexes the render scene.
  PrimitiveComponent(uint32_t body, SceneComponent* parent, const Vec3f& t, const Quatf& r, const Aabb& localBounds,
                     uint32_t proxyId);

 protected:
  void sendRenderTransform(const Vec3d& previousTranslation, const Quatf& previousRotation,
                           TransformUpdateSink& sink) override;  ///< sends a PrimitiveUpdate

 private:
  Aabb localBounds_;
  uint32_t proxyId_;
};

/// A light component (has a light id).
class LightComponent final : public SceneComponent {
 public:
  /// See SceneComponent; lightId indexes the render scene.
  LightComponent(uint32_t body, SceneComponent* parent, const Vec3f& t, const Quatf& r, uint32_t lightId);

 protected:
  void sendRenderTransform(const Vec3d& previousTranslation, const Quatf& previousRotation,
                           TransformUpdateSink& sink) override;  ///< sends a LightUpdate

 private:
  uint32_t lightId_;
};

/// The same attachments as an AttachmentStore, one heap object each, updated object by object.
class ObjectStyleScene {
 public:
  /// Mirrors every attachment of store (same ids, offsets, render ids) as a heap object.
  explicit ObjectStyleScene(const AttachmentStore& store);

  /// Updates all components: roots in parallel, each subtree recursively by pointer.
  void update(JobSystem& jobs, const BodyPoseView& bodies, TransformUpdateSink& sink, uint32_t grain = 64);
  /// Same, on the calling thread.
  void updateSerial(const BodyPoseView& bodies, TransformUpdateSink& sink);

  /// Number of components.
  uint32_t size() const { return static_cast<uint32_t>(components_.size()); }
  /// Component by attachment id.
  const SceneComponent& component(uint32_t id) const { return *components_[id]; }

 private:
  std::vector<std::unique_ptr<SceneComponent>> components_;  // by attachment id
  std::vector<SceneComponent*> roots_;                        // components riding on a body
  uint32_t bodiesReferenced_;
};

}  // namespace bw
