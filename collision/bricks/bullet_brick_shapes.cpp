#include "collision/bricks/bullet_brick_shapes.h"

#include <Eigen/Dense>

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

namespace {
// Corners of the convex region n . x <= d of `count` planes: every point where three planes
// meet that lies inside all of them (within `tolerance`). note: Bullet's
// btGeometryUtil::getVerticesFromPlaneEquations accepts points up to 1 cm outside, which on a
// shrunk brick is most of the margin.
std::vector<Vec3f> planeCorners(const BrickPlane* planes, int count, float tolerance) {
  std::vector<Vec3f> corners;
  for (int i = 0; i < count; ++i)
    for (int j = i + 1; j < count; ++j)
      for (int k = j + 1; k < count; ++k) {
        Eigen::Matrix3d m;
        m.row(0) = planes[i].n.cast<double>().transpose();
        m.row(1) = planes[j].n.cast<double>().transpose();
        m.row(2) = planes[k].n.cast<double>().transpose();
        if (std::abs(m.determinant()) < 1e-9) continue;  // two of them parallel
        const Eigen::Vector3d x = m.partialPivLu().solve(Eigen::Vector3d(planes[i].d, planes[j].d, planes[k].d));
        bool inside = true;
        for (int p = 0; p < count && inside; ++p) inside = planes[p].n.cast<double>().dot(x) <= double(planes[p].d) + tolerance;
        if (inside) corners.push_back(x.cast<float>());
      }
  return corners;
}
}  // namespace

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
    // Wedges, corner wedges, oval cylinders: a hull with Bullet's margin, the expert way: the
    // shape's face planes moved in by the margin, so hull plus margin is the brick (rounded at
    // its edges) and GJK keeps its margin to work with. The margin is Bullet's 4 cm, at most a
    // tenth of the smallest half size (as btBoxShape caps its own).
    Brick canonical = b;
    canonical.position = Vec3f::Zero();
    canonical.rotation = AxisRotation::identity();
    const float margin = std::min(0.04f, 0.1f * b.halfSize.minCoeff());
    BrickPlane planes[kMaxBrickPlanes];
    const int n = canonicalBrickPlanes(canonical, planes);
    for (int i = 0; i < n; ++i) planes[i].d -= margin;
    const std::vector<Vec3f> points = planeCorners(planes, n, 1e-5f * (1.f + b.halfSize.maxCoeff()));
    auto hull = std::make_unique<btConvexHullShape>();
    for (size_t i = 0; i < points.size(); ++i) hull->addPoint(btVector3(points[i].x(), points[i].y(), points[i].z()), i + 1 == points.size());
    hull->setMargin(margin);
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

BulletChunkCell bulletChunkCell(const Vec3f& p, float chunkSize) {
  return {int64_t(std::floor(p.x() / chunkSize)), int64_t(std::floor(p.y() / chunkSize)), int64_t(std::floor(p.z() / chunkSize))};
}

Vec3f bulletChunkOrigin(const BulletChunkCell& cell, float chunkSize) {
  return Vec3f((float(cell[0]) + 0.5f) * chunkSize, (float(cell[1]) + 0.5f) * chunkSize, (float(cell[2]) + 0.5f) * chunkSize);
}

std::vector<BulletBrickChunk> buildBulletChunks(const BrickGrid& grid, float chunkSize, BulletBrickShapes& shapes,
                                                std::vector<std::vector<uint32_t>>* childBricks) {
  requireInRange(chunkSize, 1e-6, 1e9, "buildBulletChunks", "chunkSize");
  std::map<BulletChunkCell, std::vector<uint32_t>> cells;  // ordered: chunks come out in cube order
  grid.forEachBrick([&](uint32_t id) { cells[bulletChunkCell(grid.brick(id).position, chunkSize)].push_back(id); });
  std::vector<BulletBrickChunk> chunks;
  chunks.reserve(cells.size());
  if (childBricks) childBricks->clear();
  for (auto& [cell, ids] : cells) {
    std::sort(ids.begin(), ids.end());  // the same children order whatever the pool's order
    BulletBrickChunk c;
    c.origin = bulletChunkOrigin(cell, chunkSize);
    c.shape = std::make_unique<btCompoundShape>(true, int(ids.size()));
    for (uint32_t id : ids) {
      const Brick& b = grid.brick(id);
      c.shape->addChildShape(BulletBrickShapes::childTransform(b, c.origin), shapes.shapeFor(b));
    }
    // The compound's tree was built by incremental inserts; a static chunk's is rebuilt
    // top-down once, as a user does (its leaves, each child's node, survive the rebuild).
    c.shape->getDynamicAabbTree()->optimizeTopDown();
    c.bricks = uint32_t(ids.size());
    chunks.push_back(std::move(c));
    if (childBricks) childBricks->push_back(std::move(ids));
  }
  return chunks;
}

}  // namespace bw
