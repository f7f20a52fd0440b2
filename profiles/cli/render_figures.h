#pragma once
// The render frame's figures in `brickworld run` and `sweep` (scenes with attachments): stage
// times per frame, records, the render thread's busy time, the render-scene hash, and the
// submission + commit time predicted at more threads from the run's work/span.
#include <cstdint>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/series.h"
#include "world/world.h"

namespace bw::cli {

/// Render figures of one run (one submission mode).
struct RenderFigures {
  Series update, submission, commit, wait, gameThread;  ///< ms per frame; gameThread = update + submission + commit
  Series chunkUpkeep;  ///< of update: render chunks brought up to date with edits and parts (ms per frame)
  uint64_t cellsRefreshed = 0, cellsRecomputed = 0, chunksAdded = 0, chunksHidden = 0;  ///< summed over frames
  double renderBusyMs = 0;                             ///< render thread, whole run
  uint64_t primitives = 0, lights = 0, movedBodies = 0;  ///< summed over frames
  uint32_t frames = 0;

  /// Adds one frame (its render stage and render-chunk upkeep).
  void add(const StepStats& s);
  /// Waits for the render thread and takes the busy time and the scene hash (call after the run).
  void finish(World& world);
  uint64_t sceneHash = 0;  ///< render scene hash after the run (set by finish)
  /// Submission + commit ms per frame predicted at p threads from the run's per-job timings:
  /// per stage max(work / p, span), serial zones (the mutex queue's pushes) all in the span.
  /// The transform update too when withUpdate.
  double predictedMs(int threads, bool withUpdate = false) const;
  /// The render thread's wake per frame, run beside the next frame by a worker (on the game
  /// thread itself with one thread): ms per frame.
  double wakeBesideMs() const;
  std::vector<WorkSpan> spans;  ///< per frame (set by finish)
  int renderStage = 0;
  SubmissionMode mode = SubmissionMode::Batched;  ///< set by finish

  nlohmann::json json(const World& world) const;
  void print(const World& world) const;
};

/// `--submission all`: the scene run again in the per-object modes from the same initial state;
/// prints (or adds to out) each mode's figures, the ratios to batched, and whether every
/// render-scene hash equals batched's. Returns false when a hash differs.
/// `onMode` (if set) sees each mode's figures, batched first (the recording keeps them).
bool compareSubmissionModes(const SceneDescription& scene, int threads, uint32_t frames, World& batchedWorld,
                            const RenderFigures& batched, bool json, nlohmann::json& out,
                            const std::function<void(const char* mode, const RenderFigures&)>& onMode = {});

}  // namespace bw::cli
