#include "collision/bricks/grid_pair.h"

#include <algorithm>

#include "collision/bricks/brick_geometry.h"
#include "collision/bricks/brick_grid.h"
#include "collision/core/obb.h"

namespace bw {
namespace {

using Item = GridPairScratch::Item;
constexpr uint8_t kNode = 0, kBrick = 1, kLod = 2;

// One grid's side of the traversal: item bounds in its own frame.
struct Side {
  const OctoBvh& tree;
  Aabb bounds(const Item& it) const {
    return it.kind == kBrick ? tree.element(it.ref).bounds() : tree.cluster(it.ref >> 3).bounds(int(it.ref & 7));
  }
};

float extent(const Aabb& b) { return (b.max - b.min).maxCoeff(); }

// Pushes the contents of node `it` of `side` paired with `other` (in the pair's order).
template <bool OpenA>
void open(const Side& side, const Item& it, const Item& other, std::vector<std::pair<Item, Item>>& stack) {
  const octobvh::NodeCluster& cl = side.tree.cluster(it.ref >> 3);
  const int s = int(it.ref & 7);
  auto push = [&](const Item& child) {
    if constexpr (OpenA) {
      stack.push_back({child, other});
    } else {
      stack.push_back({other, child});
    }
  };
  side.tree.forEachHeldPublic(cl, s, [&](uint32_t e) { push(Item{e, kBrick}); });
  cl.forEachSubCluster(s, [&](uint32_t c) {
    const octobvh::NodeCluster& ch = side.tree.cluster(c);
    for (int o = 0; o < 8; ++o)
      if (!ch.isEmpty(o)) push(Item{octobvh::nodeRef(c, o), kNode});
  });
}

}  // namespace

QueryShape brickQueryShape(const Brick& b, Vec3f* vertices) {
  if (b.shape == BrickShape::Box) return QueryShape::box(b.halfSize);
  const int n = canonicalBrickVertices(b, vertices);
  return QueryShape::hull(vertices, uint32_t(n));
}

void collideGridPair(const BrickGrid& a, const BrickGrid& b, const LocalPose& aInB, const GridPairParams& params,
                     GridPairScratch& scratch, std::vector<GridPairContact>& out, GridPairStats* stats) {
  if (a.brickCount() == 0 || b.brickCount() == 0) return;
  const Side sa{a.index()}, sb{b.index()};
  const Mat3f R = aInB.rotation.toRotationMatrix();
  const float margin = std::max(0.f, params.speculativeMargin);
  // a's bounds as an oriented box in b's frame.
  auto orient = [&](const Aabb& local) { return Obb{R * local.center() + aInB.position, local.halfExtent(), R}; };
  GridPairStats st;
  Vec3f hullA[kMaxBrickVertices];
  LocalContact found[kMaxContactsPerBrick];

  // The narrowphase of two non-node items.
  auto collide = [&](const Item& ia, const Item& ib) {
    ++st.brickPairs;
    QueryShape shape;
    LocalPose pose;
    uint32_t featureA;
    if (ia.kind == kBrick) {
      const uint32_t id = a.index().payload(ia.ref);
      const Brick& br = a.brick(id);
      shape = brickQueryShape(br, hullA);
      pose = {aInB.rotation * br.position + aInB.position, aInB.rotation * br.rotation.quaternion()};
      featureA = id;
    } else {
      const Aabb box = sa.bounds(ia);
      shape = QueryShape::box(box.halfExtent().cwiseMax(Vec3f::Constant(kMinBrickHalfSize)));
      pose = {R * box.center() + aInB.position, aInB.rotation};
      featureA = kLodFeature | ia.ref;
    }
    Brick other;
    uint32_t featureB;
    if (ib.kind == kBrick) {
      featureB = b.index().payload(ib.ref);
      other = b.brick(featureB);
    } else {
      const Aabb box = sb.bounds(ib);
      other = Brick::box(box.center(), box.halfExtent().cwiseMax(Vec3f::Constant(kMinBrickHalfSize)));
      featureB = kLodFeature | ib.ref;
    }
    const int n = collideShapeBrick(shape, pose, other, featureB, params.speculativeMargin, found);
    for (int i = 0; i < n; ++i) out.push_back({found[i].position, found[i].normal, found[i].depth, featureA, featureB});
  };

  auto& stack = scratch.stack;
  stack.clear();
  stack.push_back({Item{octobvh::nodeRef(a.index().rootCluster(), 0), kNode}, Item{octobvh::nodeRef(b.index().rootCluster(), 0), kNode}});
  while (!stack.empty()) {
    auto [ia, ib] = stack.back();
    stack.pop_back();
    ++st.itemPairs;
    const Aabb boxA = sa.bounds(ia), boxB = sb.bounds(ib);
    const Aabb grownB{boxB.min - Vec3f::Constant(margin), boxB.max + Vec3f::Constant(margin)};
    if (!mayOverlap(orient(boxA), grownB)) continue;
    const float ea = extent(boxA), eb = extent(boxB);
    // LOD: a node against a brick (or LOD box) it is small beside collides as its box. Against
    // a node nothing is decided yet: the larger of two nodes is opened first, so a node is
    // compared with what it actually meets, not with the other grid's root.
    if (params.lodFraction > 0.f) {
      if (ia.kind == kNode && ib.kind != kNode && ea < params.lodFraction * eb) ia.kind = kLod, ++st.lodBoxes;
      if (ib.kind == kNode && ia.kind != kNode && eb < params.lodFraction * ea) ib.kind = kLod, ++st.lodBoxes;
    }
    if (ia.kind != kNode && ib.kind != kNode) {
      collide(ia, ib);
      continue;
    }
    // Open the larger node (a node against a brick or LOD box: the node).
    if (ia.kind == kNode && (ib.kind != kNode || ea >= eb)) {
      open<true>(sa, ia, ib, stack);
    } else {
      open<false>(sb, ib, ia, stack);
    }
  }
  if (stats) {
    stats->itemPairs += st.itemPairs;
    stats->brickPairs += st.brickPairs;
    stats->lodBoxes += st.lodBoxes;
  }
}

}  // namespace bw
