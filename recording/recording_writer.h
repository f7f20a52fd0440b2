#pragma once
/// Writes a run's recording (FORMAT.md): the scene's geometry once, then after every step the
/// frame's edits, splits, new grids and bodies, changed terrain chunks, the poses and states of
/// every body that is not static, the stage times and (optionally) the contacts.
///
///   bw::World world(scene, threads);
///   bw::RecordingWriter rec(world, "run.bwr", {.contacts = true});
///   bw::ContainmentTracker inside(world);
///   for (int f = 0; f < 300; ++f) { world.step(); rec.frame(world, inside.update()); }
///   rec.finish();
///
/// Recording reads the world only between steps and changes nothing it simulates (the state
/// hash is the same with and without it); it turns the world's edit log on (World::recordEdits).
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "recording/recording_format.h"
#include "world/containment.h"
#include "world/world.h"

namespace bw {

struct RecordingOptions {
  bool contacts = false;  ///< CONT blocks: the last substep's contacts of every frame
  bool gzip = false;      ///< one gzip stream (smaller, ~10x slower to write) instead of the bytes as they are
  /// Grids with more bricks than this at the start are recorded by their OctoBVH boxes only
  /// (NODE), not brick by brick: a page draws ~10^5-10^6 instanced bricks at interactive rates.
  uint32_t maxGridBricks = 300'000;
  /// NODE blocks carry these levels of boxes per grid: BrickGrid::coverBoxes(8^k), k = 1..this.
  int nodeLevels = 5;
};

class RecordingWriter {
 public:
  /// Opens `path` (InvalidInput naming it when it cannot be written) and writes the header and
  /// the scene as it is now. `threads` is only noted in the header.
  RecordingWriter(World& world, const std::string& path, RecordingOptions options, int threads);
  ~RecordingWriter();
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;

  /// The step just made: call once after every World::step(), with the containment report of
  /// the same state (bodies in it are drawn as inside solid).
  void frame(const World& world, const ContainmentReport& inside);
  /// `--submission all`: the render frame's times of one submission mode, the run's frames made
  /// again in that mode (ms per frame: transform update, submission, commit, wait for the render
  /// thread; one value per recorded frame each, else InvalidInput). After the last frame().
  void submissionMode(const std::string& name, std::span<const double> update, std::span<const double> submission,
                      std::span<const double> commit, std::span<const double> wait);
  /// Writes END_ and closes the file; throws InvalidInput when a write failed (a full disk).
  void finish();
  /// Names of the stage times each frame carries, in order (the header's `stages`).
  static const std::vector<std::string>& stageNames();
  uint32_t frames() const { return frames_; }
  /// Decompressed bytes written so far.
  uint64_t bytes() const { return bytes_; }

 private:
  void block(uint32_t tag, const ByteSink& payload);
  void writeGrid(const World& world, uint32_t grid);
  void writeNodeBoxes(const World& world, uint32_t grid);
  void writeBodies(const World& world, uint32_t first);
  /// TERR with the chunks of terrain `t` listed (all of them when `chunks` is null).
  void writeTerrainChunks(const World& world, uint32_t t, const std::vector<uint64_t>* chunks);
  /// Terrain chunks whose voxels changed since the last look, and their neighbours (a chunk's
  /// mesh reads one voxel into each neighbour); updates the kept hashes.
  std::vector<uint64_t> changedChunks(const World& world, uint32_t t);
  void putPose(ByteSink& s, const Vec3d& position, const Quatf& rotation) const;
  /// Keeps grid `g`'s mirror (below) up to date with one edit.
  void mirrorEdit(const BrickEdit& e);
  /// The edits that turn grid `g`'s mirror into the grid (removals, then placements), appended
  /// to `out`; the mirror then equals the grid. For grids edited through World::editGrid().
  void diffWithMirror(const World& world, uint32_t g, std::vector<BrickEdit>& out);

  std::string path_;
  void* file_ = nullptr;  // gzFile
  bool failed_ = false;
  RecordingOptions options_;
  Vec3d origin_ = Vec3d::Zero();
  uint32_t gridsWritten_ = 0, terrainsWritten_ = 0, bodiesWritten_ = 0, frames_ = 0;
  uint64_t bytes_ = 0;
  // Per terrain: a hash of each stored chunk's voxels, by chunk key (what changedChunks compares).
  std::vector<std::unordered_map<uint64_t, uint64_t>> chunkHashes_;
  std::vector<uint8_t> states_;  // per body, this frame's RecordedState (scratch)
  // Per grid recorded brick by brick, its bricks as a reader of the recording has them so far,
  // by brick id (live: 1). An edit through World::editGrid() is not logged brick by brick: the
  // grid is compared with its mirror to record what changed. Empty for grids recorded as boxes.
  struct Mirror {
    bool kept = false;  // the grid is recorded brick by brick
    std::vector<Brick> bricks;
    std::vector<uint8_t> live;
  };
  std::vector<Mirror> mirrors_;
  std::vector<BrickEdit> edits_;  // the frame's EDIT entries (scratch)
  ByteSink scratch_;
};

}  // namespace bw
