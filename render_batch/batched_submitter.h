#pragma once
/// Batched submission: workers append records to a pre-sized atomic-append batch (one
/// fetch_add per record, or per block of records when the update hands over blocks); the game thread hands the whole batch over as one command at frame end.
///
/// Two batches alternate: the render thread reads frame N's while workers fill frame N+1's.
/// beginFrame(N) waits for frame N-2's fence before reusing its batch. Light moves send no
/// radius refresh (the radius does not change when a light moves).
/// Overflow: if more records arrive than the batch holds, the extra ones are dropped without
/// any out-of-bounds write, commitFrame still closes the frame (fence only, the partial batch
/// is not applied, so the render scene keeps frame N-1's state) and then throws
/// CapacityExceeded naming the array and its capacity.
#include <cstdint>

#include "render_batch/render_thread.h"
#include "render_batch/transform_batch.h"
#include "transforms/transform_update_sink.h"

namespace bw {

/// TransformUpdateSink that appends to the frame's batch (see file comment).
class BatchedSubmitter final : public TransformUpdateSink {
 public:
  /// Batches sized for primitiveCapacity / lightCapacity records per frame.
  BatchedSubmitter(RenderThread& render, uint32_t primitiveCapacity, uint32_t lightCapacity);

  /// One fetch_add and a copy into the frame's batch; refused appends are counted, reported at commit.
  void primitive(const PrimitiveUpdate& update) override { current_->primitives.tryAppend(update); }
  /// Same for lights (no radius refresh).
  void light(const LightUpdate& update) override { current_->lights.tryAppend(update); }
  /// A worker's block of primitives: one fetch_add for the block.
  void primitives(const PrimitiveUpdate* updates, uint32_t count) override { current_->primitives.tryAppend(updates, count); }
  /// A worker's block of lights: one fetch_add for the block.
  void lights(const LightUpdate* updates, uint32_t count) override { current_->lights.tryAppend(updates, count); }

  /// Prepares frame's batch (game thread, before the update); may wait for frame - 2.
  void beginFrame(uint64_t frame);
  /// Raises the capacity of the batch begun to at least these counts (game thread, after
  /// beginFrame: the render thread is done with that batch). Allocates only when it grows.
  void growCurrent(uint32_t primitiveCapacity, uint32_t lightCapacity);
  /// Commits frame's batch as one command (game thread, after the update joined); wakeNow:
  /// RenderThread::commitBatch (an overflowing frame's fence wakes at once).
  void commitFrame(uint64_t frame, bool wakeNow = true);

 private:
  RenderThread& render_;
  TransformBatch batches_[2];
  TransformBatch* current_;
};

}  // namespace bw
