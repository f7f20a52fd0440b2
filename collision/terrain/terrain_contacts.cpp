#include "collision/terrain/terrain_contacts.h"

#include <BulletCollision/CollisionShapes/btBoxShape.h>
#include <BulletCollision/CollisionShapes/btConvexHullShape.h>
#include <BulletCollision/CollisionShapes/btTriangleShape.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkPairDetector.h>
#include <BulletCollision/NarrowPhaseCollision/btPointCollector.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "collision/core/argument_checks.h"
#include "collision/terrain/triangle_contacts.h"

namespace bw {
namespace {

btVector3 toBt(const Vec3f& v) { return btVector3(v.x(), v.y(), v.z()); }
Vec3f fromBt(const btVector3& v) { return Vec3f(v.x(), v.y(), v.z()); }

/// Shape placed in a chunk's local frame.
struct LocalShape {
  Vec3f centre;
  Mat3f rot;
  Vec3f halfBounds;      ///< half extents of its local AABB
  Vec3f corners[8];      ///< box corners (box only)
  const Vec3f* points;   ///< hull points in shape frame
  uint32_t pointCount;
  Vec3f vertex(uint32_t i) const { return points ? Vec3f(rot * points[i] + centre) : corners[i]; }
  uint32_t vertexCount() const { return points ? pointCount : 8u; }
};

// The half extents of the shape's bounds in a frame where its rotation is `rot`.
Vec3f placedHalfBounds(const QueryShape& s, const Mat3f& rot) {
  switch (s.kind) {
    case QueryShape::Kind::Sphere:
      return Vec3f::Constant(s.radius);
    case QueryShape::Kind::Capsule:
      return (rot.col(2) * s.halfHeight).cwiseAbs() + Vec3f::Constant(s.radius);
    case QueryShape::Kind::Box:
      return rot.cwiseAbs() * s.halfExtents;
    case QueryShape::Kind::Hull: {
      Vec3f m = Vec3f::Zero();
      for (uint32_t i = 0; i < s.pointCount; ++i) m = m.cwiseMax((rot * s.points[i]).cwiseAbs());
      return m;
    }
  }
  return Vec3f::Zero();
}

LocalShape placeShape(const QueryShape& s, const Vec3f& centre, const Quatf& rot) {
  LocalShape l{centre, rot.toRotationMatrix(), Vec3f::Zero(), {}, nullptr, 0};
  l.halfBounds = placedHalfBounds(s, l.rot);
  if (s.kind == QueryShape::Kind::Box) {
    for (int k = 0; k < 8; ++k) {
      const Vec3f sgn((k & 1) ? 1.f : -1.f, (k & 2) ? 1.f : -1.f, (k & 4) ? 1.f : -1.f);
      l.corners[k] = l.rot * s.halfExtents.cwiseProduct(sgn) + centre;
    }
  } else if (s.kind == QueryShape::Kind::Hull) {
    l.points = s.points;
    l.pointCount = s.pointCount;
  }
  return l;
}

/// The bounds placeShape gives (centre -+ halfBounds), without the corners a triangle test needs:
/// what the broadphase steps and the water sum read.
Aabb placedBounds(const QueryShape& s, const Vec3f& centre, const Quatf& rot) {
  return Aabb::fromCenterHalf(centre, placedHalfBounds(s, rot.toRotationMatrix()));
}

/// Box/hull vs one triangle. With the shape's centre in front of the face: its vertices that
/// went in through this triangle (or are within reach over it), each a contact along the face
/// normal, however deep. Otherwise, or when there is none (an edge or corner of the shape on the
/// triangle's edge): GJK + EPA for the deepest point, pushed out along the face when the centre
/// is behind the face itself, with the vertices over the triangle no deeper than that push-out.
/// note: EPA against a lone triangle is not to be trusted for a sunk vertex: its depth can be a
/// shallow slide off the triangle's edge, and for a deep corner it can fail outright (a
/// distance above the speculative reach); before the vertices came first, 29% of tumbling boxes
/// half under flat ground had their deepest corner reported shallower or not at all
/// (terrain_contacts_test, TumblingBoxes...).
int convexTriangle(const btConvexShape& convex, const btTransform& xf, const LocalShape& shape, const Vec3f& a,
                   const Vec3f& b, const Vec3f& c, const Vec3f& n, float spec, TriangleContact* out, int maxOut) {
  // Reject early when the whole shape is behind the face or beyond reach of its plane.
  const float sdCentre = n.dot(shape.centre - a);
  const float reach = shape.halfBounds.dot(n.cwiseAbs());
  if (sdCentre + reach < 0.f || sdCentre - reach > spec) return 0;
  const float tol = 1e-4f * (1.f + shape.centre.cwiseAbs().maxCoeff());
  // The vertices within reach over the triangle, down to `deepest` behind it.
  const auto vertexContacts = [&](float deepest) {
    int k = 0;
    for (uint32_t i = 0; i < shape.vertexCount() && k < maxOut; ++i) {
      const Vec3f v = shape.vertex(i);
      const float sd = n.dot(v - a);
      if (sd > spec || sd < -(deepest + tol)) continue;
      const Vec3f proj = v - sd * n;
      if ((closestPointOnTriangle(proj, a, b, c) - proj).squaredNorm() > tol * tol) continue;
      out[k++] = {proj, n, -sd};
    }
    return k;
  };
  if (sdCentre > 0.f) {
    // The centre in front: a vertex behind the face went in through it where the segment from
    // the centre to the vertex crosses its plane, so that crossing must lie on this triangle
    // (each vertex is then taken by exactly one triangle of a flat surface, however deep).
    // note: the vertex's own projection is no test: a corner resting on a ledge's top edge lies
    // 0.46 m behind the plane of the ledge's side face and projects onto it, but went in (1 mm)
    // through the top; taken from the side it was a 0.46 m contact out of nothing (quarry).
    int k = 0;
    for (uint32_t i = 0; i < shape.vertexCount() && k < maxOut; ++i) {
      const Vec3f v = shape.vertex(i);
      const float sd = n.dot(v - a);
      if (sd > spec) continue;
      const Vec3f through = sd < 0.f ? Vec3f(shape.centre + (v - shape.centre) * (sdCentre / (sdCentre - sd))) : Vec3f(v - sd * n);
      if ((closestPointOnTriangle(through, a, b, c) - through).squaredNorm() > tol * tol) continue;
      out[k++] = {v - sd * n, n, -sd};
    }
    if (k) return k;
  }

  btTriangleShape tri(toBt(a), toBt(b), toBt(c));
  tri.setMargin(0.f);
  btVoronoiSimplexSolver simplex;
  btGjkEpaPenetrationDepthSolver epa;
  btGjkPairDetector gjk(&convex, &tri, &simplex, &epa);
  btDiscreteCollisionDetectorInterface::ClosestPointInput in;
  in.m_transformA = xf;
  in.m_transformB.setIdentity();
  btPointCollector res;
  gjk.getClosestPoints(in, res, nullptr);
  if (!res.m_hasResult || res.m_distance > spec) return 0;
  TriangleContact gjkContact{fromBt(res.m_pointInWorld), fromBt(res.m_normalOnBInWorld), -float(res.m_distance)};
  const Vec3f centreOnPlane = shape.centre - sdCentre * n;
  if (gjkContact.normal.dot(n) < 0.f && (closestPointOnTriangle(centreOnPlane, a, b, c) - centreOnPlane).squaredNorm() <= tol * tol) {
    // Normal points into the solid with the shape's centre behind the face itself: push out
    // along the face. note: only over the face: a shape resting across a hole's rim has its
    // centre behind the plane of the hole's wall but beside the wall's triangles; pushed out
    // along that wall's normal it was thrown sideways by its whole width (quarry).
    float minSd = std::numeric_limits<float>::infinity();
    for (uint32_t i = 0; i < shape.vertexCount(); ++i) minSd = std::min(minSd, n.dot(shape.vertex(i) - a));
    gjkContact.normal = n;
    gjkContact.depth = -minSd;
  }
  int k = 0;
  if (gjkContact.normal.dot(n) > 0.7f) k = vertexContacts(gjkContact.depth);
  if (k == 0) out[k++] = gjkContact;
  return k;
}

uint32_t featureOf(const Int3& chunk, uint32_t triangle) {
  const uint32_t c = uint32_t(chunk.x & 63) | (uint32_t(chunk.y & 63) << 6) | (uint32_t(chunk.z & 127) << 12);
  return (c << 13) | triangle;
}

// Checks what both terrain queries take: a valid shape at a finite, unit-rotation pose.
void validatePlacedShape(const QueryShape& shape, const RigidTransform& pose, const char* context) {
  shape.validate(context);
  requireFinite(pose.translation, context, "pose.translation");
  requireUnitQuaternion(pose.rotation, context, "pose.rotation");
}

}  // namespace

void dropInteriorEdgeContacts(std::vector<Contact>& out, size_t begin, const std::vector<Vec3f>& faceNormals) {
  if (faceNormals.size() != out.size() - begin) {
    throw InvalidInput("dropInteriorEdgeContacts: faceNormals.size() differs from the number of contacts");
  }
  // Decide every contact against the untouched list first, then compact.
  thread_local std::vector<uint8_t> drop;
  drop.assign(faceNormals.size(), 0);
  for (size_t i = begin; i < out.size(); ++i) {
    const Vec3f& fi = faceNormals[i - begin];
    if (out[i].normal.dot(fi) >= 0.9999f) continue;  // a face contact: always kept
    for (size_t j = begin; j < out.size(); ++j) {
      const Vec3f& fj = faceNormals[j - begin];
      if (j == i || out[j].normal.dot(fj) < 0.9999f || fi.dot(fj) < 0.9999f) continue;
      const double gap = fj.cast<double>().dot(out[i].position - out[j].position);
      if (std::abs(gap) < 1e-4 * (1.0 + std::abs(double(out[i].depth)))) {
        drop[i - begin] = 1;
        break;
      }
    }
  }
  size_t w = begin;
  for (size_t i = begin; i < out.size(); ++i) {
    if (!drop[i - begin]) out[w++] = out[i];
  }
  out.resize(w);
}

namespace {

// Calls f(chunk) for every chunk with solid triangles that a query of `shape` at `pose` within
// `spec` reads, in the terrain broadphase's order; f returns false to stop.
template <class F>
void forEachQueriedChunk(const Terrain& terrain, const QueryShape& shape, const RigidTransform& pose, float spec, F&& f) {
  const RigidTransform& place = terrain.placement();
  const Aabb terrainBox = placedBounds(shape, place.pointToLocal(pose.translation), place.rotationToLocal(pose.rotation)).expanded(spec);
  VoxelRange range;
  if (!terrain.broadphase().voxelRangeOf(terrainBox, terrain.voxelSize(), range)) return;
  bool going = true;
  terrain.broadphase().forEachTouchedChunk(range, [&](const Int3& chunk, const TerrainOverlap& o) {
    if (!going || !o.solid || terrain.broadphase().kind(chunk) != ChunkMaskKind::Masked) return;
    going = f(chunk);
  });
}

}  // namespace

// Bullet's view of a box or hull query shape, kept by a plan so a steady-state query allocates
// nothing (a hull's point array keeps its capacity). GJK only reads the shapes, so the pieces of
// one plan share them across threads.
struct TerrainContactPlan::BulletShapes {
  // Made the way a fresh shape per query was (margin 0 set after the points' bounds), so the
  // contacts stay bit-identical.
  struct Hull : btConvexHullShape {
    void setPoints(const Vec3f* points, uint32_t count) {
      setMargin(CONVEX_DISTANCE_MARGIN);
      m_unscaledPoints.resize(0);
      for (uint32_t i = 0; i < count; ++i) m_unscaledPoints.push_back(toBt(points[i]));
      recalcLocalAabb();
      setMargin(0.f);
    }
  };
  std::optional<btBoxShape> box;
  Hull hull;
};

struct TerrainContactPlan::PlacedChunk {
  const ChunkCollision* chunk;
  Int3 coords;
  RigidTransform xf;  // the chunk's frame in the world
  LocalShape shape;   // the query's shape in that frame
  btTransform btXf;   // the same placement as Bullet's GJK takes it
};

TerrainContactPlan::TerrainContactPlan() : bullet_(std::make_unique<BulletShapes>()) {}
TerrainContactPlan::~TerrainContactPlan() = default;
TerrainContactPlan::TerrainContactPlan(TerrainContactPlan&&) noexcept = default;
TerrainContactPlan& TerrainContactPlan::operator=(TerrainContactPlan&&) noexcept = default;

// The candidate triangles, with chunk data from lookup(chunk) (nullptr: not available; the
// plan is then empty and this returns false). After each chunk, chunkDone(first, end) gets the
// range of its triangles, before the next lookup (which may evict that chunk when it fills the cache).
template <class Lookup, class ChunkDone>
bool planWith(TerrainContactPlan& p, const Terrain& terrain, const QueryShape& shape, const RigidTransform& pose, float spec,
              Lookup&& lookup, ChunkDone&& chunkDone) {
  const char* const where = "terrainContacts";
  validatePlacedShape(shape, pose, where);
  requireInRange(spec, 0.0, 1e6, where, "speculativeDistance");
  p.terrain_ = &terrain;
  p.shape_ = shape;
  p.pose_ = pose;
  p.spec_ = spec;
  p.triangles_.clear();
  p.placed_.clear();
  if (shape.kind == QueryShape::Kind::Box) {
    p.bullet_->box.emplace(toBt(shape.halfExtents.cwiseMax(Vec3f::Constant(1e-6f))));
    p.bullet_->box->setMargin(0.f);
  } else if (shape.kind == QueryShape::Kind::Hull) {
    p.bullet_->hull.setPoints(shape.points, shape.pointCount);
  }
  bool complete = true;
  forEachQueriedChunk(terrain, shape, pose, spec, [&](const Int3& chunk) {
    const ChunkCollision* found = lookup(chunk);
    if (!found) return complete = false;
    if (found->mesh.triangleCount() == 0) return true;
    const RigidTransform xf = terrain.chunkTransform(chunk);
    const Vec3f localCentre = xf.pointToLocal(pose.translation);
    const Quatf localRot = xf.rotationToLocal(pose.rotation);
    const Aabb box = placedBounds(shape, localCentre, localRot).expanded(spec);
    const uint32_t first = uint32_t(p.triangles_.size());
    const uint32_t placed = uint32_t(p.placed_.size());
    found->tree.queryAabb(found->mesh.view(), box, [&](uint32_t t) { p.triangles_.push_back({placed, t}); });
    if (p.triangles_.size() > first) {
      const LocalShape ls = placeShape(shape, localCentre, localRot);
      const btTransform btXf(btQuaternion(localRot.x(), localRot.y(), localRot.z(), localRot.w()), toBt(ls.centre));
      p.placed_.push_back({found, chunk, xf, ls, btXf});
    }
    chunkDone(first, uint32_t(p.triangles_.size()));
    return true;
  });
  if (!complete) {
    p.triangles_.clear();
    p.placed_.clear();
  }
  return complete;
}

bool TerrainContactPlan::plan(const Terrain& terrain, const QueryShape& shape, const RigidTransform& pose, float spec) {
  return planWith(
      *this, terrain, shape, pose, spec, [&](const Int3& chunk) { return terrain.cachedChunkCollision(chunk); },
      [](uint32_t, uint32_t) {});
}

void TerrainContactPlan::contactsOfTriangles(uint32_t begin, uint32_t end, std::vector<Contact>& out,
                                             std::vector<Vec3f>& faceNormals) const {
  if (begin > end || end > triangles_.size()) {
    throw InvalidInput("TerrainContactPlan::contactsOfTriangles: range [" + std::to_string(begin) + ", " + std::to_string(end) +
                       ") outside the plan's " + std::to_string(triangles_.size()) + " triangles");
  }
  const QueryShape& shape = shape_;
  const btConvexShape* convex = nullptr;
  if (shape.kind == QueryShape::Kind::Box) convex = &*bullet_->box;
  if (shape.kind == QueryShape::Kind::Hull) convex = &bullet_->hull;
  for (uint32_t i = begin; i < end; ++i) {
    const Triangle& tr = triangles_[i];
    const PlacedChunk& pc = placed_[tr.placed];
    const RigidTransform& xf = pc.xf;
    const LocalShape& ls = pc.shape;
    const TriangleMeshView mesh = pc.chunk->mesh.view();
    const uint32_t t = tr.triangle;
    Vec3f a, b, c;
    mesh.corners(t, a, b, c);
    const Vec3f cr = (b - a).cross(c - a);
    const float len = cr.norm();
    if (!(len > 0.f)) continue;
    const Vec3f n = cr / len;
    TriangleContact lc[8];
    int k = 0;
    switch (shape.kind) {
      case QueryShape::Kind::Sphere:
        k = sphereTriangle(ls.centre, shape.radius, a, b, c, n, spec_, lc[0]) ? 1 : 0;
        break;
      case QueryShape::Kind::Capsule: {
        const Vec3f axis = ls.rot.col(2) * shape.halfHeight;
        TriangleContact two[2];
        k = capsuleTriangle(ls.centre - axis, ls.centre + axis, shape.radius, a, b, c, n, spec_, two);
        std::copy(two, two + k, lc);
        break;
      }
      case QueryShape::Kind::Box:
      case QueryShape::Kind::Hull:
        k = convexTriangle(*convex, pc.btXf, ls, a, b, c, n, spec_, lc, 8);
        break;
    }
    for (int j = 0; j < k; ++j) {
      out.push_back({xf.pointToWorld(lc[j].point), xf.directionToWorld(lc[j].normal), lc[j].depth, featureOf(pc.coords, t),
                     pc.chunk->mesh.materials[t]});
      faceNormals.push_back(xf.directionToWorld(n));
    }
  }
}

void finishTerrainContacts(std::vector<Contact>& out, size_t begin, const std::vector<Vec3f>& faceNormals) {
  dropInteriorEdgeContacts(out, begin, faceNormals);
  // A point shared by several triangles (quad diagonals, corners) is reported by each: keep
  // one. Done after the interior-edge filter, which needs every triangle's face normal.
  size_t w = begin;
  for (size_t i = begin; i < out.size(); ++i) {
    bool duplicate = false;
    for (size_t j = begin; j < w && !duplicate; ++j) {
      duplicate = (out[j].position - out[i].position).squaredNorm() < 1e-10 && out[j].normal.dot(out[i].normal) > 0.9999f;
    }
    if (!duplicate) out[w++] = out[i];
  }
  out.resize(w);
}

namespace {

// One whole query on the calling thread: each chunk's triangles as soon as it is looked up
// (a filling lookup may evict chunks looked up before), then finish.
// note: thread_local plan and scratch, so steady-state queries do not allocate, on any thread.
template <class Lookup>
bool contactsWith(const Terrain& terrain, const QueryShape& shape, const RigidTransform& pose, float spec, std::vector<Contact>& out,
                  Lookup&& lookup) {
  thread_local TerrainContactPlan plan;
  thread_local std::vector<Vec3f> faceNormals;
  const size_t before = out.size();
  faceNormals.clear();
  const bool complete = planWith(plan, terrain, shape, pose, spec, lookup, [&](uint32_t first, uint32_t end) {
    plan.contactsOfTriangles(first, end, out, faceNormals);
  });
  if (!complete) {
    out.resize(before);
    return false;
  }
  finishTerrainContacts(out, before, faceNormals);
  return true;
}

}  // namespace

size_t terrainContacts(Terrain& terrain, const QueryShape& shape, const RigidTransform& pose, float spec,
                       std::vector<Contact>& out) {
  const size_t before = out.size();
  contactsWith(terrain, shape, pose, spec, out, [&](const Int3& chunk) { return &terrain.chunkCollision(chunk); });
  return out.size() - before;
}

bool terrainContactsCached(const Terrain& terrain, const QueryShape& shape, const RigidTransform& pose, float spec,
                           std::vector<Contact>& out) {
  return contactsWith(terrain, shape, pose, spec, out, [&](const Int3& chunk) { return terrain.cachedChunkCollision(chunk); });
}

namespace {

// One axis of the water sum: the overlap of each cell [v * vs, v * vs + vs) with the box's
// [boxMin, boxMax), and its midpoint, with the operations the sum per voxel used (the cell's
// min and max against the box's, then difference and half sum), so every voxel's terms are the
// same floats: computed once per column instead of once per voxel.
struct CellOverlap {
  float length = 0.f, mid = 0.f;
  bool empty = true;
};

CellOverlap cellOverlap(float cellMin, float cellMax, float boxMin, float boxMax) {
  const float lo = std::max(cellMin, boxMin), hi = std::min(cellMax, boxMax);  // Eigen's cwiseMax / cwiseMin
  CellOverlap o;
  o.empty = lo >= hi;
  o.length = hi - lo;
  o.mid = (lo + hi) * 0.5f;
  return o;
}

void cellOverlaps(int first, int last, float vs, float boxMin, float boxMax, std::vector<CellOverlap>& out) {
  out.resize(size_t(last - first + 1));
  for (int v = first; v <= last; ++v) {
    const float cellMin = float(v) * vs;
    out[size_t(v - first)] = cellOverlap(cellMin, cellMin + vs, boxMin, boxMax);
  }
}

}  // namespace

bool terrainWaterContact(const Terrain& terrain, const QueryShape& shape, const RigidTransform& pose, WaterContact& out) {
  validatePlacedShape(shape, pose, "terrainWaterContact");
  return terrainWaterContactChecked(terrain, shape, pose, out);
}

bool terrainWaterContactChecked(const Terrain& terrain, const QueryShape& shape, const RigidTransform& pose, WaterContact& out) {
  out = {};
  const RigidTransform& place = terrain.placement();
  const Aabb box = placedBounds(shape, place.pointToLocal(pose.translation), place.rotationToLocal(pose.rotation));
  const float vs = terrain.voxelSize();
  const Int3 size = terrain.voxels().size();
  int lo[3], hi[3];
  for (int i = 0; i < 3; ++i) {
    const int n = (&size.x)[i];
    lo[i] = int(std::clamp(std::floor(double(box.min[i]) / vs), 0.0, double(n - 1)));
    hi[i] = int(std::clamp(std::floor(double(box.max[i]) / vs), 0.0, double(n - 1)));
  }
  // note: no broadphase test first: chunks without water are skipped below (a lookup per chunk
  // of a layer), and the bitmask test cost more than the sum for a body in the water (a quarter
  // of monument's terrain work). The chunks of one layer are looked up once, not one key lookup
  // per voxel. The voxels still come in y, z, x order, each term the same floats: the same sums,
  // bit for bit.
  const int cx0 = lo[0] >> kChunkShift, cz0 = lo[2] >> kChunkShift;
  const int nx = (hi[0] >> kChunkShift) - cx0 + 1, nz = (hi[2] >> kChunkShift) - cz0 + 1;
  thread_local std::vector<const VoxelChunk*> layer;  // [z][x]: the current y layer's chunks that hold water
  thread_local std::vector<CellOverlap> alongX, alongZ;
  layer.resize(size_t(nx) * size_t(nz));
  cellOverlaps(lo[0], hi[0], vs, box.min.x(), box.max.x(), alongX);
  cellOverlaps(lo[2], hi[2], vs, box.min.z(), box.max.z(), alongZ);
  int layerY = -1;
  bool anyWater = false;
  double volume = 0;
  Vec3d moment = Vec3d::Zero();
  for (int y = lo[1]; y <= hi[1]; ++y) {
    if ((y >> kChunkShift) != layerY) {
      layerY = y >> kChunkShift;
      anyWater = false;
      for (int cz = 0; cz < nz; ++cz)
        for (int cx = 0; cx < nx; ++cx) {
          const VoxelChunk* c = terrain.voxels().chunk({cx0 + cx, layerY, cz0 + cz});
          layer[size_t(cz) * size_t(nx) + size_t(cx)] = c && c->waterCount ? c : nullptr;
          anyWater |= c && c->waterCount;
        }
    }
    if (!anyWater) {
      y |= kChunkSize - 1;  // on to the next layer of chunks
      continue;
    }
    // The filled part of a cell: occupancy/255 of its height, from the bottom (a full cell's
    // overlap computed once per row).
    const float cellMinY = float(y) * vs;
    const CellOverlap fullY = cellOverlap(cellMinY, cellMinY + vs * 255.f / 255.f, box.min.y(), box.max.y());
    for (int z = lo[2]; z <= hi[2]; ++z) {
      const CellOverlap& oz = alongZ[size_t(z - lo[2])];
      if (oz.empty) continue;
      // note: Eigen's prod() of a 3-vector is x * (y * z) (WaterSumsEqualAVoxelByVoxelReference
      // holds us to its bits), so a full cell's y * z is the row's.
      const float fullYZ = fullY.length * oz.length;
      const VoxelChunk* const* row = &layer[size_t((z >> kChunkShift) - cz0) * size_t(nx)];
      const int inChunk = chunkVoxelIndex(0, y & (kChunkSize - 1), z & (kChunkSize - 1));
      for (int x = lo[0]; x <= hi[0];) {
        const VoxelChunk* c = row[(x >> kChunkShift) - cx0];
        const int end = std::min(hi[0], x | (kChunkSize - 1));  // this chunk's part of the row
        if (!c) {
          x = end + 1;
          continue;
        }
        const Voxel* voxels = c->voxels + inChunk;
        for (; x <= end; ++x) {
          const Voxel v = voxels[x & (kChunkSize - 1)];
          if (!v.isWater()) continue;
          const CellOverlap& ox = alongX[size_t(x - lo[0])];
          if (ox.empty) continue;
          double ov;
          float midY;
          if (v.occupancy == 255) {
            if (fullY.empty) continue;
            ov = double(ox.length * fullYZ);
            midY = fullY.mid;
          } else {
            const CellOverlap oy = cellOverlap(cellMinY, cellMinY + vs * float(v.occupancy) / 255.f, box.min.y(), box.max.y());
            if (oy.empty) continue;
            ov = double(ox.length * (oy.length * oz.length));
            midY = oy.mid;
          }
          volume += ov;
          moment += ov * Vec3f(ox.mid, midY, oz.mid).cast<double>();
        }
      }
    }
  }
  if (volume <= 0) return false;
  const double boxVolume = double(box.volume());
  const double scale = boxVolume > 0 ? double(shape.volume()) / boxVolume : 0.0;
  out.submergedVolume = volume * scale;
  out.submergedFraction = float(std::min(1.0, volume / boxVolume));
  out.centreOfBuoyancy = place.pointToWorld((moment / volume).cast<float>());
  return true;
}

}  // namespace bw
