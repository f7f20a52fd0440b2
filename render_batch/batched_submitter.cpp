#include "render_batch/batched_submitter.h"

#include <string>

#include "collision/core/argument_checks.h"

namespace bw {

BatchedSubmitter::BatchedSubmitter(RenderThread& render, uint32_t primitiveCapacity, uint32_t lightCapacity)
    : render_(render),
      batches_{TransformBatch(primitiveCapacity, lightCapacity), TransformBatch(primitiveCapacity, lightCapacity)},
      current_(&batches_[0]) {}

void BatchedSubmitter::beginFrame(uint64_t frame) {
  // note: batch (frame & 1) was last handed over for frame - 2; its fence means the render
  // thread is done reading it.
  if (frame >= 3) render_.waitForFrame(frame - 2);
  current_ = &batches_[frame & 1];
  current_->clear();
  current_->frame = frame;
}

void BatchedSubmitter::growCurrent(uint32_t primitiveCapacity, uint32_t lightCapacity) {
  current_->primitives.growCapacity(primitiveCapacity);
  current_->lights.growCapacity(lightCapacity);
}

void BatchedSubmitter::commitFrame(uint64_t frame, bool wakeNow) {
  TransformBatch& batch = *current_;
  if (batch.frame != frame)
    throw InvalidInput("BatchedSubmitter::commitFrame: frame " + std::to_string(frame) + " was not begun (current " +
                       std::to_string(batch.frame) + ")");
  if (batch.primitives.overflowed() || batch.lights.overflowed()) {
    std::string message = "BatchedSubmitter frame " + std::to_string(frame) + ": ";
    if (batch.primitives.overflowed()) message += batch.primitives.overflowMessage("primitive update batch");
    if (batch.primitives.overflowed() && batch.lights.overflowed()) message += "; ";
    if (batch.lights.overflowed()) message += batch.lights.overflowMessage("light update batch");
    render_.endFrame(frame);
    throw CapacityExceeded(message);
  }
  render_.commitBatch(batch, frame, wakeNow);
}

}  // namespace bw
