#include "render_batch/render_frame_pipeline.h"

#include <chrono>
#include <string>

#include "collision/core/argument_checks.h"

#include "render_batch/concurrent_command_queue.h"
#include "render_batch/mutex_command_queue.h"

namespace bw {
namespace {

std::unique_ptr<CommandQueue> makeQueue(SubmissionMode mode, const AttachmentStore& store) {
  if (usesConcurrentQueue(mode)) return std::make_unique<ConcurrentCommandQueue>();
  // note: the per-object mutex queue is reserved for a full frame of commands so that the
  // comparison measures locking, not vector growth.
  const size_t perLight = sendsLightRadius(mode) ? 2u : 1u;
  const size_t expected = mode == SubmissionMode::Batched ? 4 : store.primitiveCount() + perLight * store.lightCount() + 1;
  return std::make_unique<MutexCommandQueue>(expected);
}

double msSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

RenderFramePipeline::RenderFramePipeline(AttachmentStore& store, SubmissionMode mode,
                                         RenderThread::FenceObserver observer, uint32_t batchPrimitiveCapacity,
                                         uint32_t batchLightCapacity)
    : store_(store),
      mode_(mode),
      scenePrimitives_(store.primitiveCount()),
      sceneLights_(store.lightCount()),
      batchFollowsStore_{batchPrimitiveCapacity == UINT32_MAX, batchLightCapacity == UINT32_MAX} {
  render_ = std::make_unique<RenderThread>(RenderScene(store.primitiveCount(), store.lightAttenuationRadii()),
                                           makeQueue(mode, store), std::move(observer));
  if (mode == SubmissionMode::Batched)
    batched_ = std::make_unique<BatchedSubmitter>(
        *render_, batchPrimitiveCapacity == UINT32_MAX ? store.primitiveCount() : batchPrimitiveCapacity,
        batchLightCapacity == UINT32_MAX ? store.lightCount() : batchLightCapacity);
  else
    perObject_ = std::make_unique<PerObjectSubmitter>(*render_, sendsLightRadius(mode));
}

RenderFramePipeline::~RenderFramePipeline() {
  // note: the render thread may still read a batch; stop it before the submitter goes away.
  wakeRenderThread();
  render_.reset();
}

FrameTiming RenderFramePipeline::runFrame(const BodyPoseView& bodies, JobSystem& jobs) {
  return runFrame(bodies, [&jobs](TransformUpdate& update) { update.run(jobs); });
}

FrameTiming RenderFramePipeline::runFrame(const BodyPoseView& bodies, const UpdateRunner& runner, bool wakeOwed) {
  FrameTiming timing;
  if (store_.lightCount() != sceneLights_)
    throw InvalidInput("RenderFramePipeline::runFrame: the store has " + std::to_string(store_.lightCount()) +
                       " lights, the render scene registered " + std::to_string(sceneLights_) +
                       " (lights cannot be added once the render thread runs)");
  const uint64_t frame = frame_ + 1;
  const auto waitStart = std::chrono::steady_clock::now();
  wakeRenderThread();  // the last frame's, if its caller has not delivered it yet
  if (frame >= 3) render_->waitForFrame(frame - 2);
  timing.waitMs = msSince(waitStart);
  const auto start = std::chrono::steady_clock::now();
  // note: frame_ advances just before the commit, which always signals the fence (even when
  // it then throws on overflow); a throwing update leaves frame_ unchanged and nothing fenced.
  // note: the commit's time is taken even when it throws (a batch overflow), by the guard.
  struct CommitTimer {
    FrameTiming& timing;
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
    ~CommitTimer() { timing.commitMs = msSince(start); }
  };
  // note: enqueued once the update's inputs were accepted (a refused update leaves nothing in
  // the queue) and before the update starts, so it precedes every record of this frame in the
  // queue (FIFO in happens-before order, which the workers' start gives).
  const auto growScene = [this] {
    if (store_.primitiveCount() <= scenePrimitives_) return;
    scenePrimitives_ = store_.primitiveCount();
    render_->enqueue(GrowScene{scenePrimitives_});
  };
  if (batched_) {
    batched_->beginFrame(frame);
    batched_->growCurrent(batchFollowsStore_[0] ? store_.primitiveCount() : 0, batchFollowsStore_[1] ? store_.lightCount() : 0);
    TransformUpdate update(store_, bodies, *batched_);
    growScene();
    runner(update);
    frame_ = frame;
    CommitTimer commit{timing};
    wakeOwed_.store(wakeOwed, std::memory_order_release);
    batched_->commitFrame(frame, !wakeOwed);
  } else {
    TransformUpdate update(store_, bodies, *perObject_);
    growScene();
    runner(update);
    frame_ = frame;
    CommitTimer commit{timing};
    wakeOwed_.store(wakeOwed, std::memory_order_release);
    perObject_->commitFrame(frame, !wakeOwed);
  }
  timing.gameMs = msSince(start);
  return timing;
}

void RenderFramePipeline::finish() {
  wakeRenderThread();
  if (frame_ != 0) render_->waitForFrame(frame_);
}

}  // namespace bw
