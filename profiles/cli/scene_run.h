#pragma once
// Running a scene from the CLI (`brickworld run SCENE`): shared by the run and sweep commands.
#include <cstdint>
#include <string>

#include "render_batch/submission_mode.h"
#include "world/bullet_baseline.h"

namespace bw::cli {

struct SceneRunOptions {
  uint32_t driftAfter = 0;  ///< report how far dynamic bodies move from this frame to the end (0: off)
  std::string scene;        ///< path, or the name of a scene in profiles/scenes
  uint32_t frames = 0;      ///< 0: the scene's own setting
  int threads = 1;
  std::string csvPath;      ///< per-frame stage times
  std::string tracePath;    ///< Chrome trace of the whole run
  std::string recordPath;   ///< a recording of the run (recording/FORMAT.md), for `brickworld view`
  bool recordContacts = false;  ///< the recording carries every frame's contacts
  bool recordGzip = false;      ///< the recording is one gzip stream
  uint32_t recordBricks = 300'000;  ///< grids above this many bricks are recorded as their OctoBVH boxes
  int recordDepth = 5;              ///< levels of OctoBVH boxes recorded per grid (RecordingOptions::nodeLevels)
  bool json = false;
  bool progress = true;
  /// brickworld; bullet (Bullet as an expert sets it up) or bullet-naive (one compound per grid);
  /// both (brickworld and bullet) or all (the three): same initial state, ratios printed.
  std::string engine = "brickworld";
  float bulletChunk = BulletBaseline::kDefaultChunkSize;  ///< edge of the expert Bullet setup's chunk compounds (m)
  std::string bulletKinematic = "auto";                   ///< how the expert setup holds kinematic grids (KinematicGrids)
  std::string sleeping;     ///< "on"/"off" overrides the scene's setting; empty keeps it
  /// Scenes with attachments: batched, mutex or concurrent (per-object queues, one command per
  /// record, like for like with the batch), or all (the three from the same initial state).
  std::string submission;  ///< empty: batched (and no complaint about a scene without attachments)
};

/// The submission mode a --submission name stands for (batched, mutex, concurrent).
SubmissionMode submissionModeFromName(const std::string& name);

/// Runs the scene and prints the report; returns the process exit code.
int runScene(const SceneRunOptions& options);

/// Resolves a scene argument to a file path (a path as given, else profiles/scenes/NAME.json).
std::string resolveScenePath(const std::string& scene);

}  // namespace bw::cli
