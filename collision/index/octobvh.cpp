#include "collision/index/octobvh.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "collision/core/argument_checks.h"

namespace bw {

using namespace octobvh;

namespace {

// Build items kept between builds (1 KiB): enough for any leaf split or root growth.
constexpr size_t kKeptBuildItems = 32;
// Worst-case pool use of one insert: root growth (<= 9 clusters per level over ~40 levels) plus
// a split or forced split that may build chains down to kMinLevel for 9 elements.
constexpr uint32_t kClusterHeadroom = 1024;
constexpr uint32_t kLeafHeadroom = 1024;
constexpr int8_t kEmptyMinLevel = -128;
constexpr float kInf = std::numeric_limits<float>::infinity();

}  // namespace

// ---------------------------------------------------------------- construction

OctoBvh::OctoBvh(Config config)
    : config_(config),
      elements_(config.maxElements, "OctoBVH elements"),
      clusters_(config.maxElements + kClusterHeadroom * 4, "OctoBVH node clusters"),
      leaves_(config.maxElements + kLeafHeadroom * 4, "OctoBVH leaf blocks"),
      overflow_(config.maxElements / 8 + 1024, "OctoBVH overflow blocks") {
  if (config.maxElements == 0 || config.maxElements > (1u << 30))
    throw InvalidInput("OctoBvh: maxElements is " + std::to_string(config.maxElements) + ", expected 1..2^30");
  rootCluster_ = allocCluster(rootLevel_);
}

uint32_t OctoBvh::allocCluster(int level) {
  const uint32_t c = clusters_.allocate();
  NodeCluster& cl = clusters_[c];
  const Aabb e = Aabb::empty();
  for (int s = 0; s < 8; ++s) {
    cl.setBounds(s, e);
    cl.child[s] = kInvalidIndex;
    cl.leaf[s] = kInvalidIndex;
    cl.filter[s] = 0;
    cl.numHeld[s] = 0;
    cl.maxMinLevel[s] = kEmptyMinLevel;
  }
  cl.childTotal = 0;
  cl.forcedCount = 0;
  cl.level = int8_t(level);
  return c;
}

void OctoBvh::clear() {
  NodeCluster& root = clusters_[rootCluster_];
  if (root.child[0] != kInvalidIndex) freeSubtreeClusters(root.child[0]);
  std::vector<uint32_t> held;
  heldTake(rootCluster_, 0, held);
  clearNode(rootCluster_, 0);
  std::vector<uint32_t> all;
  elements_.forEachLive([&](uint32_t e) { all.push_back(e); });
  for (uint32_t e : all) elements_.free(e);
  rootLevel_ = kMinLevel + 1;
  clusters_[rootCluster_].level = int8_t(rootLevel_);
}

// ---------------------------------------------------------------- validation of input

void OctoBvh::validateElement(const Aabb& b, const char* context) const {
  // note: one branch-free pass for the common case (a bulk load validates every element first);
  // the checks below only run to name what is wrong. NaN fails every comparison, inf the range.
  bool ok = true;
  for (int i = 0; i < 3; ++i)
    ok &= (b.min[i] <= b.max[i]) & (b.min[i] > -kMaxCoordinate) & (b.max[i] < kMaxCoordinate);
  if (ok) return;
  requireFinite(b.min, context, "bounds.min");
  requireFinite(b.max, context, "bounds.max");
  for (int i = 0; i < 3; ++i) {
    if (b.min[i] > b.max[i])
      throw InvalidInput(std::string(context) + ": bounds.min." + "xyz"[i] + " (" + std::to_string(b.min[i]) +
                         ") is greater than bounds.max." + "xyz"[i] + " (" + std::to_string(b.max[i]) + ")");
    if (std::abs(b.min[i]) >= kMaxCoordinate || std::abs(b.max[i]) >= kMaxCoordinate)
      throw InvalidInput(std::string(context) + ": bounds on " + "xyz"[i] + " reach beyond the grid-local range +-2^30");
  }
}

void OctoBvh::reserveHeadroom(const char* context) const {
  if (elements_.size() >= elements_.capacity())
    throw CapacityExceeded(std::string(context) + ": OctoBVH is full (" + std::to_string(elements_.capacity()) +
                           " elements, see OctoBvh::Config::maxElements)");
  if (clusters_.capacity() - clusters_.size() < kClusterHeadroom ||
      leaves_.capacity() - leaves_.size() < kLeafHeadroom || overflow_.capacity() - overflow_.size() < 16)
    throw CapacityExceeded(std::string(context) + ": OctoBVH node pools are exhausted (" +
                           std::to_string(clusters_.size()) + " clusters in use)");
}

// ---------------------------------------------------------------- held elements

void OctoBvh::heldAdd(uint32_t c, int s, uint32_t e) {
  NodeCluster& cl = clusters_[c];
  if (cl.numHeld[s] == 0) {
    // note: a single held element is stored in the leaf field itself, no block.
    cl.leaf[s] = e;
    cl.numHeld[s] = 1;
    return;
  }
  if (cl.numHeld[s] == 1) {
    const uint32_t only = cl.leaf[s];
    cl.leaf[s] = leaves_.allocate();
    leaves_[cl.leaf[s]].elements[0] = only;
  } else if (cl.numHeld[s] == kLeafCapacity) {
    // Only a min-level leaf holds more than 8: convert to an overflow chain.
    const uint32_t ob = overflow_.allocate();
    OverflowBlock& o = overflow_[ob];
    std::memcpy(o.elements, leaves_[cl.leaf[s]].elements, sizeof(LeafBlock));
    o.count = kLeafCapacity;
    o.next = kInvalidIndex;
    leaves_.free(cl.leaf[s]);
    cl.leaf[s] = ob;
    cl.numHeld[s] = kOverflow;
  }
  if (cl.numHeld[s] == kOverflow) {
    OverflowBlock& first = overflow_[cl.leaf[s]];
    uint32_t idx = first.count++;
    uint32_t b = cl.leaf[s];
    while (idx >= 14) {
      if (overflow_[b].next == kInvalidIndex) {
        const uint32_t nb = overflow_.allocate();
        overflow_[nb].next = kInvalidIndex;
        overflow_[nb].count = 0;
        overflow_[b].next = nb;
      }
      b = overflow_[b].next;
      idx -= 14;
    }
    overflow_[b].elements[idx] = e;
    return;
  }
  leaves_[cl.leaf[s]].elements[cl.numHeld[s]++] = e;
}

void OctoBvh::heldRemove(uint32_t c, int s, uint32_t e) {
  NodeCluster& cl = clusters_[c];
  if (cl.numHeld[s] == kOverflow) {
    // Swap with the chain's last element, then shrink the chain.
    OverflowBlock& first = overflow_[cl.leaf[s]];
    const uint32_t last = first.count - 1;
    uint32_t* lastSlot = nullptr;
    uint32_t* found = nullptr;
    uint32_t i = 0, lastBlockPrev = kInvalidIndex, lastBlock = cl.leaf[s];
    for (uint32_t b = cl.leaf[s], prev = kInvalidIndex; b != kInvalidIndex; prev = b, b = overflow_[b].next) {
      for (uint32_t k = 0; k < 14 && i <= last; ++k, ++i) {
        if (overflow_[b].elements[k] == e) found = &overflow_[b].elements[k];
        if (i == last) {
          lastSlot = &overflow_[b].elements[k];
          lastBlock = b;
          lastBlockPrev = prev;
        }
      }
    }
    if (!found) throw std::logic_error("OctoBvh: element missing from its overflow leaf");
    *found = *lastSlot;
    first.count = last;
    if (last % 14 == 0 && lastBlockPrev != kInvalidIndex) {  // the last block became empty
      overflow_[lastBlockPrev].next = kInvalidIndex;
      overflow_.free(lastBlock);
    }
    if (first.count == kLeafCapacity) {  // back to a plain leaf block
      const uint32_t lb = leaves_.allocate();
      std::memcpy(leaves_[lb].elements, first.elements, sizeof(LeafBlock));
      overflow_.free(cl.leaf[s]);
      cl.leaf[s] = lb;
      cl.numHeld[s] = kLeafCapacity;
    }
    return;
  }
  if (cl.numHeld[s] == 1) {
    if (cl.leaf[s] != e) throw std::logic_error("OctoBvh: element missing from the node that must hold it");
    cl.leaf[s] = kInvalidIndex;
    cl.numHeld[s] = 0;
    return;
  }
  LeafBlock& lb = leaves_[cl.leaf[s]];
  for (int i = 0; i < cl.numHeld[s]; ++i) {
    if (lb.elements[i] == e) {
      lb.elements[i] = lb.elements[--cl.numHeld[s]];
      if (cl.numHeld[s] == 1) {  // back to an inline single element
        const uint32_t only = lb.elements[0];
        leaves_.free(cl.leaf[s]);
        cl.leaf[s] = only;
      }
      return;
    }
  }
  throw std::logic_error("OctoBvh: element missing from the node that must hold it");
}

void OctoBvh::heldTake(uint32_t c, int s, std::vector<uint32_t>& out) {
  forEachHeld(clusters_[c], s, [&](uint32_t e) { out.push_back(e); });
  heldDrop(c, s);
}

void OctoBvh::heldDrop(uint32_t c, int s) {
  NodeCluster& cl = clusters_[c];
  BW_ASSERT(cl.numHeld[s] != kForcedCluster);
  if (cl.numHeld[s] == kOverflow) {
    for (uint32_t b = cl.leaf[s]; b != kInvalidIndex;) {
      const uint32_t next = overflow_[b].next;
      overflow_.free(b);
      b = next;
    }
  } else if (cl.numHeld[s] > 1) {
    leaves_.free(cl.leaf[s]);
  }
  cl.numHeld[s] = 0;
  cl.leaf[s] = kInvalidIndex;
}

// ---------------------------------------------------------------- node helpers

void OctoBvh::clearNode(uint32_t c, int s) {
  NodeCluster& cl = clusters_[c];
  cl.setBounds(s, Aabb::empty());
  cl.child[s] = kInvalidIndex;
  cl.leaf[s] = kInvalidIndex;
  cl.filter[s] = 0;
  cl.numHeld[s] = 0;
  cl.maxMinLevel[s] = kEmptyMinLevel;
}

bool OctoBvh::refit(uint32_t c, int s, NodeSummary* before) {
  NodeCluster& cl = clusters_[c];
  if (before) *before = summaryOf(c, s);
  // note: min levels grow with an element's largest extent, so the largest min level held is
  // the one of the largest extent: one conversion per refit, not one per element. The merges
  // are Aabb::merge's (std::min(acc, v)), on the record's floats.
  float lo[3] = {kInf, kInf, kInf}, hi[3] = {-kInf, -kInf, -kInf}, largest = -1.f;
  uint32_t filter = 0;
  forEachHeld(cl, s, [&](uint32_t e) {
    const ElementRecord& r = elements_[e];
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], r.min[k]);
      hi[k] = std::max(hi[k], r.max[k]);
      largest = std::max(largest, r.max[k] - r.min[k]);
    }
    filter |= r.filter;
  });
  Aabb b{{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}};
  int mml = largest < 0.f ? kEmptyMinLevel : minLevelForExtent(largest);
  cl.forEachSubCluster(s, [&](uint32_t sub) {
    // note: no emptiness test: an empty node's bounds are inverted, its filter 0 and its max
    // min level kEmptyMinLevel, so merging all 8 lanes is exact (and vectorises).
    const NodeCluster& ch = clusters_[sub];
    float lo[3] = {ch.minX[0], ch.minY[0], ch.minZ[0]}, hi[3] = {ch.maxX[0], ch.maxY[0], ch.maxZ[0]};
    for (int o = 1; o < 8; ++o) {
      lo[0] = std::min(lo[0], ch.minX[o]);
      lo[1] = std::min(lo[1], ch.minY[o]);
      lo[2] = std::min(lo[2], ch.minZ[o]);
      hi[0] = std::max(hi[0], ch.maxX[o]);
      hi[1] = std::max(hi[1], ch.maxY[o]);
      hi[2] = std::max(hi[2], ch.maxZ[o]);
    }
    uint32_t f = 0;
    int m = kEmptyMinLevel;
    for (int o = 0; o < 8; ++o) {
      f |= ch.filter[o];
      m = std::max<int>(m, ch.maxMinLevel[o]);
    }
    b.merge(Aabb{{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}});
    filter |= f;
    mml = std::max(mml, m);
  });
  const bool changed = !(cl.bounds(s) == b) || cl.filter[s] != filter || cl.maxMinLevel[s] != mml;
  cl.setBounds(s, b);
  cl.filter[s] = filter;
  cl.maxMinLevel[s] = int8_t(mml);
  return changed;
}

void OctoBvh::gatherSubtree(uint32_t cluster, int s, std::vector<uint32_t>& out) const {
  const NodeCluster& cl = clusters_[cluster];
  forEachHeld(cl, s, [&](uint32_t e) { out.push_back(e); });
  cl.forEachSubCluster(s, [&](uint32_t sub) {
    for (int o = 0; o < 8; ++o)
      if (!clusters_[sub].isEmpty(o)) gatherSubtree(sub, o, out);
  });
}

void OctoBvh::freeSubtreeClusters(uint32_t cluster) {
  for (int o = 0; o < 8; ++o) {
    NodeCluster& cl = clusters_[cluster];
    if (cl.numHeld[o] == kForcedCluster) {
      const uint32_t forced = cl.leaf[o];
      cl.numHeld[o] = 0;
      cl.leaf[o] = kInvalidIndex;
      freeSubtreeClusters(forced);
    }
    if (clusters_[cluster].child[o] != kInvalidIndex) freeSubtreeClusters(clusters_[cluster].child[o]);
    heldDrop(cluster, o);
  }
  clusters_.free(cluster);
}

// ---------------------------------------------------------------- canonical build

// note: a build sorts its elements level by level; each element's centre and min level are
// computed once into a contiguous item (32 B) rather than from its record at every level (a
// handle's record is a random access, and the centre a conversion to double): callgrind put the
// per-level recomputation at most of a bulk load. The items move exactly as the handles did, so
// leaves list their elements in the same order as before (queries report in that order, and
// every scene's state hash depends on it). (Scattering the partitions into a second buffer
// instead of swapping in place saved 2% of a 50k-brick split's instructions, for 50% more page
// faults: not kept.)
void OctoBvh::buildFrom(uint32_t c, int s, const Cube& cube, const uint32_t* elems, uint32_t count) {
  std::vector<BuildItem>& items = buildScratch_;
  items.resize(count);
  for (uint32_t i = 0; i < count; ++i) buildItemOf(elements_[elems[i]], elems[i], items[i]);
  build(c, s, cube, items.data(), count);
  releaseBuildScratch();
}

void OctoBvh::buildItemOf(const ElementRecord& r, uint32_t e, BuildItem& it) {
  centreOf(r, it.ctr);
  it.e = e;
  it.minLevel = int8_t(minLevelOf(r));
}

uint32_t OctoBvh::placeBuilt(uint32_t e) {
  if (!bulk_) return e;
  const uint32_t h = bulk_->fresh[bulk_->placed++];
  elements_[h] = ElementRecord::of(bulk_->bounds[e], bulk_->filters[e], bulk_->payloads[e]);
  bulk_->handles[e] = h;
  return h;
}

void OctoBvh::releaseBuildScratch() {
  if (buildScratch_.capacity() > kKeptBuildItems) std::vector<BuildItem>().swap(buildScratch_);
  if (runScratch_.capacity() > kKeptBuildItems) std::vector<BuildItem>().swap(runScratch_);
}

void OctoBvh::buildLeaf(uint32_t c, int s, const BuildItem* items, uint32_t count) {
  if (bulk_) {
    // note: a leaf's inputs are scattered over the input arrays; asking for all of them
    // first overlaps their misses instead of taking them one placement at a time.
    for (uint32_t i = 0; i < count; ++i) {
      __builtin_prefetch(&bulk_->bounds[items[i].e]);
      __builtin_prefetch(&bulk_->filters[items[i].e]);
      __builtin_prefetch(&bulk_->payloads[items[i].e]);
    }
  }
  for (uint32_t i = 0; i < count; ++i) heldAdd(c, s, placeBuilt(items[i].e));
  refit(c, s);
}

void OctoBvh::build(uint32_t c, int s, const Cube& cube, BuildItem* items, uint32_t count) {
  if (count <= uint32_t(kLeafCapacity) || cube.level == kMinLevel) return buildLeaf(c, s, items, count);
  // Elements that cannot go below this level first.
  BuildItem* mid = std::partition(items, items + count, [&](const BuildItem& it) { return it.minLevel >= cube.level; });
  const uint32_t big = uint32_t(mid - items);
  const bool forced = big > uint32_t(kLeafCapacity);
  const uint32_t child = allocCluster(cube.level - 1);
  clusters_[c].child[s] = child;
  if (!forced) {
    for (uint32_t i = 0; i < big; ++i) heldAdd(c, s, placeBuilt(items[i].e));
    buildOctants(child, cube, items + big, count - big);
  } else if (big == count) {
    // Nothing fits a child: the large elements are forced into the children.
    clusters_[child].forcedCount = big;
    buildOctants(child, cube, items, count);
  } else {
    const uint32_t forcedCluster = allocCluster(cube.level - 1);
    clusters_[c].leaf[s] = forcedCluster;
    clusters_[c].numHeld[s] = kForcedCluster;
    clusters_[forcedCluster].forcedCount = big;
    buildOctants(forcedCluster, cube, items, big);
    buildOctants(child, cube, items + big, count - big);
  }
  refit(c, s);
}

void OctoBvh::partitionByOctant(const Cube& cube, BuildItem* items, uint32_t n, uint32_t start[8], uint32_t counts[8]) {
  for (int o = 0; o < 8; ++o) counts[o] = 0;
  for (uint32_t i = 0; i < n; ++i) {
    items[i].slot = uint8_t(cube.childSlotFor(items[i].ctr));
    ++counts[items[i].slot];
  }
  uint32_t next[8];
  for (int o = 0, acc = 0; o < 8; ++o) {
    start[o] = next[o] = uint32_t(acc);
    acc += int(counts[o]);
  }
  for (int o = 0; o < 8; ++o) {
    const uint32_t end = start[o] + counts[o];
    while (next[o] < end) {
      const int t = items[next[o]].slot;
      if (t == o) ++next[o];
      else std::swap(items[next[o]], items[next[t]++]);
    }
  }
}

// The items' 8-way partition, each part built into its node of cluster `sub`.
void OctoBvh::buildOctants(uint32_t sub, const Cube& cube, BuildItem* items, uint32_t n) {
  clusters_[sub].childTotal = n;
  uint32_t start[8], counts[8];
  partitionByOctant(cube, items, n, start, counts);
  for (int o = 0; o < 8; ++o)
    if (counts[o]) build(sub, o, cube.child(o), items + start[o], counts[o]);
}

namespace {
// The canonical root level of a set of elements: the extreme centres on each axis decide, as
// every centre must lie in [-2^R, 2^R), and so does the largest min level.
struct RootLevelScan {
  int R = kMinLevel;
  double lo = 0, hi = 0;
  void add(int minLevel, const double ctr[3]) {
    R = std::max(R, minLevel);
    for (int k = 0; k < 3; ++k) {
      lo = std::min(lo, ctr[k]);
      hi = std::max(hi, ctr[k]);
    }
  }
  int level() const {
    int r = R;
    while (!(lo >= -pow2(r) && hi < pow2(r))) ++r;
    return r + 1;
  }
};
}  // namespace

int OctoBvh::canonicalRootLevel(const std::vector<uint32_t>& elems) const {
  RootLevelScan scan;
  for (uint32_t e : elems) {
    double ctr[3];
    centreOf(elements_[e], ctr);
    scan.add(minLevelOf(elements_[e]), ctr);
  }
  return scan.level();
}

std::vector<uint32_t> OctoBvh::bulkLoad(std::span<const Aabb> bounds, std::span<const uint32_t> filters,
                                        std::span<const uint32_t> payloads) {
  return bulkLoadCheckingBounds(bounds, filters, payloads, true);
}

std::vector<uint32_t> OctoBvh::bulkLoadValid(std::span<const Aabb> bounds, std::span<const uint32_t> filters,
                                             std::span<const uint32_t> payloads) {
  return bulkLoadCheckingBounds(bounds, filters, payloads, false);
}

std::vector<uint32_t> OctoBvh::bulkLoadCheckingBounds(std::span<const Aabb> bounds, std::span<const uint32_t> filters,
                                               std::span<const uint32_t> payloads, bool checkBounds) {
  if (!empty()) throw InvalidInput("OctoBvh::bulkLoad: the tree must be empty");
  if (filters.size() != bounds.size() || payloads.size() != bounds.size())
    throw InvalidInput("OctoBvh::bulkLoad: bounds, filters and payloads differ in length (" +
                       std::to_string(bounds.size()) + ", " + std::to_string(filters.size()) + ", " +
                       std::to_string(payloads.size()) + ")");
  if (bounds.size() > elements_.capacity())
    throw CapacityExceeded("OctoBvh::bulkLoad: " + std::to_string(bounds.size()) + " elements exceed the capacity of " +
                           std::to_string(elements_.capacity()));
  // note: the records are written as the build places each element at its node, so the pool
  // holds them in the order the leaves list them: a query reading a leaf's records meets
  // neighbouring lines, not one random line per element. The tree is what inserting them gives;
  // inside a node the elements are in the sorted build's order (octobvh_sorted_build.cpp).
  const uint32_t n = uint32_t(bounds.size());
  std::vector<uint32_t> handles;
  if (n == 0) return handles;
  RootLevelScan scan;
  BuildItem it;
  for (uint32_t i = 0; i < n; ++i) {  // one pass over the input: checked and scanned (nothing touched yet)
    if (checkBounds) validateElement(bounds[i], "OctoBvh::bulkLoad");
    buildItemOf(ElementRecord::of(bounds[i], 0, 0), i, it);
    scan.add(it.minLevel, it.ctr);
  }
  handles.resize(n);
  rootLevel_ = scan.level();
  clusters_[rootCluster_].level = int8_t(rootLevel_);
  // The n handles the placements would allocate one by one, in their order, at once (nothing
  // else allocates elements during the build). placeBuilt writes each record whole: the
  // records are not zeroed first (a pass over 32 bytes an element, its pages' first touch).
  const std::unique_ptr<uint32_t[]> fresh(new uint32_t[n]);  // (written whole: not zeroed first)
  elements_.allocateManyForOverwrite(n, fresh.get());
  BulkInput input{bounds.data(), filters.data(), payloads.data(), handles.data(), fresh.get(), 0};
  struct BulkScope {  // the build reads bulk_ only while bulkLoad runs
    OctoBvh& tree;
    ~BulkScope() { tree.bulk_ = nullptr; }
  } scope{*this};
  bulk_ = &input;
  // note: one radix sort instead of build()'s partition at every level (the same tree; a 50k
  // brick part's build 46.6 -> 32.6 M instructions, octobvh_sorted_build.cpp).
  const OverwriteVector<SortedItem> sorted = sortForBuild(bounds);
  buildSorted(rootCluster_, 0, rootCube(), 0, sorted.data(), n);
  BW_ASSERT(input.placed == n);  // every handle allocated above went to an element
  releaseBuildScratch();
  return handles;
}

void OctoBvh::overlap(const Aabb& box, uint32_t mask, std::vector<uint32_t>& out, QueryStats* stats) const {
  overlap(box, mask, [&](uint32_t e) { out.push_back(e); }, stats);
}

void OctoBvh::overlap(const Obb& box, uint32_t mask, std::vector<uint32_t>& out, QueryStats* stats) const {
  overlap(box, mask, [&](uint32_t e) { out.push_back(e); }, stats);
}

}  // namespace bw
