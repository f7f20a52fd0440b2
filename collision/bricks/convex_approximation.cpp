// Convex approximation of a brick grid from its OctoBVH (article 000, "Convex Approximation
// From OctoBVH" and "Convex Simplification to Box").
#include <LinearMath/btConvexHullComputer.h>
#include <algorithm>

#include "collision/bricks/brick_grid.h"
#include "collision/core/argument_checks.h"

namespace bw {

using namespace octobvh;

namespace {

// Points for the hull: exact vertices of bricks met above `depth` (large bricks held by inner
// nodes, and whole small leaves), and the 8 corners of every subtree left at `depth`.
void collectPoints(const BrickGrid& grid, uint32_t c, int s, int level, int depth, std::vector<Vec3f>& pts) {
  const OctoBvh& tree = grid.index();
  const NodeCluster& cl = tree.cluster(c);
  if (cl.isEmpty(s)) return;
  if (level == depth && cl.child[s] != kInvalidIndex) {
    const Aabb b = cl.bounds(s);
    for (int i = 0; i < 8; ++i)
      pts.emplace_back((i & 1) ? b.max.x() : b.min.x(), (i & 2) ? b.max.y() : b.min.y(), (i & 4) ? b.max.z() : b.min.z());
    return;
  }
  Vec3f v[kMaxBrickVertices];
  tree.forEachHeldPublic(cl, s, [&](uint32_t e) {
    const int n = brickVertices(grid.brick(tree.payload(e)), v);
    pts.insert(pts.end(), v, v + n);
  });
  cl.forEachSubCluster(s, [&](uint32_t sub) {
    for (int o = 0; o < 8; ++o) collectPoints(grid, sub, o, level + 1, depth, pts);
  });
}

}  // namespace

void BrickGrid::coverBoxes(uint32_t maxBoxes, std::vector<Aabb>& out) const {
  out.clear();
  if (brickCount() == 0) return;
  // Level by level from the root while the next level still fits in maxBoxes: chains of
  // single children (a grid far from the origin sits under a few) cost no boxes.
  struct Node {
    uint32_t cluster;
    int slot;
  };
  std::vector<Node> frontier{{index_.rootCluster(), 0}}, next;
  std::vector<Aabb> held;  // bricks held by nodes already expanded (large bricks)
  for (;;) {
    next.clear();
    size_t heldHere = 0;
    bool grew = false;
    for (const Node& n : frontier) {
      const NodeCluster& cl = index_.cluster(n.cluster);
      if (cl.child[n.slot] == kInvalidIndex) {
        next.push_back(n);  // a leaf stays as it is
        continue;
      }
      grew = true;
      index_.forEachHeldPublic(cl, n.slot, [&](uint32_t) { ++heldHere; });
      cl.forEachSubCluster(n.slot, [&](uint32_t sub) {
        for (int o = 0; o < 8; ++o)
          if (!index_.cluster(sub).isEmpty(o)) next.push_back({sub, o});
      });
    }
    if (!grew || next.size() + held.size() + heldHere > maxBoxes) break;
    for (const Node& n : frontier) {
      const NodeCluster& cl = index_.cluster(n.cluster);
      if (cl.child[n.slot] != kInvalidIndex) index_.forEachHeldPublic(cl, n.slot, [&](uint32_t e) { held.push_back(index_.bounds(e)); });
    }
    std::swap(frontier, next);
  }
  for (const Node& n : frontier) out.push_back(index_.cluster(n.cluster).bounds(n.slot));
  out.insert(out.end(), held.begin(), held.end());
}

QueryShape ConvexApproximation::shape() const {
  if (isBox) return QueryShape::box(bounds.halfExtent().cwiseMax(Vec3f::Constant(1e-4f)));
  return QueryShape::hull(centered.data(), uint32_t(centered.size()), float(hullVolume), centeredHalfExtents);
}

Vec3f ConvexApproximation::shapeCenter() const { return bounds.center(); }

ConvexApproximation BrickGrid::buildConvexApproximation(int depth) const {
  if (depth < 0 || depth > 16)
    throw InvalidInput("BrickGrid::convexApproximation: depth is " + std::to_string(depth) + ", expected 0..16");
  ConvexApproximation a;
  a.depth = depth;
  if (brickCount() == 0) return a;
  std::vector<Vec3f> pts;
  collectPoints(*this, index_.rootCluster(), 0, 0, depth, pts);
  a.inputPoints = uint32_t(pts.size());
  forEachBrick([&](uint32_t id) { a.brickVolume += canonicalBrickMoments(brick(id)).volume; });
  btConvexHullComputer hull;
  hull.compute(pts[0].data(), int(sizeof(Vec3f)), int(pts.size()), 0, 0);
  for (int i = 0; i < hull.vertices.size(); ++i) {
    const btVector3& p = hull.vertices[i];
    a.vertices.emplace_back(float(p.x()), float(p.y()), float(p.z()));
    a.bounds.merge(a.vertices.back());
  }
  // Volume: fan-triangulate each face from its first vertex; tetrahedra against the centroid.
  Vec3d centroid = Vec3d::Zero();
  for (const Vec3f& p : a.vertices) centroid += p.cast<double>();
  centroid /= double(std::max<size_t>(a.vertices.size(), 1));
  for (int f = 0; f < hull.faces.size(); ++f) {
    const btConvexHullComputer::Edge* first = &hull.edges[hull.faces[f]];
    const Vec3d p0 = a.vertices[first->getSourceVertex()].cast<double>();
    const btConvexHullComputer::Edge* e = first->getNextEdgeOfFace();
    while (e->getTargetVertex() != first->getSourceVertex()) {
      const Vec3d p1 = a.vertices[e->getSourceVertex()].cast<double>();
      const Vec3d p2 = a.vertices[e->getTargetVertex()].cast<double>();
      a.hullVolume += std::abs((p1 - p0).cross(p2 - p0).dot(centroid - p0)) / 6.0;
      e = e->getNextEdgeOfFace();
    }
  }
  // A box only when the hull has exactly 8 vertices and they are the 8 corners of its bounds
  // (a wedge also has few vertices, but never all 8 corners).
  if (a.vertices.size() == 8) {
    const float eps = 1e-5f * std::max(1.f, a.bounds.extent().maxCoeff());
    bool all = true;
    for (int i = 0; i < 8 && all; ++i) {
      const Vec3f corner((i & 1) ? a.bounds.max.x() : a.bounds.min.x(), (i & 2) ? a.bounds.max.y() : a.bounds.min.y(),
                         (i & 4) ? a.bounds.max.z() : a.bounds.min.z());
      all = std::any_of(a.vertices.begin(), a.vertices.end(), [&](const Vec3f& v) { return (v - corner).cwiseAbs().maxCoeff() <= eps; });
    }
    a.isBox = all;
  }
  const Vec3f c = a.bounds.center();
  for (const Vec3f& v : a.vertices) a.centered.push_back(v - c);
  a.centeredHalfExtents = QueryShape::hull(a.centered.data(), uint32_t(a.centered.size())).hullHalfExtents;
  return a;
}

const ConvexApproximation& BrickGrid::convexApproximation(int depth) {
  if (depth < 0 || depth >= int(approximations_.size()))
    throw InvalidInput("BrickGrid::convexApproximation: depth is " + std::to_string(depth) + ", cached depths are 0..7");
  CachedApproximation& c = approximations_[depth];
  if (c.edit != edits_) {
    c.value = buildConvexApproximation(depth);
    c.edit = edits_;
  }
  return c.value;
}

size_t collideGrids(BrickGrid& a, const RigidTransform& poseA, BrickGrid& b, const RigidTransform& poseB, int depth,
                    const ContactParams& params, ContactScratch& scratch, std::vector<Contact>& out, int& smallerIndex,
                    ContactStats* stats, GridPairMode mode) {
  // note: checked once here, not once a brick by collide in the brick-by-brick loop (checking the
  // same poses again was 8% of demolition's instructions).
  poseA.validate("collideGrids (pose a)");
  poseB.validate("collideGrids (pose b)");
  BrickGrid::validateContactParams(params, "collideGrids");
  return collideGridsChecked(a, poseA, b, poseB, depth, params, scratch, out, smallerIndex, stats, mode);
}

size_t collideGridsChecked(BrickGrid& a, const RigidTransform& poseA, BrickGrid& b, const RigidTransform& poseB, int depth,
                           const ContactParams& params, ContactScratch& scratch, std::vector<Contact>& out, int& smallerIndex,
                           ContactStats* stats, GridPairMode mode) {
  // By brick count; when both are small enough to go brick by brick, the one of smaller extent
  // (its bricks against the other's, not a 120 m yard brick against a rubble part's: box vs
  // brick of such sizes gave 27 m deep contacts, demolition).
  const bool bothSmall = a.brickCount() <= kBrickwiseGridBricks && b.brickCount() <= kBrickwiseGridBricks;
  const bool aSmaller = bothSmall ? a.bounds().halfExtent().squaredNorm() <= b.bounds().halfExtent().squaredNorm()
                                  : a.brickCount() <= b.brickCount();
  smallerIndex = aSmaller ? 0 : 1;
  BrickGrid& small = aSmaller ? a : b;
  const BrickGrid& large = aSmaller ? b : a;
  const RigidTransform& smallPose = aSmaller ? poseA : poseB;
  const RigidTransform& largePose = aSmaller ? poseB : poseA;
  if (small.brickCount() == 0 || large.brickCount() == 0) return 0;
  if (small.brickCount() <= kBrickwiseGridBricks) {
    // Every brick's manifold, then the pair's reduced as one (by normal direction, then area):
    // a 100-brick part lying on the ground would otherwise hand the solver 400 contacts.
    const size_t first = out.size();
    small.forEachBrick([&](uint32_t id) {
      const Brick& br = small.brick(id);
      const RigidTransform pose{smallPose.pointToWorld(br.position), smallPose.rotation * br.rotation.quaternion()};
      const size_t before = out.size();
      // (a placed brick's half size is valid; its pose is two valid poses composed)
      large.collideChecked(largePose, QueryShape::box(br.halfSize), pose, params, scratch, out, stats);
      for (size_t k = before; k < out.size(); ++k) out[k].featureB = smallFeature(out[k].featureB, id);
    });
    reduceManifold(out, first, params.maxContacts);
    return out.size() - first;
  }
  const bool twoWay = mode == GridPairMode::TwoWay || (mode == GridPairMode::Auto && [&] {
                        const ConvexApproximation& a = small.convexApproximation(depth);
                        return a.hullVolume > kAutoTwoWayFill * a.brickVolume;
                      }());
  if (twoWay) {
    // Both grids' bricks, in the large grid's frame (the relative pose formed in double once).
    const LocalPose smallInLarge{largePose.pointToLocal(smallPose.translation), largePose.rotationToLocal(smallPose.rotation)};
    GridPairParams pairParams;
    pairParams.lodFraction = params.lodFraction;
    pairParams.speculativeMargin = params.speculativeMargin;
    scratch.pairContacts.clear();
    GridPairStats pairStats;
    collideGridPair(small, large, smallInLarge, pairParams, scratch.pair, scratch.pairContacts, &pairStats);
    const size_t first = out.size();
    for (const GridPairContact& c : scratch.pairContacts) {
      const uint32_t material = (c.brickB & kLodFeature) ? 0u : large.brick(c.brickB).material;
      out.push_back({largePose.pointToWorld(c.position), largePose.directionToWorld(c.normal), c.depth, smallFeature(c.brickB, c.brickA),
                     material});
    }
    if (stats) {
      stats->index.boxTests += pairStats.itemPairs;
      stats->bricksTested += uint32_t(pairStats.brickPairs);
      stats->lodBoxes += uint32_t(pairStats.lodBoxes);
      stats->rawContacts += uint32_t(scratch.pairContacts.size());
    }
    reduceManifold(out, first, params.maxContacts);
    return out.size() - first;
  }
  const ConvexApproximation& approx = small.convexApproximation(depth);
  const RigidTransform shapePose{smallPose.pointToWorld(approx.shapeCenter()), smallPose.rotation};
  // (the hull is made here from placed bricks: checking its every vertex again on every call, with
  // the poses, was a third of carrier_fleet's start, whose in-solid search collides each pair at
  // every spot it tries)
  return large.collideChecked(largePose, approx.shape(), shapePose, params, scratch, out, stats);
}

}  // namespace bw
