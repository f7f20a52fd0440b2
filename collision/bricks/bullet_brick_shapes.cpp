#include "collision/bricks/bullet_brick_shapes.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <map>

#include "collision/bricks/brick_geometry.h"
#include "collision/core/argument_checks.h"
#include "collision/core/hash.h"

namespace bw {

size_t BulletBrickShapes::KeyHash::operator()(const Key& k) const {
  uint64_t h = hashCombine(k.shape, k.sides);
  for (float f : {k.hx, k.hy, k.hz}) h = hashCombine(h, std::bit_cast<uint32_t>(f));
  return size_t(h);
}

btCollisionShape* BulletBrickShapes::shapeFor(const Brick& b) {
  const Key key{uint8_t(b.shape), b.shape == BrickShape::Cylinder ? b.sides : uint8_t(0), b.halfSize.x(), b.halfSize.y(),
                b.halfSize.z()};
  if (auto it = byKey_.find(key); it != byKey_.end()) return it->second;
  const btVector3 half(b.halfSize.x(), b.halfSize.y(), b.halfSize.z());
  std::unique_ptr<btCollisionShape> shape;
  if (b.shape == BrickShape::Box) {
    shape = std::make_unique<btBoxShape>(half);  // its margin lies inside the half extents: exact
  } else if (b.shape == BrickShape::Cylinder && b.halfSize.x() == b.halfSize.y()) {
    shape = std::make_unique<btCylinderShapeZ>(half);  // round, margin inside like the box
  } else {
    // Wedges, corner wedges, oval cylinders: the hull of the exact vertices. A hull's margin
    // lies outside its points, so keep it small beside the brick (Bullet's default is 4 cm).
    Brick canonical = b;
    canonical.position = Vec3f::Zero();
    canonical.rotation = AxisRotation::identity();
    Vec3f v[kMaxBrickVertices];
    const int n = canonicalBrickVertices(canonical, v);
    auto hull = std::make_unique<btConvexHullShape>();
    for (int i = 0; i < n; ++i) hull->addPoint(btVector3(v[i].x(), v[i].y(), v[i].z()), i + 1 == n);
    hull->setMargin(std::min(0.04f, 0.1f * b.halfSize.minCoeff()));
    shape = std::move(hull);
  }
  btCollisionShape* raw = shape.get();
  shapes_.push_back(std::move(shape));
  byKey_.emplace(key, raw);
  return raw;
}

btTransform BulletBrickShapes::childTransform(const Brick& b, const Vec3f& origin) {
  const Quatf q = b.rotation.quaternion();
  const Vec3f p = b.position - origin;
  return btTransform(btQuaternion(q.x(), q.y(), q.z(), q.w()), btVector3(p.x(), p.y(), p.z()));
}

size_t BulletBrickShapes::bytes() const {
  size_t total = 0;
  for (const auto& s : shapes_) {
    if (auto* hull = dynamic_cast<const btConvexHullShape*>(s.get()))
      total += sizeof(btConvexHullShape) + size_t(hull->getNumPoints()) * sizeof(btVector3);
    else
      total += std::max(sizeof(btCylinderShapeZ), sizeof(btBoxShape));
  }
  return total;
}

std::vector<BulletBrickChunk> buildBulletChunks(const BrickGrid& grid, float chunkSize, BulletBrickShapes& shapes) {
  requireInRange(chunkSize, 1e-6, 1e9, "buildBulletChunks", "chunkSize");
  using Cell = std::array<int64_t, 3>;
  std::map<Cell, std::vector<uint32_t>> cells;  // ordered: chunks come out in cube order
  grid.forEachBrick([&](uint32_t id) {
    const Vec3f& p = grid.brick(id).position;
    cells[{int64_t(std::floor(p.x() / chunkSize)), int64_t(std::floor(p.y() / chunkSize)), int64_t(std::floor(p.z() / chunkSize))}]
        .push_back(id);
  });
  std::vector<BulletBrickChunk> chunks;
  chunks.reserve(cells.size());
  for (auto& [cell, ids] : cells) {
    std::sort(ids.begin(), ids.end());  // the same children order whatever the pool's order
    BulletBrickChunk c;
    c.origin = Vec3f((float(cell[0]) + 0.5f) * chunkSize, (float(cell[1]) + 0.5f) * chunkSize, (float(cell[2]) + 0.5f) * chunkSize);
    c.shape = std::make_unique<btCompoundShape>(true, int(ids.size()));
    for (uint32_t id : ids) {
      const Brick& b = grid.brick(id);
      c.shape->addChildShape(BulletBrickShapes::childTransform(b, c.origin), shapes.shapeFor(b));
    }
    c.bricks = uint32_t(ids.size());
    chunks.push_back(std::move(c));
  }
  return chunks;
}

}  // namespace bw
