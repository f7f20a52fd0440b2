// OctoBVH diagnostics: structure hash, full validation, memory and shape figures.
#include <algorithm>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include "collision/core/hash.h"
#include "collision/index/octobvh.h"

namespace bw {

using namespace octobvh;

namespace {

uint64_t elementKey(const ElementRecord& r) {
  uint64_t h = 0;
  for (int i = 0; i < 3; ++i) h = hashCombine(hashCombine(h, bitsOf(r.min[i])), bitsOf(r.max[i]));
  return hashCombine(hashCombine(h, r.filter), r.payload);
}

[[noreturn]] void broken(const std::string& what) { throw std::logic_error("OctoBvh::validate: " + what); }

}  // namespace

uint64_t OctoBvh::hashNode(uint32_t c, int s) const {
  const NodeCluster& cl = clusters_[c];
  if (cl.isEmpty(s)) return 0x5EEDull;
  uint64_t h = hashCombine(uint64_t(int64_t(cl.level) + 1000), heldCount(c, s));
  const Aabb b = cl.bounds(s);
  for (int i = 0; i < 3; ++i) h = hashCombine(hashCombine(h, bitsOf(b.min[i])), bitsOf(b.max[i]));
  h = hashCombine(hashCombine(h, cl.filter[s]), uint64_t(int64_t(cl.maxMinLevel[s]) + 1000));
  std::vector<uint64_t> keys;
  forEachHeld(cl, s, [&](uint32_t e) { keys.push_back(elementKey(elements_[e])); });
  std::sort(keys.begin(), keys.end());  // order inside a leaf is not part of the structure
  for (uint64_t k : keys) h = hashCombine(h, k);
  cl.forEachSubCluster(s, [&](uint32_t sub) {
    const NodeCluster& ch = clusters_[sub];
    h = hashCombine(hashCombine(hashCombine(h, sub == cl.child[s] ? 0xC1D5ull : 0xF0CEull), ch.childTotal), ch.forcedCount);
    for (int o = 0; o < 8; ++o) h = hashCombine(h, hashNode(sub, o));
  });
  return h;
}

uint64_t OctoBvh::structureHash() const { return hashCombine(uint64_t(rootLevel_ + 1000), hashNode(rootCluster_, 0)); }

void OctoBvh::validateNode(uint32_t c, int s, const Cube& cube, std::vector<uint32_t>& out) const {
  const NodeCluster& cl = clusters_[c];
  std::ostringstream where;
  where << "node (cluster " << c << ", slot " << s << ", level " << cube.level << ")";
  if (cl.level != cube.level) broken(where.str() + ": cluster level " + std::to_string(cl.level));
  if (cl.isEmpty(s)) {
    if (!cl.bounds(s).isEmpty() || cl.filter[s] != 0) broken(where.str() + ": empty node with bounds or filter");
    return;
  }
  const size_t first = out.size();
  std::vector<uint32_t> held;
  forEachHeld(cl, s, [&](uint32_t e) { held.push_back(e); });
  if (cl.numHeld[s] == kOverflow && (cube.level != kMinLevel || held.size() <= size_t(kLeafCapacity)))
    broken(where.str() + ": overflow chain above the minimum level or with <= 8 elements");
  if (cl.numHeld[s] != kOverflow && cl.numHeld[s] != kForcedCluster && cl.numHeld[s] > kLeafCapacity)
    broken(where.str() + ": more than 8 held");
  const double width = std::ldexp(1.0, cube.level);
  for (uint32_t e : held) {
    if (!elements_.isLive(e)) broken(where.str() + ": holds a dead element " + std::to_string(e));
    double ctr[3];
    centreOf(elements_[e], ctr);
    for (int i = 0; i < 3; ++i)
      if (!(ctr[i] >= cube.origin[i] && ctr[i] < cube.origin[i] + width))
        broken(where.str() + ": element " + std::to_string(e) + " centre outside the node cube");
    out.push_back(e);
  }
  const uint32_t forced = cl.forced(s);
  if (cl.child[s] == kInvalidIndex) {
    if (forced != kInvalidIndex) broken(where.str() + ": a forced cluster without children");
    if (held.size() > size_t(kLeafCapacity) && cube.level != kMinLevel) broken(where.str() + ": leaf with > 8 above min level");
  } else {
    // Validates the 8 nodes of cluster `sub` and returns how many elements they hold.
    auto validateSub = [&](uint32_t sub) {
      const size_t before = out.size();
      for (int o = 0; o < 8; ++o) validateNode(sub, o, cube.child(o), out);
      const size_t below = out.size() - before;
      if (below != clusters_[sub].childTotal)
        broken(where.str() + ": childTotal " + std::to_string(clusters_[sub].childTotal) + " but " + std::to_string(below) + " below");
      return below;
    };
    const NodeCluster& ch = clusters_[cl.child[s]];
    const size_t inChildren = validateSub(cl.child[s]);
    size_t inForced = 0;
    if (forced != kInvalidIndex) {
      const size_t beforeForced = out.size();
      inForced = validateSub(forced);
      if (clusters_[forced].forcedCount != inForced) broken(where.str() + ": forced cluster's forcedCount is stale");
      for (size_t i = beforeForced; i < out.size(); ++i)
        if (minLevelOf(elements_[out[i]]) < cube.level) broken(where.str() + ": forced cluster holds an element that fits a child");
    }
    const size_t n = out.size() - first;
    if (n <= size_t(kLeafCapacity)) broken(where.str() + ": inner node with only " + std::to_string(n) + " elements");
    size_t big = 0;
    for (size_t i = first; i < out.size(); ++i) big += minLevelOf(elements_[out[i]]) >= cube.level;
    if (big > size_t(kLeafCapacity) && big == n) {
      if (ch.forcedCount != big || forced != kInvalidIndex || !held.empty())
        broken(where.str() + ": should force all " + std::to_string(big) + " elements into its children, forcedCount " +
               std::to_string(ch.forcedCount) + ", held " + std::to_string(held.size()));
    } else if (big > size_t(kLeafCapacity)) {
      if (forced == kInvalidIndex || inForced != big || ch.forcedCount != 0)
        broken(where.str() + ": should force " + std::to_string(big) + " elements into a forced cluster beside " +
               std::to_string(inChildren) + " in its children");
    } else {
      if (ch.forcedCount != 0 || forced != kInvalidIndex) broken(where.str() + ": forced without a forced split");
      if (held.size() != big) broken(where.str() + ": holds " + std::to_string(held.size()) + " but " + std::to_string(big) + " are too large for the children");
      for (uint32_t e : held)
        if (minLevelOf(elements_[e]) < cube.level) broken(where.str() + ": holds an element that fits a child");
    }
  }
  Aabb b = Aabb::empty();
  uint32_t filter = 0;
  int mml = -128;
  for (size_t i = first; i < out.size(); ++i) {
    const ElementRecord& r = elements_[out[i]];
    b.merge(r.bounds());
    filter |= r.filter;
    mml = std::max(mml, minLevelOf(r));
  }
  if (!(b == cl.bounds(s))) broken(where.str() + ": bounds are not the tight bounds of the subtree");
  if (filter != cl.filter[s]) broken(where.str() + ": filter OR is stale");
  if (mml != cl.maxMinLevel[s]) broken(where.str() + ": maxMinLevel is stale");
}

void OctoBvh::validate() const {
  std::vector<uint32_t> seen;
  validateNode(rootCluster_, 0, rootCube(), seen);
  std::sort(seen.begin(), seen.end());
  if (std::adjacent_find(seen.begin(), seen.end()) != seen.end()) broken("an element is held twice");
  if (seen.size() != size()) broken("tree holds " + std::to_string(seen.size()) + " elements, pool has " + std::to_string(size()));
  const int canonical = seen.empty() ? kMinLevel + 1 : canonicalRootLevel(seen);
  if (canonical != rootLevel_)
    broken("root level " + std::to_string(rootLevel_) + ", canonical " + std::to_string(canonical));
}

OctoBvh::MemoryStats OctoBvh::memoryStats() const {
  MemoryStats m;
  m.clusters = clusters_.size();
  m.nodes = m.clusters * 8;
  clusters_.forEachLive([&](uint32_t c) {
    for (int s = 0; s < 8; ++s) m.nonEmptyNodes += !clusters_[c].isEmpty(s);
  });
  m.leafBlocks = leaves_.size();
  m.overflowBlocks = overflow_.size();
  m.elements = elements_.size();
  m.nodeBytes = m.clusters * sizeof(NodeCluster);
  m.leafBytes = m.leafBlocks * sizeof(LeafBlock) + m.overflowBlocks * sizeof(OverflowBlock);
  m.elementBytes = m.elements * sizeof(ElementRecord);
  return m;
}

void OctoBvh::shapeNode(uint32_t c, int s, int depth, ShapeStats& st) const {
  const NodeCluster& cl = clusters_[c];
  if (cl.isEmpty(s)) return;
  st.depth = std::max(st.depth, depth);
  if (cl.child[s] == kInvalidIndex) {
    ++st.leaves;
  } else {
    ++st.innerNodes;
    if (clusters_[cl.child[s]].forcedCount || cl.forced(s) != kInvalidIndex) ++st.forcedNodes;
    if (cl.forced(s) != kInvalidIndex) ++st.forcedClusters;
    cl.forEachSubCluster(s, [&](uint32_t sub) {
      for (int o = 0; o < 8; ++o) shapeNode(sub, o, depth + 1, st);
    });
  }
  forEachHeld(cl, s, [&](uint32_t e) { st.forcedElements += minLevelOf(elements_[e]) > cl.level; });
}

OctoBvh::ShapeStats OctoBvh::shapeStats() const {
  ShapeStats st;
  shapeNode(rootCluster_, 0, 0, st);
  return st;
}

size_t OctoBvh::residentBytes() const {
  return elements_.residentBytes() + clusters_.residentBytes() + leaves_.residentBytes() + overflow_.residentBytes();
}

}  // namespace bw
