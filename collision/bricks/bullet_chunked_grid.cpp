#include "collision/bricks/bullet_chunked_grid.h"

#include <algorithm>
#include <string>

#include "collision/core/errors.h"
#include "collision/core/hash.h"

namespace bw {

size_t BulletChunkedGrid::CellHash::operator()(const BulletChunkCell& c) const {
  return size_t(hashCombine(hashCombine(uint64_t(c[0]), uint64_t(c[1])), uint64_t(c[2])));
}

BulletChunkedGrid::BulletChunkedGrid(const BrickGrid& grid, float chunkSize, BulletBrickShapes& shapes)
    : chunkSize_(chunkSize), shapes_(shapes) {
  chunks_ = buildBulletChunks(grid, chunkSize, shapes, &childBricks_);
  for (uint32_t c = 0; c < chunks_.size(); ++c) {
    const std::vector<uint32_t>& ids = childBricks_[c];
    chunkOfCell_.emplace(bulletChunkCell(grid.brick(ids.front()).position, chunkSize), c);
    for (uint32_t k = 0; k < ids.size(); ++k) {
      if (ids[k] >= chunkOf_.size()) {
        chunkOf_.resize(ids[k] + 1, kNone);
        childOf_.resize(ids[k] + 1, kNone);
      }
      chunkOf_[ids[k]] = c;
      childOf_[ids[k]] = k;
    }
    bricks_ += ids.size();
  }
  touchedMark_.assign(chunks_.size(), 0);
  shrink_.assign(chunks_.size(), 0);
}

void BulletChunkedGrid::touch(uint32_t chunk) {
  if (touchedMark_[chunk]) return;
  touchedMark_[chunk] = 1;
  touched_.push_back(chunk);
}

void BulletChunkedGrid::place(uint32_t id, const Brick& brick) {
  if (id < chunkOf_.size() && chunkOf_[id] != kNone)
    throw InvalidInput("BulletChunkedGrid::place: brick " + std::to_string(id) + " already has a child");
  const BulletChunkCell cell = bulletChunkCell(brick.position, chunkSize_);
  auto [it, fresh] = chunkOfCell_.try_emplace(cell, uint32_t(chunks_.size()));
  if (fresh) {
    BulletBrickChunk c;
    c.origin = bulletChunkOrigin(cell, chunkSize_);
    c.shape = std::make_unique<btCompoundShape>(true);
    chunks_.push_back(std::move(c));
    childBricks_.emplace_back();
    touchedMark_.push_back(0);
    shrink_.push_back(0);
  }
  const uint32_t chunk = it->second;
  BulletBrickChunk& c = chunks_[chunk];
  // Bullet grows the compound's AABB by the new child itself.
  c.shape->addChildShape(BulletBrickShapes::childTransform(brick, c.origin), shapes_.shapeFor(brick));
  if (id >= chunkOf_.size()) {
    chunkOf_.resize(id + 1, kNone);
    childOf_.resize(id + 1, kNone);
  }
  chunkOf_[id] = chunk;
  childOf_[id] = uint32_t(childBricks_[chunk].size());
  childBricks_[chunk].push_back(id);
  ++c.bricks;
  ++bricks_;
  touch(chunk);
}

void BulletChunkedGrid::remove(uint32_t id) {
  if (id >= chunkOf_.size() || chunkOf_[id] == kNone)
    throw InvalidInput("BulletChunkedGrid::remove: brick " + std::to_string(id) + " has no child");
  const uint32_t chunk = chunkOf_[id], child = childOf_[id];
  BulletBrickChunk& c = chunks_[chunk];
  std::vector<uint32_t>& ids = childBricks_[chunk];
  // The chunk's box can only shrink when the removed child reached its side: only then is
  // it recalculated (finishEdits), as every child's box is taken again for it.
  btVector3 lo, hi, childLo, childHi;
  c.shape->getAabb(btTransform::getIdentity(), lo, hi);
  const btCompoundShapeChild& entry = c.shape->getChildList()[child];
  entry.m_childShape->getAabb(entry.m_transform, childLo, childHi);
  const btScalar slack = 1e-4f * chunkSize_;
  for (int k = 0; k < 3; ++k)
    if (childLo[k] <= lo[k] + slack || childHi[k] >= hi[k] - slack) shrink_[chunk] = 1;
  // Bullet swaps the last child into the removed one's slot; the map follows it.
  c.shape->removeChildShapeByIndex(int(child));
  const uint32_t moved = ids.back();
  ids[child] = moved;
  childOf_[moved] = child;
  ids.pop_back();
  chunkOf_[id] = childOf_[id] = kNone;
  --c.bricks;
  --bricks_;
  touch(chunk);
}

const std::vector<uint32_t>& BulletChunkedGrid::finishEdits() {
  std::sort(touched_.begin(), touched_.end());
  for (uint32_t c : touched_) {
    touchedMark_[c] = 0;
    if (shrink_[c]) chunks_[c].shape->recalculateLocalAabb();  // (an emptied one: no box, so a refill grows from nothing)
    shrink_[c] = 0;
  }
  finished_.swap(touched_);
  touched_.clear();
  return finished_;
}

}  // namespace bw
