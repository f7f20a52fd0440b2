#include "transforms/transform_update.h"

#include <algorithm>
#include <chrono>
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

template <bool Timed>
void TransformUpdate::runBlocks(uint32_t begin, uint32_t end, UpdateRangeTimes* times) const {
  using Clock = std::chrono::steady_clock;
  const AttachmentColumns& c = columns_;
  PrimitiveUpdate primitives[kRecordBlock];
  LightUpdate lights[kRecordBlock];
  for (uint32_t blockBegin = begin; blockBegin < end; blockBegin += kRecordBlock) {
    const uint32_t blockEnd = std::min(end, blockBegin + kRecordBlock);
    Clock::time_point t0;
    if constexpr (Timed) t0 = Clock::now();
    uint32_t nPrimitives = 0, nLights = 0;
    for (uint32_t k = blockBegin; k < blockEnd; ++k) {
      const uint32_t id = c.levelOrder[k];
      const uint32_t parent = c.parent[id];
      const uint32_t body = c.body[id];
      // note: a parent is one level up, finished before this level started, so reading its
      // moved flag and pose here is race-free.
      const bool parentMoved = parent == kInvalidIndex ? bodies_.moved[body] != 0 : c.moved[parent] != 0;
      const bool dirty = c.localDirty[id] != 0;
      const bool moved = parentMoved || dirty;
      c.moved[id] = moved ? 1 : 0;
      if (!moved) continue;
      c.localDirty[id] = 0;
      Vec3d previousTranslation = c.worldTranslation[id];
      Quatf previousRotation = c.worldRotation[id];
      if (parent == kInvalidIndex)
        composeAttachmentPose(bodies_.position[body], bodies_.rotation[body], c.localTranslation[id],
                              c.localRotation[id], c.worldTranslation[id], c.worldRotation[id]);
      else
        composeAttachmentPose(c.worldTranslation[parent], c.worldRotation[parent], c.localTranslation[id],
                              c.localRotation[id], c.worldTranslation[id], c.worldRotation[id]);
      if (c.fresh[id]) {  // added or rebound since the first update: no motion from a pose it never had
        previousTranslation = c.worldTranslation[id];
        previousRotation = c.worldRotation[id];
        c.fresh[id] = 0;
      }
      if (c.kind[id] == AttachmentKind::Primitive) {
        // note: a hidden primitive is sent once, when it is hidden; its later moves show nothing.
        // The record is made either way and just not kept: made under a condition, GCC stopped
        // inlining makePrimitiveUpdate, and carrier_fleet's update took 20% longer.
        primitives[nPrimitives] = makePrimitiveUpdate(c.renderId[id], c.localBounds[id], c.worldTranslation[id],
                                                      c.worldRotation[id], previousTranslation, previousRotation);
        nPrimitives += (dirty || !c.localBounds[id].isEmpty()) ? 1 : 0;
      } else
        lights[nLights++] = makeLightUpdate(c.renderId[id], c.worldTranslation[id], c.worldRotation[id]);
    }
    Clock::time_point t1;
    if constexpr (Timed) t1 = Clock::now();
    if (nPrimitives) sink_.primitives(primitives, nPrimitives);
    if (nLights) sink_.lights(lights, nLights);
    if constexpr (Timed) {
      const Clock::time_point t2 = Clock::now();
      times->updateNs += std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count();
      times->submitNs += std::chrono::duration_cast<std::chrono::nanoseconds>(t2 - t1).count();
      times->primitives += nPrimitives;
      times->lights += nLights;
    }
  }
}

void TransformUpdate::runRange(uint32_t begin, uint32_t end) const { runBlocks<false>(begin, end, nullptr); }

void TransformUpdate::runRangeTimed(uint32_t begin, uint32_t end, UpdateRangeTimes& times) const {
  runBlocks<true>(begin, end, &times);
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
