// OctoBVH bulk removal: many elements leave in one walk (a grid losing a part that broke off).
// Subtrees that lose everything are freed whole, nodes left with <= 8 elements become leaves,
// and each other node on the removed elements' paths is refitted once, however many of them
// pass through it: the tree ends exactly as removing them one by one would leave it.
#include <algorithm>
#include <string>

#include "collision/core/argument_checks.h"
#include "collision/index/octobvh.h"

namespace bw {

using namespace octobvh;

namespace {
// Below this many, one remove() each costs less than marking and partitioning.
constexpr size_t kBulkRemoveMin = 64;
}  // namespace

void OctoBvh::removeMany(std::span<const uint32_t> handles) {
  // Checked first, so a bad handle or a handle given twice changes nothing. A few are checked
  // against each other, many through marks by handle (kept for the walk: the survivors of a
  // node that becomes a leaf are the unmarked elements it held).
  const auto refuse = [&](uint32_t h, bool live) {
    throw InvalidInput("OctoBvh::removeMany: handle " + std::to_string(h) + (live ? " is listed twice" : " is not an element of this tree"));
  };
  if (handles.size() < kBulkRemoveMin) {
    for (size_t i = 0; i < handles.size(); ++i) {
      if (!elements_.isLive(handles[i])) refuse(handles[i], false);
      for (size_t j = 0; j < i; ++j)
        if (handles[j] == handles[i]) refuse(handles[i], true);
    }
    for (uint32_t h : handles) remove(h);
    return;
  }
  std::vector<uint8_t> marked(elements_.indexBound(), 0);
  for (uint32_t h : handles) {
    if (!elements_.isLive(h)) refuse(h, false);
    if (marked[h]++) refuse(h, true);
  }
  std::vector<BuildItem>& items = buildScratch_;  // (no build runs during a bulk removal)
  items.resize(handles.size());
  constexpr size_t kAhead = 16;  // the handles come in the caller's order: a miss each
  for (size_t i = 0; i < handles.size(); ++i) {
    if (i + kAhead < handles.size()) prefetchElement(handles[i + kAhead]);
    const ElementRecord& r = elements_[handles[i]];
    centreOf(r, items[i].ctr);
    items[i].e = handles[i];
    items[i].minLevel = int8_t(minLevelOf(r));
  }
  {
    // Whole subtrees go: their clusters' and blocks' emptied pages are given back in runs.
    const auto deferClusters = clusters_.deferPageRelease();
    const auto deferLeaves = leaves_.deferPageRelease();
    const auto deferOverflow = overflow_.deferPageRelease();
    removing_ = marked.data();
    removeManyAt(rootCluster_, 0, rootCube(), items.data(), uint32_t(items.size()));
    removing_ = nullptr;
    releaseBuildScratch();
    elements_.freeManyChecked(handles);  // (checked above: live and distinct)
    shrinkRoot();
  }
}

// Takes the k removed items (all in this node's subtree) out of node (c, s) of cube `cube`.
void OctoBvh::removeManyAt(uint32_t c, int s, const Cube& cube, BuildItem* items, uint32_t k) {
  const uint32_t total = subtreeCount(c, s);
  NodeCluster& cl = clusters_[c];
  if (k == total || total - k <= uint32_t(kLeafCapacity)) {
    // Everything goes, or what is left is one leaf: gather the survivors, drop the subtree.
    std::vector<uint32_t>& rest = mergeScratch_;
    rest.clear();
    if (k != total) {
      gatherSubtree(c, s, rest);
      rest.erase(std::remove_if(rest.begin(), rest.end(), [&](uint32_t e) { return removing_[e] != 0; }), rest.end());
    }
    replaceWithLeaf(c, s, rest);
    refit(c, s);
    return;
  }
  if (cl.child[s] == kInvalidIndex) {  // a min-level leaf holding more than 8
    for (uint32_t i = 0; i < k; ++i) heldRemove(c, s, items[i].e);
    refit(c, s);
    return;
  }
  // An inner node that stays one: its held elements leave here, the rest go down their paths,
  // to the children or to the forced cluster, as removeAt's walk would take them.
  const uint32_t child = cl.child[s], forced = cl.forced(s);
  auto goesTo = [&](const BuildItem& it) { return clusterBelow(clusters_[c], s, cube.level, it.minLevel); };
  BuildItem* toChildren = std::partition(items, items + k, [&](const BuildItem& it) { return goesTo(it) == kInvalidIndex; });
  for (BuildItem* it = items; it != toChildren; ++it) heldRemove(c, s, it->e);
  BuildItem* toForced = std::partition(toChildren, items + k, [&](const BuildItem& it) { return goesTo(it) == child; });
  const auto descend = [&](uint32_t sub, BuildItem* from, BuildItem* to) {
    const uint32_t n = uint32_t(to - from);
    if (n == 0) return;
    NodeCluster& below = clusters_[sub];
    below.childTotal -= n;
    if (below.forcedCount) below.forcedCount -= n;
    uint32_t start[8], counts[8];
    partitionByOctant(cube, from, n, start, counts);
    for (int o = 0; o < 8; ++o)
      if (counts[o]) removeManyAt(sub, o, cube.child(o), from + start[o], counts[o]);
  };
  descend(child, toChildren, toForced);
  if (forced != kInvalidIndex) descend(forced, toForced, items + k);
  if (forced != kInvalidIndex) {
    NodeCluster& n = clusters_[c];
    if (clusters_[child].childTotal == 0) {
      // Nothing left that fits a child: the forced subtree becomes the children again.
      clusters_.free(child);
      n.child[s] = forced;
      n.numHeld[s] = 0;
      n.leaf[s] = kInvalidIndex;
    } else if (clusters_[forced].childTotal <= uint32_t(kLeafCapacity)) {
      // Down to 8 large elements or fewer: they are held here again.
      std::vector<uint32_t>& big = mergeScratch_;
      big.clear();
      for (int o = 0; o < 8; ++o)
        if (!clusters_[forced].isEmpty(o)) gatherSubtree(forced, o, big);
      n.numHeld[s] = 0;
      n.leaf[s] = kInvalidIndex;
      freeSubtreeClusters(forced);
      for (uint32_t x : big) heldAdd(c, s, x);
    }
  }
  refit(c, s);
}

}  // namespace bw
