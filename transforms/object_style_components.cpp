#include "transforms/object_style_components.h"

#include <string>

#include "collision/core/argument_checks.h"
#include "transforms/attachment_math.h"

namespace bw {

SceneComponent::SceneComponent(uint32_t body, SceneComponent* parent, const Vec3f& localTranslation,
                               const Quatf& localRotation)
    : parent_(parent), body_(body), localTranslation_(localTranslation), localRotation_(localRotation) {}

void SceneComponent::updateComponentToWorld(const BodyPoseView& bodies, bool parentMoved, TransformUpdateSink& sink) {
  const bool moved = dirty_ || (parent_ ? parentMoved : bodies.moved[body_] != 0);
  if (moved) {
    dirty_ = false;
    const Vec3d previousTranslation = worldTranslation_;
    const Quatf previousRotation = worldRotation_;
    if (parent_)
      composeAttachmentPose(parent_->worldTranslation_, parent_->worldRotation_, localTranslation_, localRotation_,
                            worldTranslation_, worldRotation_);
    else
      composeAttachmentPose(bodies.position[body_], bodies.rotation[body_], localTranslation_, localRotation_,
                            worldTranslation_, worldRotation_);
    sendRenderTransform(previousTranslation, previousRotation, sink);
  }
  for (SceneComponent* child : children_) child->updateComponentToWorld(bodies, moved, sink);
}

PrimitiveComponent::PrimitiveComponent(uint32_t body, SceneComponent* parent, const Vec3f& t, const Quatf& r,
                                       const Aabb& localBounds, uint32_t proxyId)
    : SceneComponent(body, parent, t, r), localBounds_(localBounds), proxyId_(proxyId) {}

void PrimitiveComponent::sendRenderTransform(const Vec3d& previousTranslation, const Quatf& previousRotation,
                                             TransformUpdateSink& sink) {
  sink.primitive(makePrimitiveUpdate(proxyId_, localBounds_, worldTranslation(), worldRotation(),
                                     previousTranslation, previousRotation));
}

LightComponent::LightComponent(uint32_t body, SceneComponent* parent, const Vec3f& t, const Quatf& r,
                               uint32_t lightId)
    : SceneComponent(body, parent, t, r), lightId_(lightId) {}

void LightComponent::sendRenderTransform(const Vec3d&, const Quatf&, TransformUpdateSink& sink) {
  sink.light(makeLightUpdate(lightId_, worldTranslation(), worldRotation()));
}

ObjectStyleScene::ObjectStyleScene(const AttachmentStore& store) : bodiesReferenced_(store.bodiesReferenced()) {
  components_.reserve(store.size());
  for (uint32_t id = 0; id < store.size(); ++id) {
    SceneComponent* parent =
        store.parent(id) == kInvalidIndex ? nullptr : components_[store.parent(id)].get();
    if (store.kind(id) == AttachmentKind::Primitive)
      components_.push_back(std::make_unique<PrimitiveComponent>(store.body(id), parent, store.localTranslation(id),
                                                                 store.localRotation(id), store.localBounds(id),
                                                                 store.renderId(id)));
    else
      components_.push_back(std::make_unique<LightComponent>(store.body(id), parent, store.localTranslation(id),
                                                             store.localRotation(id), store.renderId(id)));
    if (parent)
      parent->addChild(components_.back().get());
    else
      roots_.push_back(components_.back().get());
  }
}

void ObjectStyleScene::update(JobSystem& jobs, const BodyPoseView& bodies, TransformUpdateSink& sink, uint32_t grain) {
  if (bodiesReferenced_ > bodies.count)
    throw InvalidInput("ObjectStyleScene::update: components ride on " + std::to_string(bodiesReferenced_) +
                       " bodies but the body view holds " + std::to_string(bodies.count));
  struct Context {
    ObjectStyleScene* scene;
    const BodyPoseView* bodies;
    TransformUpdateSink* sink;
  } ctx{this, &bodies, &sink};
  const Context* c = &ctx;
  jobs.parallelFor(0, static_cast<uint32_t>(roots_.size()), grain, [c](uint32_t b, uint32_t e) {
    for (uint32_t i = b; i < e; ++i) {
      SceneComponent* root = c->scene->roots_[i];
      // note: a root reads its body's moved flag itself, so the argument is unused for roots.
      root->updateComponentToWorld(*c->bodies, false, *c->sink);
    }
  });
}

void ObjectStyleScene::updateSerial(const BodyPoseView& bodies, TransformUpdateSink& sink) {
  if (bodiesReferenced_ > bodies.count)
    throw InvalidInput("ObjectStyleScene::updateSerial: body view too small");
  for (SceneComponent* root : roots_) root->updateComponentToWorld(bodies, false, sink);
}

}  // namespace bw
