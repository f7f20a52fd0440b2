#pragma once
/// One game-side frame of the render path: transform update, submission in a chosen mode, commit.
///
///   RenderFramePipeline pipeline(store, SubmissionMode::Batched);
///   for (...) { bodies.step(f, 1.f); pipeline.runFrame(bodies.view(), jobs); }
///   pipeline.finish();    // waits for the last frame; the render scene is then readable
///
/// Frames in flight: frame N starts only after frame N-2's fence, so the render thread applies
/// frame N-1 while the game computes frame N (DESIGN.md frame step 7) and never falls further behind.
/// A store that gained primitives between frames (render chunks of placed bricks, parts split
/// off) grows the render scene first (a GrowScene ahead of the frame's records) and, when the
/// batch capacity follows the store (UINT32_MAX), the frame's batch. Lights are registered once:
/// a store that gained lights is refused (InvalidInput), nothing submitted.
/// Waking: by default the commit wakes the render thread. A caller that has a worker to spare
/// asks runFrame to leave the wake owed and delivers it with wakeRenderThread() from that worker
/// beside its next frame (World does): the game thread then never pays the wake's syscall. An
/// owed wake is delivered anyway before anything waits on the render thread (the next frame,
/// finish(), the destructor), so a caller that forgets costs latency, never a hang.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>

#include "jobs/job_system.h"
#include "render_batch/batched_submitter.h"
#include "render_batch/per_object_submitter.h"
#include "render_batch/render_thread.h"
#include "render_batch/submission_mode.h"
#include "transforms/attachment_store.h"
#include "transforms/transform_update.h"

namespace bw {

/// Game-thread time of one frame.
struct FrameTiming {
  double gameMs = 0;    ///< transform update + submission + commit on the game thread
  double commitMs = 0;  ///< of gameMs, the commit (batch hand-over or frame fence)
  double waitMs = 0;    ///< time blocked on the render thread before the frame could start
};

/// Drives frames for one store in one submission mode (see file comment).
class RenderFramePipeline {
 public:
  /// Runs a transform update (on the job system, on the caller's own threads, ...).
  using UpdateRunner = std::function<void(TransformUpdate&)>;

  /// Render scene sized from store; batches sized from the store (and growing with it) unless
  /// capacities are given.
  RenderFramePipeline(AttachmentStore& store, SubmissionMode mode, RenderThread::FenceObserver observer = {},
                      uint32_t batchPrimitiveCapacity = UINT32_MAX, uint32_t batchLightCapacity = UINT32_MAX);
  ~RenderFramePipeline();

  /// Runs the next frame with the update on jobs.
  FrameTiming runFrame(const BodyPoseView& bodies, JobSystem& jobs);
  /// Runs the next frame with the update run by runner; wakeOwed: the commit leaves the render
  /// thread's wake to wakeRenderThread() (see file comment).
  FrameTiming runFrame(const BodyPoseView& bodies, const UpdateRunner& runner, bool wakeOwed = false);
  /// Delivers an owed wake (nothing when none is owed); safe from any thread.
  void wakeRenderThread() {
    if (wakeOwed_.exchange(false, std::memory_order_acq_rel)) render_->wake();
  }
  /// Waits until every submitted frame is applied.
  void finish();

  /// Last frame submitted (frames count from 1).
  uint64_t frame() const { return frame_; }
  /// Submission mode.
  SubmissionMode mode() const { return mode_; }
  /// The render thread (its scene is readable after finish()).
  RenderThread& renderThread() { return *render_; }

 private:
  AttachmentStore& store_;
  SubmissionMode mode_;
  std::unique_ptr<RenderThread> render_;
  std::unique_ptr<PerObjectSubmitter> perObject_;
  std::unique_ptr<BatchedSubmitter> batched_;
  uint64_t frame_ = 0;
  uint32_t scenePrimitives_;     // proxies the render scene has (or will have, after its queue)
  uint32_t sceneLights_;         // lights registered with the render scene
  bool batchFollowsStore_[2];    // primitive, light capacity given as UINT32_MAX
  std::atomic<bool> wakeOwed_{false};  // a commit left its wake to wakeRenderThread()
};

}  // namespace bw
