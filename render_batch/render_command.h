#pragma once
/// Commands the game side sends to the render thread, executed in submission order.
///
/// Per-object submission sends one command per moved primitive (PrimitiveUpdate), per moved
/// light (LightUpdate), plus the radius refresh the engine of article 000 sent on every light
/// move (LightRadiusUpdate); a FrameEnd closes the frame. Batched submission sends one
/// BatchCommit per frame, which both applies the frame's batch and closes the frame. In either
/// mode a frame that added primitives starts with a GrowScene.
#include <cstdint>
#include <variant>

#include "render_batch/transform_batch.h"
#include "transforms/transform_records.h"

namespace bw {

/// Recomputes a light's radius from its attenuation (what the engine did on every light move).
struct LightRadiusUpdate {
  uint32_t lightId;  ///< light to refresh
};

/// Applies a whole frame's batch, then signals the frame fence.
struct BatchCommit {
  const TransformBatch* batch;  ///< owned by the submitter, untouched by it until this frame's fence
  uint64_t frame;               ///< frame the fence signals
};

/// Signals the frame fence: everything submitted before it has been applied.
struct FrameEnd {
  uint64_t frame;  ///< frame the fence signals
};

/// Ends the render thread's loop (sent by the RenderThread destructor).
struct StopRenderThread {};

/// Grows the render scene to primitiveCount proxies before the frame's records that use them
/// (sent by the game thread ahead of the frame's update, so it precedes them in the queue).
struct GrowScene {
  uint32_t primitiveCount;  ///< proxies the scene holds from now on
};

/// One render command (copied by value into the queue).
using RenderCommand =
    std::variant<PrimitiveUpdate, LightUpdate, LightRadiusUpdate, BatchCommit, FrameEnd, GrowScene, StopRenderThread>;
static_assert(sizeof(RenderCommand) == 192, "per-object submission copies one of these per moved object");

}  // namespace bw
