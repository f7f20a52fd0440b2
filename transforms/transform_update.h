#pragma once
/// Data-oriented parallel transform update of attachments.
///
///   TransformUpdate update(store, bodies, sink);   // validates, builds the level order if needed
///   update.run(jobs);                               // all levels, parallel inside each level
///
/// For every attachment whose parent (body or attachment) moved, or whose local offset changed,
/// it recomputes the world pose (and, for primitives, world bounds), writes it back to the
/// store and hands one record to the sink: a PrimitiveUpdate or a LightUpdate. Attachments
/// whose parent did not move are skipped after reading two bytes.
/// Ordering: levels run one after another (a parallelFor per level joins before the next),
/// so children read final parent poses. Inside a level each attachment writes only its own
/// slots: no locks, no atomics, and the store's state is the same for any thread count.
/// Records reach the sink in an order that depends on scheduling; each attachment produces
/// at most one record per update.
/// Blocks: a range is worked in blocks of kRecordBlock positions; each block's records are made
/// into a small buffer on the worker's stack (it stays in L1) and then handed to the sink as
/// one block. runRangeTimed times the two halves apart (two clock reads per block), which is
/// how the world reports transform update and submission separately although they interleave.
/// Allocation: none per frame (the level order is rebuilt only after the store was edited).
#include <cstdint>

#include "jobs/job_system.h"
#include "transforms/attachment_store.h"
#include "transforms/body_pose_view.h"
#include "transforms/transform_update_sink.h"

namespace bw {

/// Time one range spent making records and handing them to the sink, and how many it made.
struct UpdateRangeTimes {
  int64_t updateNs = 0;   ///< composing poses and making records
  int64_t submitNs = 0;   ///< inside the sink's block calls
  uint32_t primitives = 0, lights = 0;  ///< records made
};

/// One frame's transform update over an AttachmentStore (see file comment).
class TransformUpdate {
 public:
  /// Attachments per parallelFor chunk: large enough to amortise scheduling, small enough to balance.
  static constexpr uint32_t kDefaultGrain = 512;
  /// Records made before they are handed to the sink as one block.
  static constexpr uint32_t kRecordBlock = 64;

  /// Prepares one update; throws InvalidInput if the body view does not cover the store's bodies.
  TransformUpdate(AttachmentStore& store, const BodyPoseView& bodies, TransformUpdateSink& sink);

  /// Runs every level on the job system (parallel within a level).
  void run(JobSystem& jobs, uint32_t grain = kDefaultGrain);
  /// Runs every level on the calling thread.
  void runSerial();

  /// Number of hierarchy levels; run level l completely before starting level l + 1.
  uint32_t levelCount() const { return levelCount_; }
  /// First level-order position of a level.
  uint32_t levelBegin(uint32_t level) const { return store_.levelBegin(level); }
  /// One past the last level-order position of a level.
  uint32_t levelEnd(uint32_t level) const { return store_.levelBegin(level + 1); }
  /// Updates level-order positions [begin, end), all inside one level; safe to call for
  /// disjoint ranges of the same level from several threads at once.
  void runRange(uint32_t begin, uint32_t end) const;
  /// runRange, adding the time spent making records and the time spent in the sink to times.
  void runRangeTimed(uint32_t begin, uint32_t end, UpdateRangeTimes& times) const;

 private:
  AttachmentStore& store_;
  AttachmentColumns columns_;
  BodyPoseView bodies_;
  TransformUpdateSink& sink_;
  uint32_t levelCount_;

  template <bool Timed>
  void runBlocks(uint32_t begin, uint32_t end, UpdateRangeTimes* times) const;
};

}  // namespace bw
