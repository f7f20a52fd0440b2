#pragma once
/// One frame's batch of transform updates: what the batched path hands to the render thread
/// in a single command.
#include <cstdint>

#include "render_batch/atomic_append_array.h"
#include "transforms/transform_records.h"

namespace bw {

/// Primitive and light records of one frame, appended from any thread.
struct TransformBatch {
  /// Sized once from the maximum number of primitives and lights that can move in a frame.
  TransformBatch(uint32_t primitiveCapacity, uint32_t lightCapacity)
      : primitives(primitiveCapacity), lights(lightCapacity) {}

  AtomicAppendArray<PrimitiveUpdate> primitives;  ///< moved primitives of the frame
  AtomicAppendArray<LightUpdate> lights;          ///< moved lights of the frame
  uint64_t frame = 0;                             ///< frame the batch belongs to

  /// Empties both arrays for a new frame (only while no one appends).
  void clear() {
    primitives.clear();
    lights.clear();
  }
};

}  // namespace bw
