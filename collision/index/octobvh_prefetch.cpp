// OctoBVH edit prefetch: the paths of a group of edits walked in lockstep, read-only, so an
// edit loop's cache misses overlap instead of forming one chain per edit.
#include <algorithm>
#include <cmath>

#include "collision/index/octobvh.h"

namespace bw {

using namespace octobvh;

// One level of every walk per round: each round's loads were asked for in the round before.
// The rules are removeAt's and insertAt's (clusterBelow): a walk ends at the node that holds
// its element (or would, or at the leaf an insert splits). Then the lists those nodes hold and
// the records on them (a leaf's refit or split reads every one). Returns how many walks found
// their element (PathWalk::e) on the list where they ended.
size_t OctoBvh::prefetchWalks(PathWalk* walks, size_t walking) const {
  struct Holder {
    uint32_t c;
    int s;
    uint32_t e;
  };
  Holder holders[kPrefetchGroup];
  size_t held = 0;
  for (int level = rootLevel_; walking > 0; --level) {
    size_t next = 0;
    for (size_t g = 0; g < walking; ++g) {
      PathWalk w = walks[g];
      const NodeCluster& cl = clusters_[w.c];
      const uint32_t sub = cl.child[w.s] == kInvalidIndex ? kInvalidIndex : clusterBelow(cl, w.s, level, w.minLevel);
      if (sub == kInvalidIndex) {
        holders[held++] = {w.c, w.s, w.e};
        const uint32_t list = cl.leaf[w.s];
        if (cl.numHeld[w.s] == 1) __builtin_prefetch(&elements_[list]);
        else if (cl.numHeld[w.s] == kOverflow) __builtin_prefetch(&overflow_[list], 1);
        else if (cl.numHeld[w.s] > 1 && cl.numHeld[w.s] <= kLeafCapacity) __builtin_prefetch(&leaves_[list], 1);
        continue;
      }
      w.s = w.at.slotBelow(level);
      w.c = sub;
      prefetchForEdit(clusters_[sub], true);  // edits write bounds on the way down or back up
      walks[next++] = w;
    }
    walking = next;
  }
  size_t found = 0;
  for (size_t k = 0; k < held; ++k) {
    const NodeCluster& cl = clusters_[holders[k].c];
    const int s = holders[k].s;
    if (cl.numHeld[s] >= 2 && cl.numHeld[s] <= kLeafCapacity) {
      const LeafBlock& lb = leaves_[cl.leaf[s]];
      for (int i = 0; i < cl.numHeld[s]; ++i) {
        __builtin_prefetch(&elements_[lb.elements[i]]);
        found += lb.elements[i] == holders[k].e;
      }
    } else {
      forEachHeld(cl, s, [&](uint32_t x) { found += x == holders[k].e; });
    }
  }
  return found;
}

size_t OctoBvh::prefetchPaths(std::span<const uint32_t> handles) const {
  size_t found = 0;
  PathWalk walks[kPrefetchGroup];
  for (size_t first = 0; first < handles.size(); first += kPrefetchGroup) {
    const std::span<const uint32_t> group = handles.subspan(first, std::min(kPrefetchGroup, handles.size() - first));
    for (uint32_t h : group)
      if (elements_.isLive(h)) elements_.prefetchFree(h);  // the record, and what a removal frees
    size_t n = 0;
    for (uint32_t h : group) {
      if (!elements_.isLive(h)) continue;
      const Placement p = placementOf(h);
      walks[n++] = {latticeOf(p.ctr), rootCluster_, 0, p.minLevel, h};
    }
    found += prefetchWalks(walks, n);
  }
  return found;
}

void OctoBvh::prefetchInsertPaths(std::span<const Aabb> bounds) const {
  PathWalk walks[kPrefetchGroup];
  const double half = pow2(rootLevel_ - 1);
  for (size_t first = 0; first < bounds.size(); first += kPrefetchGroup) {
    const std::span<const Aabb> group = bounds.subspan(first, std::min(kPrefetchGroup, bounds.size() - first));
    size_t n = 0;
    for (const Aabb& b : group) {
      // Only boxes an insert would take without growing the root (anything else, bad input
      // included, is skipped: insert() reports it).
      const ElementRecord r = ElementRecord::of(b, 0, 0);
      bool inside = true;
      for (int k = 0; k < 3; ++k) {
        const double c = (double(b.min[k]) + double(b.max[k])) * 0.5;
        inside = inside && std::isfinite(c) && b.min[k] <= b.max[k] && c >= -half && c < half;
      }
      if (!inside) continue;
      double ctr[3];
      centreOf(r, ctr);
      const int minLevel = minLevelOf(r);
      if (minLevel > rootLevel_ - 1) continue;
      walks[n++] = {latticeOf(ctr), rootCluster_, 0, minLevel, kInvalidIndex};
    }
    prefetchWalks(walks, n);
  }
}

}  // namespace bw
