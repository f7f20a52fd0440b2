#pragma once
/// A grid as chunk compounds (bullet_brick_shapes.h) kept editable as a Bullet user keeps
/// them: a brick placed becomes a child of its cube's chunk (a new chunk when the cube had
/// none), a brick removed leaves its chunk's children (Bullet moves the last child into its
/// slot; the map from brick to child follows), and once per frame an edited chunk's local AABB
/// is recalculated when a removed child reached its side (Bullet's removeChildShapeByIndex
/// leaves it as it was; addChildShape grows it). The objects
/// and parent compounds holding the chunks are the caller's: after finishEdits() it refreshes
/// their broadphase boxes and child entries for the chunks listed (and drops the ones left
/// empty).
///
///   BulletChunkedGrid chunks(grid, 16.f, shapes);
///   chunks.remove(id);  chunks.place(id2, brick);
///   for (uint32_t c : chunks.finishEdits()) ... refresh chunk c's holders ...
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "collision/bricks/bullet_brick_shapes.h"

namespace bw {

class BulletChunkedGrid {
 public:
  /// Throws InvalidInput when chunkSize is not positive and finite.
  BulletChunkedGrid(const BrickGrid& grid, float chunkSize, BulletBrickShapes& shapes);
  /// Chunks in the order made: the build's (cube order), then new ones as edits made them.
  /// A chunk whose bricks fell to 0 stays in the list (empty, its holders drop it).
  const std::vector<BulletBrickChunk>& chunks() const { return chunks_; }
  /// Adds brick `id` (a grid id not present) as a child of its cube's chunk.
  void place(uint32_t id, const Brick& brick);
  /// Removes brick `id`'s child. InvalidInput when the id has no child.
  void remove(uint32_t id);
  /// The chunks edited since the last call, ascending, each once, their local AABBs bounding
  /// their children again (recalculated when they may have shrunk; an emptied one has no box
  /// until it is refilled: its holders drop it).
  const std::vector<uint32_t>& finishEdits();
  /// Bricks held, over every chunk.
  uint64_t brickCount() const { return bricks_; }

 private:
  struct CellHash {
    size_t operator()(const BulletChunkCell& c) const;
  };
  void touch(uint32_t chunk);
  float chunkSize_;
  BulletBrickShapes& shapes_;
  std::vector<BulletBrickChunk> chunks_;
  std::vector<std::vector<uint32_t>> childBricks_;  // per chunk: brick id of each child
  std::unordered_map<BulletChunkCell, uint32_t, CellHash> chunkOfCell_;
  std::vector<uint32_t> chunkOf_, childOf_;         // by brick id (kNone: no child)
  std::vector<uint8_t> touchedMark_;
  std::vector<uint8_t> shrink_;                     // per chunk: a removed child reached its box's side
  std::vector<uint32_t> touched_, finished_;
  uint64_t bricks_ = 0;
  static constexpr uint32_t kNone = ~0u;
};

}  // namespace bw
