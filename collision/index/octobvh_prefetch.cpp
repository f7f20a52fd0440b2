// OctoBVH edit prefetch: the paths of a group of elements walked in lockstep, read-only, so an
// edit loop's cache misses overlap instead of forming one chain per edit.
#include <algorithm>

#include "collision/index/octobvh.h"

namespace bw {

using namespace octobvh;

size_t OctoBvh::prefetchPaths(std::span<const uint32_t> handles) const {
  struct Walk {
    Lattice at;
    uint32_t c;
    int s;
    int minLevel;
    uint32_t e;
  };
  struct Holder {
    uint32_t c;
    int s;
    uint32_t e;
  };
  size_t found = 0;
  for (size_t first = 0; first < handles.size(); first += kPrefetchGroup) {
    const size_t n = std::min(kPrefetchGroup, handles.size() - first);
    const uint32_t* h = handles.data() + first;
    for (size_t g = 0; g < n; ++g)
      if (elements_.isLive(h[g])) elements_.prefetchFree(h[g]);  // the record, and what a removal frees
    Walk walks[kPrefetchGroup];
    Holder holders[kPrefetchGroup];
    size_t walking = 0, held = 0;
    for (size_t g = 0; g < n; ++g) {
      if (!elements_.isLive(h[g])) continue;
      const Placement p = placementOf(h[g]);
      walks[walking++] = {latticeOf(p.ctr), rootCluster_, 0, p.minLevel, h[g]};
    }
    // One level of every walk per round: each round's loads were asked for in the round before.
    // The rules are removeAt's (clusterBelow); a walk ends at the node holding its element.
    for (int level = rootLevel_; walking > 0; --level) {
      size_t next = 0;
      for (size_t g = 0; g < walking; ++g) {
        Walk w = walks[g];
        const NodeCluster& cl = clusters_[w.c];
        const uint32_t sub =
            cl.child[w.s] == kInvalidIndex ? kInvalidIndex : clusterBelow(cl, w.s, level, w.minLevel);
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
        prefetchForEdit(clusters_[sub], true);  // a removal refits bounds on its way back up
        walks[next++] = w;
      }
      walking = next;
    }
    // The records on each holder's list: a leaf's refit reads every remaining one.
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
  }
  return found;
}

}  // namespace bw
