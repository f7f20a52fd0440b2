#pragma once
/// Reads a recording (FORMAT.md) back, checking every block: what `brickworld view` embeds and
/// what tests compare with the run. A bad file throws InvalidInput naming the file, the block
/// (its tag, number and byte offset) and what was wrong.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "collision/bricks/brick.h"
#include "recording/recording_format.h"
#include "world/scene_description.h"

namespace bw {

struct RecordedGrid {
  uint32_t index = 0;
  std::string name;
  int32_t frame = -1;                ///< the frame it appeared in (-1: the scene's start)
  uint32_t brickCount = 0;           ///< bricks the grid had
  std::vector<uint32_t> brickIds;    ///< as written (none when the grid had more than the recording's limit)
  std::vector<Brick> bricks;
  std::vector<std::vector<Aabb>> nodeLevels;  ///< NODE: its OctoBVH boxes, coarse to fine (grid frame)
};

struct RecordedBody {
  MotionType motion = MotionType::Static;
  RecordedKind kind = RecordedKind::Box;
  uint32_t ref = 0xFFFFFFFFu;        ///< grid or terrain index
  Vec3f size = Vec3f::Zero();
  Vec3f shapePosition = Vec3f::Zero();
  Quatf shapeRotation = Quatf::Identity();
  Vec3f position = Vec3f::Zero();    ///< relative to the origin, at `frame`
  Quatf rotation = Quatf::Identity();
  int32_t frame = -1;                ///< the frame it appeared in (-1: the scene's start)
};

struct RecordedEdit {
  uint32_t grid = 0, brick = 0;
  bool placed = false;
  Brick value;
};

struct RecordedFrame {
  uint32_t index = 0;
  std::vector<RecordedEdit> edits;   ///< EDIT, in order
  std::vector<float> stageMs;        ///< one per Recording::stages
  uint32_t bodyCount = 0;            ///< bodies in the world after the step
  std::vector<uint32_t> ids;         ///< bodies that are not static
  std::vector<Vec3f> positions;      ///< relative to the origin
  std::vector<Quatf> rotations;
  std::vector<RecordedState> states;
  uint32_t bricksEdited = 0, splits = 0, terrainChunks = 0, contacts = 0;
};

/// MODE: one submission mode's render-frame times, per frame.
struct RecordedSubmissionMode {
  std::string name;
  std::vector<float> updateMs, submissionMs, commitMs, waitMs;
};

struct Recording {
  nlohmann::json head;
  Vec3d origin = Vec3d::Zero();
  std::vector<std::string> stages;
  bool contacts = false;
  std::vector<RecordedGrid> grids;   ///< by grid index
  std::vector<uint32_t> terrainChunks;  ///< per terrain: chunks in its first TERR block
  /// Per terrain, per chunk key (chunkKey): triangles of its latest mesh (0: gone).
  std::vector<std::map<uint64_t, uint32_t>> terrainTriangles;
  std::vector<RecordedBody> bodies;  ///< by body id
  std::vector<RecordedFrame> frames;
  std::vector<RecordedSubmissionMode> modes;  ///< `--submission all` runs
  bool complete = false;             ///< END_ was read (the run finished)
};

/// The bytes of recording `path`, decompressed when it is gzip (InvalidInput when it cannot be read).
std::vector<uint8_t> readRecordingBytes(const std::string& path);
/// Parses and checks decompressed recording bytes; `name` is used in errors.
Recording parseRecording(std::span<const uint8_t> bytes, const std::string& name);
/// Both.
Recording readRecording(const std::string& path);

}  // namespace bw
