// OctoBVH edits: insert (growing the root when an element lies outside it, splitting and
// forcing down along one path), remove and update (merging and undoing forced splits, shrinking
// the root), each keeping the tree the canonical function of its element set.
#include <algorithm>
#include <vector>

#include "collision/core/argument_checks.h"
#include "collision/index/octobvh.h"

namespace bw {

using namespace octobvh;

// ---------------------------------------------------------------- insert

uint32_t OctoBvh::insert(const Aabb& bounds, uint32_t filter, uint32_t payload) {
  validateElement(bounds, "OctoBvh::insert");
  reserveHeadroom("OctoBvh::insert");
  const uint32_t e = elements_.allocate();
  ElementRecord& r = elements_[e];
  for (int k = 0; k < 3; ++k) {
    r.min[k] = bounds.min[k];
    r.max[k] = bounds.max[k];
  }
  r.filter = filter;
  r.payload = payload;
  double ctr[3];
  centreOf(r, ctr);
  growRootToHold(ctr, minLevelOf(r));
  insertAt(rootCluster_, 0, rootCube(), e);
  return e;
}

void OctoBvh::growRootToHold(const double c[3], int minLevel) {
  for (;;) {
    const int R = rootLevel_ - 1;
    const double half = pow2(R);
    bool inside = minLevel <= R;
    for (int i = 0; i < 3; ++i) inside = inside && c[i] >= -half && c[i] < half;
    if (inside) return;

    NodeCluster& root = clusters_[rootCluster_];
    if (root.child[0] != kInvalidIndex) {
      // Each old root child (level R) moves into the new root child of its octant (level R+1),
      // at the corner nearest the origin (slot o ^ 7). A leaf child just moves up a level.
      const uint32_t oldC = root.child[0];
      const uint32_t newC = allocCluster(R + 1);
      for (int o = 0; o < 8; ++o) {
        const NodeCluster& old = clusters_[oldC];
        if (old.isEmpty(o)) continue;
        NodeCluster& nc = clusters_[newC];
        if (old.child[o] == kInvalidIndex && old.numHeld[o] == kOverflow) {
          // A min-level leaf with > 8 elements cannot stay a leaf one level up: rebuild it.
          std::vector<uint32_t> many;
          heldTake(oldC, o, many);
          const double no = -std::ldexp(1.0, R + 1);
          const Cube newRootCube{{no, no, no}, R + 2};
          build(newC, o, newRootCube.child(o), many.data(), uint32_t(many.size()));
        } else if (old.child[o] == kInvalidIndex) {
          nc.setBounds(o, old.bounds(o));
          nc.leaf[o] = old.leaf[o];
          nc.numHeld[o] = old.numHeld[o];
          nc.filter[o] = old.filter[o];
          nc.maxMinLevel[o] = old.maxMinLevel[o];
        } else {
          const uint32_t d = allocCluster(R);
          NodeCluster& dc = clusters_[d];
          const int t = o ^ 7;
          dc.setBounds(t, old.bounds(o));
          dc.child[t] = old.child[o];
          dc.leaf[t] = old.leaf[o];
          dc.numHeld[t] = old.numHeld[o];
          dc.filter[t] = old.filter[o];
          dc.maxMinLevel[t] = old.maxMinLevel[o];
          dc.childTotal = subtreeCount(oldC, o);
          nc.setBounds(o, old.bounds(o));
          nc.child[o] = d;
          nc.filter[o] = old.filter[o];
          nc.maxMinLevel[o] = old.maxMinLevel[o];
        }
      }
      clusters_[newC].childTotal = clusters_[oldC].childTotal;
      clusters_.free(oldC);
      clusters_[rootCluster_].child[0] = newC;
    }
    ++rootLevel_;
    clusters_[rootCluster_].level = int8_t(rootLevel_);
  }
}

// Passes e down into the node of cluster `sub` (the children or the forced cluster of the node
// whose cube is `cube`) holding its centre.
void OctoBvh::passDown(uint32_t sub, const Cube& cube, uint32_t e) {
  NodeCluster& to = clusters_[sub];
  ++to.childTotal;
  if (to.forcedCount) ++to.forcedCount;
  double ctr[3];
  centreOf(elements_[e], ctr);
  const int o = cube.childSlotFor(ctr);
  insertAt(sub, o, cube.child(o), e);
}

void OctoBvh::insertAt(uint32_t c, int s, const Cube& cube, uint32_t e) {
  const ElementRecord& r = elements_[e];
  const int m = minLevelOf(r);
  {
    NodeCluster& cl = clusters_[c];
    Aabb b = cl.bounds(s);
    b.merge(r.bounds());
    cl.setBounds(s, b);
    cl.filter[s] |= r.filter;
    cl.maxMinLevel[s] = int8_t(std::max<int>(cl.maxMinLevel[s], m));
  }
  NodeCluster& cl = clusters_[c];
  if (cl.child[s] == kInvalidIndex) {
    if (cl.numHeld[s] < kLeafCapacity || cube.level == kMinLevel) {
      heldAdd(c, s, e);
      return;
    }
    // A leaf reaching 9 elements splits into the canonical subtree of those 9.
    std::vector<uint32_t> nine;
    nine.reserve(9);
    heldTake(c, s, nine);
    nine.push_back(e);
    build(c, s, cube, nine.data(), uint32_t(nine.size()));
    return;
  }
  const uint32_t child = cl.child[s];
  if (m < cube.level) {
    if (clusters_[child].forcedCount > 0) {
      // The first element to fit a child under a node that forced everything it had: the forced
      // subtree moves whole to the node's forced cluster, and new children take this element.
      const uint32_t natural = allocCluster(cube.level - 1);
      NodeCluster& n = clusters_[c];
      n.leaf[s] = child;
      n.numHeld[s] = kForcedCluster;
      n.child[s] = natural;
    }
    passDown(clusters_[c].child[s], cube, e);
    return;
  }
  if (cl.numHeld[s] == kForcedCluster) {
    passDown(cl.leaf[s], cube, e);
    return;
  }
  if (clusters_[child].forcedCount > 0) {
    passDown(child, cube, e);
    return;
  }
  if (cl.numHeld[s] < kLeafCapacity) {
    heldAdd(c, s, e);
    return;
  }
  // A 9th element too large for the children (some element fits them: the node is inner with
  // only 8 held): the nine go to a new forced cluster by centre.
  std::vector<uint32_t> big;
  big.reserve(9);
  heldTake(c, s, big);
  big.push_back(e);
  const uint32_t forced = allocCluster(cube.level - 1);
  clusters_[c].leaf[s] = forced;
  clusters_[c].numHeld[s] = kForcedCluster;
  for (uint32_t x : big) passDown(forced, cube, x);  // counts childTotal only while forcedCount is 0
  clusters_[forced].forcedCount = uint32_t(big.size());
}

// ---------------------------------------------------------------- remove

void OctoBvh::remove(uint32_t handle) {
  if (!elements_.isLive(handle))
    throw InvalidInput("OctoBvh::remove: handle " + std::to_string(handle) + " is not an element of this tree");
  removeAt(rootCluster_, 0, rootCube(), handle);
  elements_.free(handle);
  shrinkRoot();
}

void OctoBvh::update(uint32_t handle, const Aabb& bounds, uint32_t filter) {
  if (!elements_.isLive(handle))
    throw InvalidInput("OctoBvh::update: handle " + std::to_string(handle) + " is not an element of this tree");
  validateElement(bounds, "OctoBvh::update");
  reserveHeadroom("OctoBvh::update");
  removeAt(rootCluster_, 0, rootCube(), handle);
  shrinkRoot();
  ElementRecord& r = elements_[handle];
  for (int k = 0; k < 3; ++k) {
    r.min[k] = bounds.min[k];
    r.max[k] = bounds.max[k];
  }
  r.filter = filter;
  double ctr[3];
  centreOf(r, ctr);
  growRootToHold(ctr, minLevelOf(r));
  insertAt(rootCluster_, 0, rootCube(), handle);
}

bool OctoBvh::removeBelow(uint32_t sub, const Cube& cube, uint32_t e) {
  NodeCluster& from = clusters_[sub];
  --from.childTotal;
  if (from.forcedCount) --from.forcedCount;
  double ctr[3];
  centreOf(elements_[e], ctr);
  const int o = cube.childSlotFor(ctr);
  return removeAt(sub, o, cube.child(o), e);
}

// The node becomes one leaf holding what is left of its subtree once `removed` is gone.
void OctoBvh::mergeIntoLeaf(uint32_t c, int s, uint32_t removed) {
  std::vector<uint32_t> rest;
  rest.reserve(9);
  gatherSubtree(c, s, rest);
  rest.erase(std::find(rest.begin(), rest.end(), removed));
  NodeCluster& cl = clusters_[c];
  const uint32_t child = cl.child[s], forced = cl.forced(s);
  cl.child[s] = kInvalidIndex;
  if (forced != kInvalidIndex) {
    cl.numHeld[s] = 0;
    cl.leaf[s] = kInvalidIndex;
    freeSubtreeClusters(forced);
  } else {
    std::vector<uint32_t> held;
    heldTake(c, s, held);
  }
  freeSubtreeClusters(child);
  for (uint32_t x : rest) heldAdd(c, s, x);
}

// Returns whether the node's summary (bounds, filter OR, max min level) changed, so callers
// above can skip their refit when it did not (most removals change only the bottom levels).
bool OctoBvh::removeAt(uint32_t c, int s, const Cube& cube, uint32_t e) {
  NodeCluster& cl = clusters_[c];
  if (cl.child[s] == kInvalidIndex) {
    heldRemove(c, s, e);
    return refit(c, s);
  }
  if (subtreeCount(c, s) - 1 <= uint32_t(kLeafCapacity)) {
    mergeIntoLeaf(c, s, e);
    return refit(c, s);
  }
  const uint32_t child = cl.child[s];
  const uint32_t forced = cl.forced(s);
  const int m = minLevelOf(elements_[e]);
  bool below = true;  // whether something below may have changed this node's summary
  if (m < cube.level) {
    below = removeBelow(child, cube, e);
    if (forced != kInvalidIndex && clusters_[child].childTotal == 0) {
      // Nothing left that fits a child: the forced subtree becomes the children again.
      clusters_.free(child);
      NodeCluster& n = clusters_[c];
      n.child[s] = forced;
      n.numHeld[s] = 0;
      n.leaf[s] = kInvalidIndex;
      below = true;
    }
  } else if (forced != kInvalidIndex) {
    below = removeBelow(forced, cube, e);
    if (clusters_[forced].childTotal == uint32_t(kLeafCapacity)) {
      // Down to 8 large elements: they are held here again.
      std::vector<uint32_t> big;
      big.reserve(8);
      for (int o = 0; o < 8; ++o)
        if (!clusters_[forced].isEmpty(o)) gatherSubtree(forced, o, big);
      NodeCluster& n = clusters_[c];
      n.numHeld[s] = 0;
      n.leaf[s] = kInvalidIndex;
      freeSubtreeClusters(forced);
      for (uint32_t x : big) heldAdd(c, s, x);
      below = true;
    }
  } else if (clusters_[child].forcedCount > 0) {
    below = removeBelow(child, cube, e);  // stays forced: more than 8 are left (else merged above)
  } else {
    heldRemove(c, s, e);
  }
  return below ? refit(c, s) : false;
}

void OctoBvh::shrinkRoot() {
  for (;;) {
    const int R = rootLevel_ - 1;
    if (R <= kMinLevel) return;
    NodeCluster& root = clusters_[rootCluster_];
    if (root.isEmpty(0)) {
      rootLevel_ = kMinLevel + 1;
      root.level = int8_t(rootLevel_);
      return;
    }
    if (root.maxMinLevel[0] > R - 1) return;
    const double half = std::ldexp(1.0, R - 1);
    bool fits = true;
    auto heldInside = [&](const NodeCluster& cl, int s) {
      forEachHeld(cl, s, [&](uint32_t e) {
        double ctr[3];
        centreOf(elements_[e], ctr);
        for (double v : ctr) fits = fits && v >= -half && v < half;
      });
    };
    if (root.child[0] == kInvalidIndex) {
      heldInside(root, 0);
      if (!fits) return;
    } else {
      const NodeCluster& C = clusters_[root.child[0]];
      for (int o = 0; o < 8 && fits; ++o) {
        if (C.isEmpty(o)) continue;
        if (C.child[o] == kInvalidIndex) {
          heldInside(C, o);
        } else {
          fits = C.numHeld[o] == 0;
          const NodeCluster& D = clusters_[C.child[o]];
          for (int t = 0; t < 8 && fits; ++t) fits = (t == (o ^ 7)) || D.isEmpty(t);
        }
      }
      if (!fits) return;
      // Reverse of growth: each root child's inner-corner content becomes the new root child.
      const uint32_t oldC = root.child[0];
      const uint32_t newC = allocCluster(R - 1);
      for (int o = 0; o < 8; ++o) {
        const NodeCluster& old = clusters_[oldC];
        if (old.isEmpty(o)) continue;
        NodeCluster& nc = clusters_[newC];
        if (old.child[o] == kInvalidIndex) {
          nc.setBounds(o, old.bounds(o));
          nc.leaf[o] = old.leaf[o];
          nc.numHeld[o] = old.numHeld[o];
          nc.filter[o] = old.filter[o];
          nc.maxMinLevel[o] = old.maxMinLevel[o];
        } else {
          const uint32_t d = old.child[o];
          const NodeCluster& dc = clusters_[d];
          const int t = o ^ 7;
          nc.setBounds(o, dc.bounds(t));
          nc.child[o] = dc.child[t];
          nc.leaf[o] = dc.leaf[t];
          nc.numHeld[o] = dc.numHeld[t];
          nc.filter[o] = dc.filter[t];
          nc.maxMinLevel[o] = dc.maxMinLevel[t];
          clusters_.free(d);
        }
      }
      clusters_[newC].childTotal = clusters_[oldC].childTotal;
      clusters_.free(oldC);
      clusters_[rootCluster_].child[0] = newC;
    }
    --rootLevel_;
    clusters_[rootCluster_].level = int8_t(rootLevel_);
  }
}

}  // namespace bw
