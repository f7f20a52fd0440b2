#include "transforms/transform_update.h"

#include <string>

#include "collision/core/argument_checks.h"
#include "transforms/attachment_math.h"

namespace bw {

TransformUpdate::TransformUpdate(AttachmentStore& store, const BodyPoseView& bodies, TransformUpdateSink& sink)
    : store_(store), bodies_(bodies), sink_(sink) {
  if (store.bodiesReferenced() > bodies.count)
    throw InvalidInput("TransformUpdate: attachments ride on " + std::to_string(store.bodiesReferenced()) +
                       " bodies but the body view holds " + std::to_string(bodies.count));
  if (bodies.count != 0 && (!bodies.position || !bodies.rotation || !bodies.moved))
    throw InvalidInput("TransformUpdate: body view has a null column");
  store.prepareUpdateOrder();
  columns_ = store.columns();
  levelCount_ = store.levelCount();
}

void TransformUpdate::runRange(uint32_t begin, uint32_t end) const {
  const AttachmentColumns& c = columns_;
  for (uint32_t k = begin; k < end; ++k) {
    const uint32_t id = c.levelOrder[k];
    const uint32_t parent = c.parent[id];
    const uint32_t body = c.body[id];
    // note: a parent is one level up, finished before this level started, so reading its
    // moved flag and pose here is race-free.
    const bool parentMoved = parent == kInvalidIndex ? bodies_.moved[body] != 0 : c.moved[parent] != 0;
    const bool moved = parentMoved || c.localDirty[id] != 0;
    c.moved[id] = moved ? 1 : 0;
    if (!moved) continue;
    c.localDirty[id] = 0;
    const Vec3d previousTranslation = c.worldTranslation[id];
    const Quatf previousRotation = c.worldRotation[id];
    if (parent == kInvalidIndex)
      composeAttachmentPose(bodies_.position[body], bodies_.rotation[body], c.localTranslation[id],
                            c.localRotation[id], c.worldTranslation[id], c.worldRotation[id]);
    else
      composeAttachmentPose(c.worldTranslation[parent], c.worldRotation[parent], c.localTranslation[id],
                            c.localRotation[id], c.worldTranslation[id], c.worldRotation[id]);
    if (c.kind[id] == AttachmentKind::Primitive)
      sink_.primitive(makePrimitiveUpdate(c.renderId[id], c.localBounds[id], c.worldTranslation[id],
                                          c.worldRotation[id], previousTranslation, previousRotation));
    else
      sink_.light(makeLightUpdate(c.renderId[id], c.worldTranslation[id], c.worldRotation[id]));
  }
}

void TransformUpdate::run(JobSystem& jobs, uint32_t grain) {
  for (uint32_t level = 0; level < levelCount_; ++level) {
    // note: the chunk body captures one pointer, so std::function stores it inline (no allocation).
    const TransformUpdate* self = this;
    jobs.parallelFor(levelBegin(level), levelEnd(level), grain,
                     [self](uint32_t b, uint32_t e) { self->runRange(b, e); });
  }
}

void TransformUpdate::runSerial() {
  for (uint32_t level = 0; level < levelCount_; ++level) runRange(levelBegin(level), levelEnd(level));
}

}  // namespace bw
