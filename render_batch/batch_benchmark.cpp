#include "render_batch/batch_benchmark.h"

#include <algorithm>
#include <chrono>

#include "jobs/job_system.h"
#include "render_batch/render_frame_pipeline.h"
#include "transforms/attachment_workload.h"
#include "transforms/object_style_components.h"
#include "transforms/record_slot_sink.h"

namespace bw {
namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

uint32_t defaultBenchmarkFrames(uint32_t attachments) {
  return std::clamp<uint32_t>(4'000'000u / std::max<uint32_t>(attachments, 1u), 10u, 200u);
}

SubmissionSample measureSubmission(SubmissionMode mode, uint32_t attachments, int threads, uint32_t frames,
                                   uint32_t warmupFrames, uint64_t seed) {
  AttachmentWorkload w = makeAttachmentWorkload({.attachments = attachments, .seed = seed});
  JobSystem jobs(threads);
  RenderFramePipeline pipeline(w.store, mode);
  uint64_t frame = 0;
  for (uint32_t i = 0; i < warmupFrames; ++i) {
    w.bodies.step(++frame, 1.f);
    pipeline.runFrame(w.bodies.view(), jobs);
  }
  pipeline.finish();
  const RenderThreadStats before = pipeline.renderThread().stats();
  std::vector<double> game;
  game.reserve(frames);
  double wallMs = 0;
  for (uint32_t i = 0; i < frames; ++i) {
    w.bodies.step(++frame, 1.f);
    const FrameTiming t = pipeline.runFrame(w.bodies.view(), jobs);
    game.push_back(t.gameMs);
    wallMs += t.gameMs + t.waitMs;
  }
  const auto drainStart = std::chrono::steady_clock::now();
  pipeline.finish();
  wallMs += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - drainStart).count();
  const RenderThreadStats after = pipeline.renderThread().stats();
  SubmissionSample s;
  s.mode = mode;
  s.attachments = attachments;
  s.threads = threads;
  s.frames = frames;
  s.gameMs = median(game);
  s.renderMs = frames ? (after.busyNanoseconds - before.busyNanoseconds) * 1e-6 / frames : 0;
  s.frameMs = frames ? wallMs / frames : 0;
  s.commandsPerFrame = frames ? double(after.commandsExecuted - before.commandsExecuted) / frames : 0;
  s.updatesPerFrame = frames ? double(after.primitiveUpdates + after.lightUpdates - before.primitiveUpdates -
                                      before.lightUpdates) / frames
                             : 0;
  s.radiusPerFrame = frames ? double(after.lightRadiusUpdates - before.lightRadiusUpdates) / frames : 0;
  return s;
}

TransformLayoutSample measureTransformLayout(bool objectStyle, uint32_t attachments, int threads, uint32_t frames,
                                             uint32_t warmupFrames, uint64_t seed) {
  AttachmentWorkload w = makeAttachmentWorkload({.attachments = attachments, .seed = seed});
  JobSystem jobs(threads);
  RecordSlotSink sink(w.store.primitiveCount(), w.store.lightCount());
  ObjectStyleScene objects(w.store);
  std::vector<double> times;
  times.reserve(frames);
  uint64_t frame = 0;
  for (uint32_t i = 0; i < warmupFrames + frames; ++i) {
    w.bodies.step(++frame, 1.f);
    const auto start = std::chrono::steady_clock::now();
    if (objectStyle)
      objects.update(jobs, w.bodies.view(), sink);
    else
      TransformUpdate(w.store, w.bodies.view(), sink).run(jobs);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (i >= warmupFrames) times.push_back(ms);
  }
  TransformLayoutSample s;
  s.objectStyle = objectStyle;
  s.attachments = attachments;
  s.threads = threads;
  s.frames = frames;
  s.updateMs = median(times);
  return s;
}

}  // namespace bw
