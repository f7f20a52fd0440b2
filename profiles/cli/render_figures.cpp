#include "cli/render_figures.h"

#include <cstdio>

namespace bw::cli {

void RenderFigures::add(const StepStats& s) {
  const RenderStageStats& r = s.render;
  chunkUpkeep.v.push_back(s.renderChunksMs);
  cellsRefreshed += s.renderChunks.cellsRefreshed;
  cellsRecomputed += s.renderChunks.cellsRecomputed;
  chunksAdded += s.renderChunks.chunksAdded;
  chunksHidden += s.renderChunks.chunksHidden;
  update.v.push_back(r.updateMs);
  submission.v.push_back(r.submissionMs);
  commit.v.push_back(r.commitMs);
  wait.v.push_back(r.waitMs);
  gameThread.v.push_back(r.updateMs + r.submissionMs + r.commitMs);
  primitives += r.primitives;
  lights += r.lights;
  movedBodies += r.movedBodies;
  ++frames;
}

void RenderFigures::finish(World& world) {
  sceneHash = world.renderScene().stateHash();
  renderBusyMs = double(world.render()->renderStats().busyNanoseconds) * 1e-6;
  renderStage = world.renderStage();
  spans = world.profiler().workSpans(frames, renderStage, renderStage + kRenderCommitStage);
  mode = world.render()->mode();
}

double RenderFigures::predictedMs(int threads, bool withUpdate) const {
  double total = 0;
  for (const WorkSpan& ws : spans) total += predictedRenderMs(ws, renderStage, threads, withUpdate);
  return spans.empty() ? 0 : total / double(spans.size());
}

double RenderFigures::wakeBesideMs() const {
  double total = 0;
  for (const WorkSpan& ws : spans) total += ws.besideWorkMs;
  return spans.empty() ? 0 : total / double(spans.size());
}

nlohmann::json RenderFigures::json(const World& world) const {
  const WorldRender& r = *world.render();
  nlohmann::json j{{"submission", submissionModeName(r.mode())},
                   {"attachments", r.store().size()},
                   {"primitives", r.store().primitiveCount()},
                   {"lights", r.store().lightCount()},
                   {"moved_bodies_per_frame", double(movedBodies) / frames},
                   {"primitive_records_per_frame", double(primitives) / frames},
                   {"light_records_per_frame", double(lights) / frames},
                   {"transform_update", update.json()},
                   {"submission_stage", submission.json()},
                   {"commit", commit.json()},
                   {"wait_for_render_thread", wait.json()},
                   {"render_wake_beside_ms_per_frame", wakeBesideMs()},
                   {"game_thread_submission_commit_ms_per_frame", (submission.sum() + commit.sum()) / frames},
                   {"render_thread_busy_ms_per_frame", renderBusyMs / frames},
                   {"render_scene_hash", sceneHash}};
  for (int p : {1, 2, 4, 8, 16}) j["predicted_submission_commit_ms"][std::to_string(p)] = predictedMs(p);
  j["chunks"] = {{"upkeep", chunkUpkeep.json()},
                 {"cells_refreshed_per_frame", double(cellsRefreshed) / frames},
                 {"cells_recomputed", cellsRecomputed},
                 {"chunks_added", chunksAdded},
                 {"chunks_hidden", chunksHidden}};
  return j;
}

void RenderFigures::print(const World& world) const {
  const WorldRender& r = *world.render();
  std::printf("  render (%s submission): %u attachments (%u primitives, %u lights); per frame %.0f bodies moved, %.0f + %.0f records\n",
              submissionModeName(r.mode()), r.store().size(), r.store().primitiveCount(), r.store().lightCount(),
              double(movedBodies) / frames, double(primitives) / frames, double(lights) / frames);
  for (auto [name, s] : {std::pair<const char*, const Series*>{"transform", &update}, {"submission", &submission}, {"commit", &commit},
                         {"render wait", &wait}})
    std::printf("  %-11s %7.3f ms %7.3f ms %7.3f ms\n", name, s->quantile(0.5), s->quantile(0.95), s->max());
  if (cellsRefreshed || chunksAdded)
    std::printf("  render chunks: %.0f cells a frame followed edits and parts (%llu rebuilt from the grid), %llu chunks added, %llu "
                "hidden; upkeep %.3f ms median, %.3f ms max a frame (in transform)\n",
                double(cellsRefreshed) / frames, (unsigned long long)cellsRecomputed, (unsigned long long)chunksAdded,
                (unsigned long long)chunksHidden, chunkUpkeep.quantile(0.5), chunkUpkeep.max());
  std::printf("  render thread busy %.3f ms per frame; its wake %.3f ms per frame beside the next frame; render scene hash %016llx\n",
              renderBusyMs / frames, wakeBesideMs(), (unsigned long long)sceneHash);
  std::printf("  submission + commit predicted at 1/2/4/8/16 threads: %.3f %.3f %.3f %.3f %.3f ms per frame\n", predictedMs(1),
              predictedMs(2), predictedMs(4), predictedMs(8), predictedMs(16));
}

bool compareSubmissionModes(const SceneDescription& scene, int threads, uint32_t frames, World& batchedWorld,
                            const RenderFigures& batched, bool json, nlohmann::json& out,
                            const std::function<void(const char* mode, const RenderFigures&)>& onMode) {
  bool same = true;
  const double batchedGame = (batched.submission.sum() + batched.commit.sum()) / frames;
  if (!json) std::printf("submission modes from the same initial state (%d thread(s), %u frames):\n", threads, frames);
  if (!json)
    std::printf("  %-28s %14s %14s %14s %18s  %s\n", "mode", "submit+commit", "at 16 threads", "render busy", "vs batched (16 thr)",
                "render scene hash");
  auto row = [&](const char* mode, const RenderFigures& f) {
    const double game = (f.submission.sum() + f.commit.sum()) / frames;
    const double p16 = f.predictedMs(16);
    const double ratio = p16 / std::max(batched.predictedMs(16), 1e-9);
    if (json) {
      out[mode] = {{"submission_commit_ms_per_frame", game},
                   {"predicted_submission_commit_ms_16_threads", p16},
                   {"render_thread_busy_ms_per_frame", f.renderBusyMs / frames},
                   {"over_batched_measured", game / std::max(batchedGame, 1e-9)},
                   {"over_batched_predicted_16_threads", ratio},
                   {"render_scene_hash", f.sceneHash}};
    } else {
      std::printf("  %-28s %11.3f ms %11.3f ms %11.3f ms %8.2fx / %5.2fx  %016llx\n", mode, game, p16, f.renderBusyMs / frames,
                  game / std::max(batchedGame, 1e-9), ratio, (unsigned long long)f.sceneHash);
    }
  };
  row(submissionModeName(SubmissionMode::Batched), batched);
  if (onMode) onMode(submissionModeName(SubmissionMode::Batched), batched);
  for (SubmissionMode mode : {SubmissionMode::PerObjectMutexNoRadius, SubmissionMode::PerObjectConcurrentNoRadius}) {
    World world(scene, threads, mode);
    RenderFigures f;
    for (uint32_t k = 0; k < frames; ++k) {
      world.step();
      f.add(world.lastStats());
    }
    f.finish(world);
    row(submissionModeName(mode), f);
    if (onMode) onMode(submissionModeName(mode), f);
    same = same && f.sceneHash == batched.sceneHash && world.stateHash() == batchedWorld.stateHash();
  }
  if (json) out["render_scene_hashes_equal"] = same;
  else std::printf("  render scene hashes and state hashes %s across modes\n", same ? "identical" : "DIFFER");
  return same;
}

}  // namespace bw::cli
