#pragma once
/// Frame steps 5-7 of the world (DESIGN.md): after the physics of frame N, the parallel SoA
/// transform update of the attachments of the bodies that moved, their submission in the
/// chosen mode, one commit; the render thread applies frame N while the world simulates N+1.
///
///   WorldRender render(std::move(store), SubmissionMode::Batched, bodies.size(), 0, 0);
///   RenderStageStats s = render.run(bodies, sleep, jobs, profiler, stage);   // end of each step
///   render.finish();  const RenderScene& scene = render.scene();
///
/// Built only when the scene declares attachments (the world builds the store,
/// world/render_attachments.cpp). A scene without them has no render thread.
/// Which bodies moved: a body moved when the bits of its shape pose changed since the frame
/// before. Static bodies and bodies asleep since the frame before are not even looked at (after
/// the first frame, or after checkAllBodies()), so a pile at rest submits nothing. Render poses are shape poses
/// (a grid's own frame), so a dynamic grid whose mass was refreshed after an edit (its centre
/// of mass moved inside it, its bricks did not) submits nothing either.
/// Timing: update and submission interleave inside the workers (TransformUpdate blocks); each
/// chunk times both halves apart, and the section's wall time is split between the two stages
/// in proportion to that work. Profiling zones: the pose pass at `stage`, per hierarchy level
/// l the update at stage + 1 + 2l and the submission at stage + 2 + 2l (serial zones with the
/// mutex queue: its pushes hold one lock, so work/span counts them all in the span), the commit
/// at stage + 1 + 2 * kMaxAttachmentDepth.
/// The commit's wake: the render thread's wake (a futex syscall) is handed to a worker beside the
/// next frame (JobSystem::runBeside; a beside zone "render wake" at the commit's stage, outside
/// the frame's chain of stages), joined at the next run, finish() and destruction. The game
/// thread's commit is the batch's hand-over and the job's.
/// Growth: the world edits the store between runs (render chunks of edited cells resized, hidden,
/// added or rebound; parts split off given theirs), and bodies may be added (parts, slabs): the
/// next run looks at the new bodies from their current poses, lays its update chunks out again
/// and grows the render scene ahead of the frame's records (render_frame_pipeline.h).
/// Overflow of a batch (deliberately small capacities): run() throws CapacityExceeded naming
/// the batch and its capacity; the render scene keeps the previous frame, and every attachment
/// is resent on the next frame so the render scene catches up at once.
#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include "jobs/job_system.h"
#include "jobs/profiler.h"
#include "render_batch/render_frame_pipeline.h"
#include "render_batch/submission_mode.h"
#include "transforms/attachment_store.h"
#include "transforms/transform_update.h"
#include "world/body_store.h"
#include "world/sleeping.h"

namespace bw {

/// What a render profiling stage holds, from its offset to the stage id run() was given.
enum class RenderStageKind : uint8_t { Poses, Update, Submission, Commit };
/// Offset of the commit stage (after the update and submission stages of every level).
inline constexpr int kRenderCommitStage = 1 + 2 * int(kMaxAttachmentDepth);
/// The kind of the stage at `offset` (0 .. kRenderCommitStage).
inline RenderStageKind renderStageKind(int offset) {
  if (offset == 0) return RenderStageKind::Poses;
  if (offset == kRenderCommitStage) return RenderStageKind::Commit;
  return offset % 2 == 1 ? RenderStageKind::Update : RenderStageKind::Submission;
}

/// A frame's render time predicted at `threads` from its work/span (`renderStage`: the stage id
/// run() was given): per render stage max(work / threads, span), serial zones (mutex pushes)
/// all in the span. Submission and commit, and the transform update too when withUpdate.
inline double predictedRenderMs(const WorkSpan& frame, int renderStage, int threads, bool withUpdate = false) {
  double total = 0;
  for (size_t s = 0; s < frame.stageIds.size(); ++s) {
    const int offset = frame.stageIds[s] - renderStage;
    if (offset < 0 || offset > kRenderCommitStage) continue;
    const RenderStageKind kind = renderStageKind(offset);
    if (kind == RenderStageKind::Submission || kind == RenderStageKind::Commit || withUpdate)
      total += std::max(frame.stageWorkMs[s] / threads, frame.stageSpanMs[s]);
  }
  return total;
}

/// The render part of one world frame (times in ms, wall clock on the game thread).
struct RenderStageStats {
  double updateMs = 0;       ///< finding moved bodies + composing attachment poses and records
  double submissionMs = 0;   ///< handing records over (queue pushes or batch appends)
  double commitMs = 0;       ///< closing the frame: one batch command, or the fence after per-object commands, and the
                             ///< wake's hand-over to a worker (the wake itself with one thread)
  double waitMs = 0;         ///< blocked until the render thread applied frame N-2
  double renderBusyMs = 0;   ///< render-thread busy time reported since the previous frame (lags by up to two frames)
  uint32_t movedBodies = 0;  ///< bodies whose pose changed
  uint32_t primitives = 0, lights = 0;  ///< records submitted
};

/// Per-object vs batched submission of the world's attachments (see file comment).
class WorldRender {
 public:
  /// Render scene sized from store; a batch holds batchPrimitives / batchLights records a frame
  /// (0 = every primitive / light, growing with the store). bodyCount bodies are looked at at first.
  /// The render thread records its busy time per frame into profiler (zone "render thread:
  /// apply", stage -1: beside the frames, outside their work/span); read it after finish().
  WorldRender(AttachmentStore store, SubmissionMode mode, uint32_t bodyCount, uint32_t batchPrimitives, uint32_t batchLights,
              Profiler& profiler);

  /// Frame steps 5-7 for the bodies' current poses (see file comment).
  RenderStageStats run(const BodyStore& bodies, const SleepState& sleep, JobSystem& jobs, Profiler& profiler, int stage);
  /// The next run looks at every body, static and sleeping ones too (after poses were set).
  void checkAllBodies() { checkAll_ = true; }
  /// Waits for the last run's wake job (see file comment).
  ~WorldRender();

  /// Waits for the last run's wake job, then until every submitted frame is applied.
  void finish();
  /// The render scene: call finish() first.
  const RenderScene& scene() const { return pipeline_->renderThread().scene(); }
  /// Render-thread counters as of the last fence reached.
  RenderThreadStats renderStats() const { return pipeline_->renderThread().stats(); }
  /// The attachments.
  const AttachmentStore& store() const { return store_; }
  /// The attachments, to edit between runs (never while run() is running).
  AttachmentStore& attachments() { return store_; }
  /// Submission mode.
  SubmissionMode mode() const { return pipeline_->mode(); }
  /// Frames submitted.
  uint64_t frame() const { return pipeline_->frame(); }

 private:
  uint32_t markMovedBodies(const BodyStore& bodies, const SleepState& sleep, JobSystem& jobs, Profiler& profiler, int stage);
  // Takes in bodies added since the last run (their current poses, not moved).
  void growBodies(const BodyStore& bodies);
  // One timing slot per update chunk of every level, for the store as it is now.
  void layOutUpdateChunks();
  // Waits for the wake job the last run handed to its JobSystem (beside the next frame).
  void joinWake();

  AttachmentStore store_;
  std::unique_ptr<RenderFramePipeline> pipeline_;
  // Shape pose of every body as last submitted, and whether it changed this frame.
  std::vector<Vec3d> position_;
  std::vector<Quatf> rotation_;
  std::vector<uint8_t> moved_;
  std::vector<uint8_t> asleepBefore_;         // asleep at the previous pose pass
  uint32_t poseGrain_;                        // bodies per job of the pose pass
  std::vector<uint32_t> movedPerChunk_;       // pose pass: moved bodies per chunk
  std::vector<UpdateRangeTimes> chunkTimes_;  // transform update: per chunk of every level
  std::vector<uint32_t> levelFirstChunk_;     // index of each level's first chunk in chunkTimes_
  std::vector<uint32_t> levelGrain_;          // attachments per job of each level
  uint32_t laidOutFor_ = UINT32_MAX;          // store size the chunk layout was made for
  bool checkAll_ = true;
  uint64_t reportedBusyNs_ = 0;
  JobSystem* wakeJobs_ = nullptr;  // where the last run's wake job went (outlives this: World's)
};

}  // namespace bw
