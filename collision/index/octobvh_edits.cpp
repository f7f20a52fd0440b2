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
  elements_[e] = ElementRecord::of(bounds, filter, payload);
  const Placement p = placementOf(e);
  growRootToHold(p.ctr, p.minLevel);
  insertAt(rootCluster_, 0, rootCube(), p);
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
          buildFrom(newC, o, newRootCube.child(o), many.data(), uint32_t(many.size()));
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
void OctoBvh::passDown(uint32_t sub, const Cube& cube, const Placement& p) {
  NodeCluster& to = clusters_[sub];
  ++to.childTotal;
  if (to.forcedCount) ++to.forcedCount;
  const int o = cube.childSlotFor(p.ctr);
  insertAt(sub, o, cube.child(o), p);
}

// note: a loop, not passDown's recursion, on the way down: an insert walks ~15 levels and the
// calls cost as much as the work at each (callgrind).
void OctoBvh::insertAt(uint32_t c, int s, Cube cube, const Placement& p) {
  const uint32_t e = p.e;
  const ElementRecord& r = elements_[e];
  const int m = p.minLevel;
  const Lattice at = latticeOf(p.ctr);  // the walk's slots; the cube itself only where a build needs it
  for (int level = cube.level;; --level) {
    NodeCluster& cl = clusters_[c];
    cl.minX[s] = std::min(cl.minX[s], r.min[0]);
    cl.minY[s] = std::min(cl.minY[s], r.min[1]);
    cl.minZ[s] = std::min(cl.minZ[s], r.min[2]);
    cl.maxX[s] = std::max(cl.maxX[s], r.max[0]);
    cl.maxY[s] = std::max(cl.maxY[s], r.max[1]);
    cl.maxZ[s] = std::max(cl.maxZ[s], r.max[2]);
    cl.filter[s] |= r.filter;
    cl.maxMinLevel[s] = int8_t(std::max<int>(cl.maxMinLevel[s], m));
    if (cl.child[s] == kInvalidIndex) {
      if (cl.numHeld[s] < kLeafCapacity || level == kMinLevel) {
        heldAdd(c, s, e);
        return;
      }
      // A leaf reaching 9 elements splits into the canonical subtree of those 9.
      std::vector<uint32_t> nine;
      nine.reserve(9);
      heldTake(c, s, nine);
      nine.push_back(e);
      buildFrom(c, s, cubeAt(at, level), nine.data(), uint32_t(nine.size()));
      return;
    }
    const uint32_t child = cl.child[s];
    prefetchForEdit(clusters_[child], true);
    uint32_t sub;  // the cluster e goes down into
    if (m < level) {
      if (clusters_[child].forcedCount > 0) {
        // The first element to fit a child under a node that forced everything it had: the
        // forced subtree moves whole to the node's forced cluster, and new children take e.
        const uint32_t natural = allocCluster(level - 1);
        NodeCluster& n = clusters_[c];
        n.leaf[s] = child;
        n.numHeld[s] = kForcedCluster;
        n.child[s] = natural;
      }
      sub = clusters_[c].child[s];
    } else if (cl.numHeld[s] == kForcedCluster) {
      sub = cl.leaf[s];
    } else if (clusters_[child].forcedCount > 0) {
      sub = child;
    } else if (cl.numHeld[s] < kLeafCapacity) {
      heldAdd(c, s, e);
      return;
    } else {
      // A 9th element too large for the children (some element fits them: the node is inner
      // with only 8 held): the nine go to a new forced cluster by centre.
      std::vector<uint32_t> big;
      big.reserve(9);
      heldTake(c, s, big);
      big.push_back(e);
      const uint32_t forced = allocCluster(level - 1);
      clusters_[c].leaf[s] = forced;
      clusters_[c].numHeld[s] = kForcedCluster;
      const Cube here = cubeAt(at, level);
      for (uint32_t x : big) passDown(forced, here, placementOf(x));  // counts childTotal only while forcedCount is 0
      clusters_[forced].forcedCount = uint32_t(big.size());
      return;
    }
    NodeCluster& to = clusters_[sub];
    ++to.childTotal;
    if (to.forcedCount) ++to.forcedCount;
    s = at.slotBelow(level);
    c = sub;
  }
}

// The way up an edit: whether a node's refit needs to run.
bool OctoBvh::summaryStays(uint32_t c, int s, const NodeSummary& before, const NodeSummary& after) const {
  // note: the comparisons are refit's (float ==, so a face that only changed the sign of a zero
  // counts as unchanged, as refit's own "changed" does).
  const NodeSummary node = summaryOf(c, s);
  for (int k = 0; k < 3; ++k) {
    if (!(after.lo[k] == before.lo[k] || (before.lo[k] > node.lo[k] && after.lo[k] >= node.lo[k]))) return false;
    if (!(after.hi[k] == before.hi[k] || (before.hi[k] < node.hi[k] && after.hi[k] <= node.hi[k]))) return false;
  }
  if (after.filter != before.filter && ((before.filter & ~after.filter) != 0 || (after.filter & ~node.filter) != 0)) return false;
  return after.maxMinLevel == before.maxMinLevel ||
         (before.maxMinLevel < node.maxMinLevel && after.maxMinLevel <= node.maxMinLevel);
}

// ---------------------------------------------------------------- remove

void OctoBvh::remove(uint32_t handle) {
  if (!elements_.isLive(handle))
    throw InvalidInput("OctoBvh::remove: handle " + std::to_string(handle) + " is not an element of this tree");
  const Placement p = placementOf(handle);
  const bool mayShrink = holdsRootUp(p);
  removeAt(rootCluster_, 0, rootCube(), p);
  elements_.free(handle);
  if (mayShrink) shrinkRoot();
}

// The root shrinks when every element's centre lies in the half-size cube and every min level
// fits it. The tree was canonical before the removal, so if e met both, another element that
// does not is still there: only an element that held the root up can let it shrink.
bool OctoBvh::holdsRootUp(const Placement& p) const {
  const int R = rootLevel_ - 1;
  if (R <= kMinLevel) return false;
  if (p.minLevel > R - 1) return true;
  const double half = pow2(R - 1);
  for (double v : p.ctr)
    if (!(v >= -half && v < half)) return true;
  return false;
}

void OctoBvh::update(uint32_t handle, const Aabb& bounds, uint32_t filter) {
  if (!elements_.isLive(handle))
    throw InvalidInput("OctoBvh::update: handle " + std::to_string(handle) + " is not an element of this tree");
  validateElement(bounds, "OctoBvh::update");
  reserveHeadroom("OctoBvh::update");
  const Placement old = placementOf(handle);
  const ElementRecord moved = ElementRecord::of(bounds, filter, elements_[handle].payload);
  Placement p{handle, minLevelOf(moved), {}};
  centreOf(moved, p.ctr);
  if (p.minLevel == old.minLevel && !holdsRootUp(old) && !holdsRootUp(p) && updateInPlace(old, p, moved)) return;
  const bool mayShrink = holdsRootUp(old);
  removeAt(rootCluster_, 0, rootCube(), old);
  if (mayShrink) shrinkRoot();
  elements_[handle] = moved;
  growRootToHold(p.ctr, p.minLevel);
  insertAt(rootCluster_, 0, rootCube(), p);
}

// A small move usually leaves the element's centre in the cube of the node that holds it, with
// the same min level: every placement decision is the same, so the canonical structure is too,
// and only the summaries along the path change. One walk down (stopping if the new centre
// leaves the old path), the record rewritten, then refits up while a summary changed: half
// the work of a remove and an insert. Returns false, having changed nothing, when the path
// differs (the caller then removes and inserts).
bool OctoBvh::updateInPlace(const Placement& old, const Placement& p, const ElementRecord& moved) {
  struct Step {
    uint32_t c;
    int s;
  };
  Step path[kMaxLevel - kMinLevel + 2];
  int depth = 0;
  uint32_t c = rootCluster_;
  int s = 0;
  const Lattice from = latticeOf(old.ctr), to = latticeOf(p.ctr);
  for (int level = rootLevel_;; --level) {
    const NodeCluster& cl = clusters_[c];
    path[depth++] = {c, s};
    if (cl.child[s] == kInvalidIndex) break;  // a leaf: it holds the element
    prefetchForEdit(clusters_[cl.child[s]], false);
    const uint32_t sub = clusterBelow(cl, s, level, p.minLevel);
    if (sub == kInvalidIndex) break;  // held at this inner node
    const int o = from.slotBelow(level);
    if (to.slotBelow(level) != o) return false;
    c = sub;
    s = o;
  }
  elements_[p.e] = moved;
  // The node holding it is refitted; each node above only if the one below changed in a way
  // that reaches it (summaryStays).
  const Step bottom = path[--depth];
  NodeSummary before;
  if (!refit(bottom.c, bottom.s, &before)) return true;
  Step below = bottom;
  while (depth > 0) {
    const Step st = path[--depth];
    if (summaryStays(st.c, st.s, before, summaryOf(below.c, below.s))) break;
    if (!refit(st.c, st.s, &before)) break;
    below = st;
  }
  return true;
}

// The node becomes one leaf holding what is left of its subtree once `removed` is gone.
void OctoBvh::mergeIntoLeaf(uint32_t c, int s, uint32_t removed) {
  std::vector<uint32_t>& rest = mergeScratch_;
  rest.clear();
  gatherSubtree(c, s, rest);
  rest.erase(std::find(rest.begin(), rest.end(), removed));
  replaceWithLeaf(c, s, rest);
}

void OctoBvh::replaceWithLeaf(uint32_t c, int s, const std::vector<uint32_t>& rest) {
  NodeCluster& cl = clusters_[c];
  const uint32_t child = cl.child[s], forced = cl.forced(s);
  cl.child[s] = kInvalidIndex;
  if (forced != kInvalidIndex) {
    cl.numHeld[s] = 0;
    cl.leaf[s] = kInvalidIndex;
    freeSubtreeClusters(forced);
  } else {
    heldDrop(c, s);
  }
  if (child != kInvalidIndex) freeSubtreeClusters(child);
  for (uint32_t x : rest) heldAdd(c, s, x);
}

// Takes e out of the elements node (c, s) holds and says whether the node's summary may have
// changed. It cannot when e lay strictly inside the node's bounds, below its largest min
// level, and a remaining held element has all of e's filter bits: then one record is read
// instead of every remaining one (a refit), and nothing above is refitted either.
bool OctoBvh::heldRemoveChanges(uint32_t c, int s, const Placement& p) {
  heldRemove(c, s, p.e);
  const NodeCluster& cl = clusters_[c];
  const ElementRecord& r = elements_[p.e];
  if (cl.numHeld[s] == 0 || p.minLevel >= cl.maxMinLevel[s]) return true;
  if (!(r.min[0] > cl.minX[s] && r.min[1] > cl.minY[s] && r.min[2] > cl.minZ[s] && r.max[0] < cl.maxX[s] &&
        r.max[1] < cl.maxY[s] && r.max[2] < cl.maxZ[s]))
    return true;
  uint32_t other = cl.leaf[s];  // a single held element is inline
  if (cl.numHeld[s] == kOverflow) other = overflow_[cl.leaf[s]].elements[0];
  else if (cl.numHeld[s] > 1) other = leaves_[cl.leaf[s]].elements[0];
  return (r.filter & ~elements_[other].filter) != 0;
}

// Down the element's path (counts drop on the way), then back up: each node undoes a forced
// split the removal ended and refits only while the summary below it changed (most removals
// change only the bottom levels). An explicit path instead of recursion, as in insertAt.
void OctoBvh::removeAt(uint32_t c, int s, Cube cube, const Placement& p) {
  enum Way : uint8_t { kToChildren, kToForcedCluster };
  struct Step {
    uint32_t c;
    int s;
    Way way;
  };
  Step path[kMaxLevel - kMinLevel + 2];  // every step goes down one level
  int depth = 0;
  const uint32_t e = p.e;
  const Lattice at = latticeOf(p.ctr);
  // Steps where the way back up may undo a forced split, by depth: their counts are final once
  // the walk has passed them, so above the highest one the way up stops when nothing changed.
  uint64_t undoSteps = 0;
  bool changed = true;  // whether the summary of the node the walk stopped at changed
  for (int level = cube.level;; --level) {
    NodeCluster& cl = clusters_[c];
    if (cl.child[s] == kInvalidIndex) {
      changed = heldRemoveChanges(c, s, p);
      break;
    }
    prefetchForEdit(clusters_[cl.child[s]], false);
    if (subtreeCount(c, s) - 1 <= uint32_t(kLeafCapacity)) {
      mergeIntoLeaf(c, s, e);
      break;
    }
    // (Under a node that forced everything, more than 8 are left: else it merged above.)
    const uint32_t sub = clusterBelow(cl, s, level, p.minLevel);
    if (sub == kInvalidIndex) {
      changed = heldRemoveChanges(c, s, p);
      break;
    }
    const Way way = sub == cl.child[s] ? kToChildren : kToForcedCluster;
    path[depth] = {c, s, way};
    NodeCluster& from = clusters_[sub];
    --from.childTotal;
    if (from.forcedCount) --from.forcedCount;
    if (way == kToChildren ? cl.numHeld[s] == kForcedCluster && from.childTotal == 0
                           : from.childTotal == uint32_t(kLeafCapacity))
      undoSteps |= uint64_t(1) << depth;
    ++depth;
    s = at.slotBelow(level);
    c = sub;
  }
  // The way up refits a node when a structure change undone there reshaped it, or when the node
  // below changed in a way that reaches it (summaryStays): `before` is that node's summary
  // before its refit.
  NodeSummary before{};
  uint32_t belowC = c;
  int belowS = s;
  if (changed) changed = refit(c, s, &before);
  while (depth > 0) {
    if (!changed && (undoSteps & ((uint64_t(1) << depth) - 1)) == 0) break;  // nothing left to do above
    const Step st = path[--depth];
    bool reshaped = false;
    NodeCluster& cl = clusters_[st.c];
    const uint32_t child = cl.child[st.s], forced = cl.forced(st.s);
    if (st.way == kToChildren && forced != kInvalidIndex && clusters_[child].childTotal == 0) {
      // Nothing left that fits a child: the forced subtree becomes the children again.
      clusters_.free(child);
      NodeCluster& n = clusters_[st.c];
      n.child[st.s] = forced;
      n.numHeld[st.s] = 0;
      n.leaf[st.s] = kInvalidIndex;
      changed = reshaped = true;
    } else if (st.way == kToForcedCluster && clusters_[forced].childTotal == uint32_t(kLeafCapacity)) {
      // Down to 8 large elements: they are held here again.
      std::vector<uint32_t> big;
      big.reserve(8);
      for (int o = 0; o < 8; ++o)
        if (!clusters_[forced].isEmpty(o)) gatherSubtree(forced, o, big);
      NodeCluster& n = clusters_[st.c];
      n.numHeld[st.s] = 0;
      n.leaf[st.s] = kInvalidIndex;
      freeSubtreeClusters(forced);
      for (uint32_t x : big) heldAdd(st.c, st.s, x);
      changed = reshaped = true;
    }
    if (!changed) continue;
    if (!reshaped && summaryStays(st.c, st.s, before, summaryOf(belowC, belowS))) {
      changed = false;
      continue;
    }
    changed = refit(st.c, st.s, &before);
    belowC = st.c;
    belowS = st.s;
  }
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
    const double half = pow2(R - 1);
    // Every element then has a half extent of at most half / 2 (its float extent may have been
    // rounded down by 2^-24 of itself, hence the slack): if the tree's bounds reach past that
    // beyond the half-size cube, some centre lies outside it. One look at the root instead of a
    // walk over its two top levels (most removes from a big tree end here).
    const double reach = 1.5 * half * (1.0 + 0x1p-20);
    if (root.minX[0] < -reach || root.minY[0] < -reach || root.minZ[0] < -reach || root.maxX[0] > reach ||
        root.maxY[0] > reach || root.maxZ[0] > reach)
      return;
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
