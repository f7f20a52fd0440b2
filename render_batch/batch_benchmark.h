#pragma once
/// The batching measurements behind `brickworld batch-bench` and bench_batch: per-object vs
/// batched submission, and SoA vs object-style transform update, on the shared seeded workload.
///
/// Every frame moves every body (all attachments move), like the article's scene of thousands
/// of moving objects. Timing is per frame on the game thread; medians resist the noise of a
/// shared machine.
#include <cstdint>
#include <string>
#include <vector>

#include "render_batch/submission_mode.h"

namespace bw {

/// One submission-mode measurement.
struct SubmissionSample {
  SubmissionMode mode = SubmissionMode::Batched;  ///< what was measured
  uint32_t attachments = 0;                       ///< moving attachments
  int threads = 1;                                ///< job-system threads (game thread included)
  uint32_t frames = 0;                            ///< measured frames
  double gameMs = 0;            ///< median game-thread time: update + submission + commit
  double renderMs = 0;          ///< mean render-thread busy time per frame
  double frameMs = 0;           ///< mean wall time per frame including waits for the render thread
  double commandsPerFrame = 0;  ///< render commands executed per frame (fences included)
  double updatesPerFrame = 0;   ///< primitive + light updates applied per frame (same in every mode)
  double radiusPerFrame = 0;    ///< light radius refreshes per frame (PerObjectMutex/Concurrent only)
};

/// One transform-update layout measurement.
struct TransformLayoutSample {
  bool objectStyle = false;  ///< false: SoA TransformUpdate; true: ObjectStyleScene
  uint32_t attachments = 0;  ///< moving attachments
  int threads = 1;           ///< job-system threads
  uint32_t frames = 0;       ///< measured frames
  double updateMs = 0;       ///< median update time per frame (records go to per-id slots)
};

/// Runs warmup + frames frames of mode on a fresh workload and render thread.
SubmissionSample measureSubmission(SubmissionMode mode, uint32_t attachments, int threads, uint32_t frames,
                                   uint32_t warmupFrames = 3, uint64_t seed = 1);
/// Runs warmup + frames updates of one layout on a fresh workload.
TransformLayoutSample measureTransformLayout(bool objectStyle, uint32_t attachments, int threads, uint32_t frames,
                                             uint32_t warmupFrames = 3, uint64_t seed = 1);

/// Frames to measure so a size gets a comparable amount of work (more frames for small sizes).
uint32_t defaultBenchmarkFrames(uint32_t attachments);

}  // namespace bw
