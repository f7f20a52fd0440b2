#pragma once
/// Per-object submission: every update record becomes its own render command, enqueued from
/// inside the parallel transform update (the worker that computed it pushes it).
///
/// Models the engine of article 000: a light move also enqueues a radius refresh, so a frame
/// costs primitives + 2 x lights commands (plus the frame fence). Without the refresh
/// (sendLightRadius false, the `NoRadius` modes) it is primitives + lights, like for like with
/// batched submission.
#include "render_batch/render_thread.h"
#include "transforms/transform_update_sink.h"

namespace bw {

/// TransformUpdateSink that enqueues one command per record (see file comment).
class PerObjectSubmitter final : public TransformUpdateSink {
 public:
  /// Commands go to render; sendLightRadius reproduces the engine's extra command per light move.
  explicit PerObjectSubmitter(RenderThread& render, bool sendLightRadius = true)
      : render_(render), sendLightRadius_(sendLightRadius) {}

  /// Enqueues the record as one command (called from update workers).
  void primitive(const PrimitiveUpdate& update) override { render_.enqueue(update); }
  /// Enqueues the light move and, like the engine, a radius refresh.
  void light(const LightUpdate& update) override {
    render_.enqueue(update);
    if (sendLightRadius_) render_.enqueue(LightRadiusUpdate{update.lightId});
  }
  /// Closes the frame after the update joined (game thread); wakeNow: RenderThread::endFrame.
  void commitFrame(uint64_t frame, bool wakeNow = true) { render_.endFrame(frame, wakeNow); }

 private:
  RenderThread& render_;
  bool sendLightRadius_;
};

}  // namespace bw
