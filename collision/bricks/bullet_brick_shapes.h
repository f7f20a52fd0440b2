#pragma once
/// Bricks as a Bullet expert builds them, for the baselines (bench_grid, the world's Bullet
/// engine): one shared shape per distinct brick (boxes as btBoxShape, round cylinders as
/// btCylinderShapeZ, wedges, corner wedges and oval cylinders as btConvexHullShape of their
/// face planes moved in by the margin, so hull plus margin is the brick), placed as compound children by the brick's position and rotation, and the
/// grid cut into cubic chunks, each its own btCompoundShape. A chunk is what a pair walks:
/// Bullet's compound algorithm touches every child of a compound once per pair and step, so
/// users split large static structures into chunks instead of one compound of every brick.
///
///   BulletBrickShapes shapes;
///   std::vector<BulletBrickChunk> chunks = buildBulletChunks(grid, 8.f, shapes);
///   // each chunk: a btCollisionObject at gridPose * btTransform(identity, chunk.origin)
#include <btBulletCollisionCommon.h>
#include <array>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "collision/bricks/brick_grid.h"

namespace bw {

/// Owns the shared child shapes; one per distinct (shape, half size, sides).
class BulletBrickShapes {
 public:
  BulletBrickShapes() = default;
  BulletBrickShapes(const BulletBrickShapes&) = delete;
  BulletBrickShapes& operator=(const BulletBrickShapes&) = delete;
  /// The shared shape of this brick's canonical (unrotated, centred) shape.
  btCollisionShape* shapeFor(const Brick& b);
  /// The brick's rotation and position, relative to `origin` (grid frame).
  static btTransform childTransform(const Brick& b, const Vec3f& origin);
  /// Distinct shapes made so far.
  size_t distinctShapes() const { return shapes_.size(); }
  /// Approximate heap bytes of the shared shapes (hull points included).
  size_t bytes() const;

 private:
  struct Key {
    uint8_t shape, sides;
    float hx, hy, hz;
    bool operator==(const Key&) const = default;
  };
  struct KeyHash {
    size_t operator()(const Key& k) const;
  };
  std::unordered_map<Key, btCollisionShape*, KeyHash> byKey_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
};

/// One chunk compound; its children are placed relative to `origin` (grid frame).
struct BulletBrickChunk {
  std::unique_ptr<btCompoundShape> shape;
  Vec3f origin;
  uint32_t bricks = 0;
};

/// Cuts the grid into cubes of `chunkSize` (grid units) by brick centre and builds one compound
/// per non-empty cube (its dynamic AABB tree on, rebuilt top-down). Chunks come out in a fixed order (by cube
/// coordinates), so two builds of the same grid are equal. Throws InvalidInput when chunkSize
/// is not positive and finite.
/// `childBricks`, when given, receives each chunk's brick ids in child order.
std::vector<BulletBrickChunk> buildBulletChunks(const BrickGrid& grid, float chunkSize, BulletBrickShapes& shapes,
                                                std::vector<std::vector<uint32_t>>* childBricks = nullptr);

/// The cube of edge `chunkSize` holding grid-local point `p`, and that cube's centre (a chunk's origin).
using BulletChunkCell = std::array<int64_t, 3>;
BulletChunkCell bulletChunkCell(const Vec3f& p, float chunkSize);
Vec3f bulletChunkOrigin(const BulletChunkCell& cell, float chunkSize);

/// Bytes Bullet holds for one compound child: the child record and two tree nodes.
constexpr size_t kBulletCompoundChildBytes = sizeof(btCompoundShapeChild) + 2 * sizeof(btDbvtNode);

}  // namespace bw
