#pragma once
/// The one seeded attachment workload shared by tests, benchmarks and the CLI.
///
///   AttachmentWorkload w = makeAttachmentWorkload({.attachments = 10'000, .seed = 7});
///   w.bodies.step(frame, 1.0f);                     // move every body (deterministic in seed, frame)
///   TransformUpdate(w.store, w.bodies.view(), sink).run(jobs);
///
/// Bodies get a root primitive each plus a few more attachments (primitives and lights), some
/// riding on other attachments up to maxDepth levels: hull -> lamp -> lens. The counts are
/// exact: the store holds exactly desc.attachments attachments.
#include <cstdint>
#include <vector>

#include "transforms/attachment_store.h"
#include "transforms/body_pose_view.h"

namespace bw {

/// Parameters of the seeded workload.
struct AttachmentWorkloadDesc {
  uint32_t attachments = 10'000;   ///< exact number of attachments
  uint64_t seed = 1;               ///< everything below is a function of the seed
  float lightFraction = 0.25f;     ///< share of non-root attachments that are lights
  float childFraction = 0.4f;      ///< share of non-root attachments riding on another attachment
  uint32_t maxDepth = 3;           ///< levels in a body's attachment hierarchy (1..kMaxAttachmentDepth)
  double worldExtent = 2000.0;     ///< bodies start in a cube of this half size...
  Vec3d worldOffset = Vec3d::Zero();  ///< ...centred here (far offsets exercise double precision)
};

/// SoA body poses with seeded motion: the synthetic load of `batch-bench` and bench_batch, where
/// every body moves every frame.
class BodyMotion {
 public:
  /// count bodies placed from the seed.
  BodyMotion(uint32_t count, uint64_t seed, double extent, const Vec3d& offset);

  /// Moves each body with probability movingFraction (a pure function of seed, frame, body)
  /// and sets its moved flag; clears the flag of the others. No allocation.
  void step(uint64_t frame, float movingFraction);
  /// Marks every body moved without moving it (forces a full update).
  void markAllMoved();
  /// The view the transform update reads.
  BodyPoseView view() const { return {position_.data(), rotation_.data(), moved_.data(), count()}; }
  /// Number of bodies.
  uint32_t count() const { return static_cast<uint32_t>(position_.size()); }
  /// Number of bodies the last step moved.
  uint32_t movedCount() const { return movedCount_; }

 private:
  uint64_t seed_;
  uint32_t movedCount_ = 0;
  std::vector<Vec3d> position_;   // 24 per body
  std::vector<Quatf> rotation_;   // 16
  std::vector<uint8_t> moved_;    //  1
  std::vector<Vec3f> velocity_;   // 12  units per frame
  std::vector<Quatf> spin_;       // 16  rotation per frame
};

/// A store filled from a seed and the bodies it rides on.
struct AttachmentWorkload {
  AttachmentStore store;  ///< exactly desc.attachments attachments
  BodyMotion bodies;      ///< every body referenced by the store
};

/// Builds the workload of desc; throws InvalidInput on out-of-range parameters.
AttachmentWorkload makeAttachmentWorkload(const AttachmentWorkloadDesc& desc);

}  // namespace bw
