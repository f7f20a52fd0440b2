#include "world/world_render.h"

#include <chrono>
#include <cstring>

#include "collision/core/argument_checks.h"
#include "world/world_tuning.h"

namespace bw {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// Fewest bodies per job of the pose pass (a pose is ~60 flops and a compare).
constexpr uint32_t kMinPoseGrain = 256;
// Fewest attachments per job of the transform update (a moved attachment is ~70 ns with its
// submission): 128 cut crates_on_grid's ~2,000 into 16 jobs, half of them over attachments that
// had not moved (0.6 us) and half 9 us (traced), the longest 2.6x the stage's work / 16.
constexpr uint32_t kMinUpdateGrain = 32;

// The pipeline's "follow the store" capacity for 0.
uint32_t batchSize(uint32_t asked) { return asked == 0 ? UINT32_MAX : asked; }

}  // namespace

WorldRender::WorldRender(AttachmentStore store, SubmissionMode mode, uint32_t bodyCount, uint32_t batchPrimitives,
                         uint32_t batchLights, Profiler& profiler)
    : store_(std::move(store)),
      position_(bodyCount, Vec3d::Zero()),
      rotation_(bodyCount, Quatf::Identity()),
      moved_(bodyCount, 0),
      asleepBefore_(bodyCount, 0),
      poseGrain_(tuning::grainFor(bodyCount, kMinPoseGrain)),
      movedPerChunk_(JobSystem::chunkCount(0, bodyCount, poseGrain_), 0) {
  if (store_.bodiesReferenced() > bodyCount)
    throw InvalidInput("WorldRender: attachments ride on " + std::to_string(store_.bodiesReferenced()) + " bodies, the world has " +
                       std::to_string(bodyCount));
  // At each fence, on the render thread: the busy time since the previous fence as one zone
  // ending now, in the world's frame (pipeline frames count from 1, the world's from 0).
  RenderThread::FenceObserver observer = [&profiler, lastBusy = uint64_t(0)](uint64_t frame, const RenderScene&,
                                                                             const RenderThreadStats& stats) mutable {
    if (profiler.enabled()) {
      const int64_t end = profiler.now();
      profiler.recordInFrame("render thread: apply", end - int64_t(stats.busyNanoseconds - lastBusy), end, -1, uint32_t(frame - 1));
    }
    lastBusy = stats.busyNanoseconds;
  };
  pipeline_ = std::make_unique<RenderFramePipeline>(store_, mode, std::move(observer),
                                                    batchSize(batchPrimitives), batchSize(batchLights));
  layOutUpdateChunks();
}

void WorldRender::layOutUpdateChunks() {
  store_.prepareUpdateOrder();
  laidOutFor_ = store_.size();
  levelFirstChunk_.clear();
  levelGrain_.clear();
  uint32_t chunks = 0;
  for (uint32_t level = 0; level < store_.levelCount(); ++level) {
    const uint32_t begin = store_.levelBegin(level), end = store_.levelBegin(level + 1);
    levelFirstChunk_.push_back(chunks);
    levelGrain_.push_back(tuning::grainFor(end - begin, kMinUpdateGrain));
    chunks += JobSystem::chunkCount(begin, end, levelGrain_.back());
  }
  chunkTimes_.resize(chunks);
}

void WorldRender::growBodies(const BodyStore& bodies) {
  const uint32_t n = bodies.size();
  for (uint32_t i = uint32_t(position_.size()); i < n; ++i) {
    const RigidTransform pose = bodies.shapePose(i);
    position_.push_back(pose.translation);
    rotation_.push_back(pose.rotation);
  }
  moved_.resize(n, 0);
  asleepBefore_.resize(n, 0);
  poseGrain_ = tuning::grainFor(n, kMinPoseGrain);
  movedPerChunk_.assign(JobSystem::chunkCount(0, n, poseGrain_), 0);
}

uint32_t WorldRender::markMovedBodies(const BodyStore& bodies, const SleepState& sleep, JobSystem& jobs, Profiler& profiler,
                                      int stage) {
  const uint32_t n = uint32_t(position_.size());
  const bool all = checkAll_;
  jobs.parallelFor(0, n, poseGrain_, [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler, "render poses", stage);
    uint32_t moved = 0;
    for (uint32_t i = begin; i < end; ++i) {
      moved_[i] = 0;
      // A body that fell asleep this frame still moved in it: it is skipped only from the
      // frame after (its pose is then the one submitted last).
      const bool asleep = sleep.asleep(i);
      const bool wasAsleep = asleepBefore_[i] != 0;
      asleepBefore_[i] = asleep ? 1 : 0;
      // (an asleep body riding a carrier moves on)
      const bool parked = asleep && wasAsleep && !bodies.translates(i);
      if (!all && (bodies.motion[i] == MotionType::Static || parked)) continue;
      const RigidTransform pose = bodies.shapePose(i);
      // note: bits, not values: a pose that changed by one ulp moved (the render scene must
      // equal the world's poses exactly), and -0.0 vs 0.0 is a change we can afford to send.
      if (std::memcmp(&pose.translation, &position_[i], sizeof(Vec3d)) == 0 &&
          std::memcmp(&pose.rotation, &rotation_[i], sizeof(Quatf)) == 0)
        continue;
      position_[i] = pose.translation;
      rotation_[i] = pose.rotation;
      moved_[i] = 1;
      ++moved;
    }
    movedPerChunk_[begin / poseGrain_] = moved;
  });
  checkAll_ = false;
  uint32_t total = 0;
  for (uint32_t m : movedPerChunk_) total += m;
  return total;
}

WorldRender::~WorldRender() { joinWake(); }

void WorldRender::joinWake() {
  if (wakeJobs_) wakeJobs_->joinBeside();
}

void WorldRender::finish() {
  joinWake();
  pipeline_->finish();
}

RenderStageStats WorldRender::run(const BodyStore& bodies, const SleepState& sleep, JobSystem& jobs, Profiler& profiler, int stage) {
  if (bodies.size() < position_.size())
    throw InvalidInput("WorldRender::run: the world has " + std::to_string(bodies.size()) + " bodies, the render has seen " +
                       std::to_string(position_.size()) + " (bodies are never removed)");
  if (bodies.size() > position_.size()) growBodies(bodies);
  if (store_.size() != laidOutFor_) layOutUpdateChunks();
  joinWake();  // the last frame's wake: its job reads this object
  RenderStageStats stats;
  const auto poseStart = Clock::now();
  stats.movedBodies = markMovedBodies(bodies, sleep, jobs, profiler, stage);
  const double poseMs = msSince(poseStart);

  for (UpdateRangeTimes& t : chunkTimes_) t = UpdateRangeTimes{};
  const bool serialSubmission = pipeline_->mode() == SubmissionMode::PerObjectMutex ||
                                pipeline_->mode() == SubmissionMode::PerObjectMutexNoRadius;
  double sectionMs = 0;
  const BodyPoseView view{position_.data(), rotation_.data(), moved_.data(), uint32_t(position_.size())};
  const auto runner = [&](TransformUpdate& update) {
    const auto start = Clock::now();
    for (uint32_t level = 0; level < update.levelCount(); ++level) {
      const uint32_t first = update.levelBegin(level);
      const uint32_t chunk0 = levelFirstChunk_[level];
      const int32_t updateStage = stage + 1 + 2 * int32_t(level);
      const uint32_t grain = levelGrain_[level];
      jobs.parallelFor(first, update.levelEnd(level), grain, [&](uint32_t b, uint32_t e) {
        UpdateRangeTimes& t = chunkTimes_[chunk0 + (b - first) / grain];
        const int64_t zoneStart = profiler.enabled() ? profiler.now() : 0;
        update.runRangeTimed(b, e, t);
        if (profiler.enabled()) {
          // The chunk's two halves as two zones back to back (they interleave block by block),
          // covering the whole job: the job's time outside its timed blocks (the clock reads,
          // the loop between blocks) goes to the update. Zones of the timed blocks alone left
          // it between the job and the next level's (18 us a frame on crates_on_grid), where
          // the work/span bound counts it as serial glue.
          const int64_t end = profiler.now();
          profiler.record("transform update", zoneStart, end - t.submitNs, updateStage);
          profiler.record("submission", end - t.submitNs, end, updateStage + 1, serialSubmission);
        }
      });
    }
    sectionMs = msSince(start);
  };
  FrameTiming timing;
  try {
    timing = pipeline_->runFrame(view, runner, /*wakeOwed*/ true);
  } catch (const CapacityExceeded&) {
    // The frame was fenced without its batch: the render scene still shows the frame before.
    // Resending everything next frame brings it up to date in one step.
    store_.markAllDirty();
    throw;
  }
  // The render thread's wake (a futex syscall: 6-22 us on this VM, the largest single job of
  // crates_on_grid's frame) goes to a worker beside the next frame; the game thread only hands
  // it over. With one thread it runs here, at once, as the commit's did.
  const bool profiling = profiler.enabled();
  const int64_t handOverStart = profiling ? profiler.now() : 0;
  const auto handOverClock = Clock::now();
  const int32_t commitStage = stage + kRenderCommitStage;
  wakeJobs_ = &jobs;
  jobs.runBeside([this, &profiler, profiling, commitStage, frame = profiler.frame()] {
    const int64_t begin = profiling ? profiler.now() : 0;
    pipeline_->wakeRenderThread();
    if (profiling) profiler.recordBeside("render wake", begin, profiler.now(), commitStage, frame);
  });
  const double handOverMs = msSince(handOverClock);
  if (profiling) {
    // note: with one thread the hand-over is the wake, already a beside zone of its own.
    const int64_t end = jobs.threadCount() > 1 ? profiler.now() : handOverStart;
    profiler.record("commit", handOverStart - int64_t(timing.commitMs * 1e6), end, commitStage, true);
  }
  int64_t updateNs = 0, submitNs = 0;
  for (const UpdateRangeTimes& t : chunkTimes_) {
    updateNs += t.updateNs;
    submitNs += t.submitNs;
    stats.primitives += t.primitives;
    stats.lights += t.lights;
  }
  const double share = updateNs + submitNs > 0 ? double(updateNs) / double(updateNs + submitNs) : 1.0;
  stats.updateMs = poseMs + sectionMs * share;
  stats.submissionMs = sectionMs * (1.0 - share);
  stats.commitMs = timing.commitMs + handOverMs;
  stats.waitMs = timing.waitMs;
  const uint64_t busy = renderStats().busyNanoseconds;
  stats.renderBusyMs = double(busy - reportedBusyNs_) * 1e-6;
  reportedBusyNs_ = busy;
  return stats;
}

}  // namespace bw
