#include "collision/index/loose_octree.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "collision/core/argument_checks.h"

namespace bw {

using namespace octobvh;

namespace {

int childSlotFor(const double origin[3], int level, const double c[3]) {
  // origin/level describe the node's own cube
  const double half = std::ldexp(1.0, level - 1);
  return (c[0] >= origin[0] + half ? 1 : 0) | (c[1] >= origin[1] + half ? 2 : 0) | (c[2] >= origin[2] + half ? 4 : 0);
}

void nodeOrigin(const LooseOctree::Cluster& cl, int s, double out[3]) {
  const double w = std::ldexp(1.0, cl.level);
  for (int i = 0; i < 3; ++i) out[i] = cl.origin[i] + ((s >> i) & 1 ? w : 0.0);
}

}  // namespace

LooseOctree::LooseOctree(Config config)
    : config_(config),
      elements_(config.maxElements, "LooseOctree elements"),
      clusters_(config.maxElements + 4096, "LooseOctree clusters") {
  rootCluster_ = clusters_.allocate();
  Cluster& r = clusters_[rootCluster_];
  for (int s = 0; s < 8; ++s) r.child[s] = r.head[s] = kInvalidIndex, r.held[s] = r.subtree[s] = 0;
  rootLevel_ = kMinLevel + 1;
  r.level = int8_t(rootLevel_);
  const double o = -std::ldexp(1.0, rootLevel_ - 1);
  // The root node is slot 0: its cube origin is the cluster origin.
  r.origin[0] = r.origin[1] = r.origin[2] = o;
}

Aabb LooseOctree::looseBounds(const Cluster& cl, int s) const {
  double o[3];
  nodeOrigin(cl, s, o);
  const double w = std::ldexp(1.0, cl.level);
  Aabb b;
  for (int i = 0; i < 3; ++i) {
    // Rounded outwards so the float box always contains the exact loose cube.
    const double lo = o[i] - w * 0.5, hi = o[i] + w * 1.5;
    float fl = float(lo), fh = float(hi);
    if (double(fl) > lo) fl = std::nextafter(fl, -INFINITY);
    if (double(fh) < hi) fh = std::nextafter(fh, INFINITY);
    b.min[i] = fl;
    b.max[i] = fh;
  }
  return b;
}

Aabb LooseOctree::rootBounds() const { return looseBounds(clusters_[rootCluster_], 0); }

static void validateInput(const Aabb& b, const char* context) {
  requireFinite(b.min, context, "bounds.min");
  requireFinite(b.max, context, "bounds.max");
  for (int i = 0; i < 3; ++i) {
    if (b.min[i] > b.max[i])
      throw InvalidInput(std::string(context) + ": bounds.min." + "xyz"[i] + " is greater than bounds.max." + "xyz"[i]);
    if (std::abs(b.min[i]) >= kMaxCoordinate || std::abs(b.max[i]) >= kMaxCoordinate)
      throw InvalidInput(std::string(context) + ": bounds on " + "xyz"[i] + " reach beyond the grid-local range +-2^30");
  }
}

void LooseOctree::pushHeld(uint32_t c, int s, uint32_t e) {
  Cluster& cl = clusters_[c];
  elements_.get<1>(e) = cl.head[s];
  cl.head[s] = e;
  ++cl.held[s];
}

uint32_t LooseOctree::insert(const Aabb& bounds, uint32_t filter, uint32_t payload) {
  validateInput(bounds, "LooseOctree::insert");
  if (elements_.size() >= elements_.capacity())
    throw CapacityExceeded("LooseOctree::insert: the index is full (" + std::to_string(elements_.capacity()) + " elements)");
  if (clusters_.capacity() - clusters_.size() < 1024)
    throw CapacityExceeded("LooseOctree::insert: node pool is full");
  const uint32_t e = elements_.allocate();
  ElementRecord& r = elements_.get<0>(e);
  for (int k = 0; k < 3; ++k) r.min[k] = bounds.min[k], r.max[k] = bounds.max[k];
  r.filter = filter;
  r.payload = payload;
  double ctr[3];
  centreOf(r, ctr);
  growRootToHold(ctr, minLevelOf(r));
  insertAt(rootCluster_, 0, e);
  return e;
}

void LooseOctree::growRootToHold(const double c[3], int minLevel) {
  for (;;) {
    const int R = rootLevel_ - 1;
    const double half = std::ldexp(1.0, R);
    bool inside = minLevel <= R;
    for (int i = 0; i < 3; ++i) inside = inside && c[i] >= -half && c[i] < half;
    if (inside) return;
    Cluster& root = clusters_[rootCluster_];
    if (root.child[0] != kInvalidIndex) {
      // Old root children (level R) become the inner-corner children of new level R+1 nodes.
      const uint32_t oldC = root.child[0];
      const uint32_t newC = clusters_.allocate();
      Cluster& nc = clusters_[newC];
      nc.level = int8_t(R + 1);
      for (int i = 0; i < 3; ++i) nc.origin[i] = -std::ldexp(1.0, R + 1);
      for (int o = 0; o < 8; ++o) {
        nc.child[o] = nc.head[o] = kInvalidIndex;
        nc.held[o] = nc.subtree[o] = 0;
        const Cluster& old = clusters_[oldC];
        if (old.subtree[o] == 0) continue;
        const uint32_t d = clusters_.allocate();
        Cluster& dc = clusters_[d];
        dc.level = int8_t(R);
        nodeOrigin(nc, o, dc.origin);
        for (int t = 0; t < 8; ++t) dc.child[t] = dc.head[t] = kInvalidIndex, dc.held[t] = dc.subtree[t] = 0;
        const int t = o ^ 7;
        dc.child[t] = old.child[o];
        dc.head[t] = old.head[o];
        dc.held[t] = old.held[o];
        dc.subtree[t] = old.subtree[o];
        nc.child[o] = d;
        nc.subtree[o] = old.subtree[o];
      }
      clusters_.free(oldC);
      clusters_[rootCluster_].child[0] = newC;
    }
    ++rootLevel_;
    Cluster& r = clusters_[rootCluster_];
    r.level = int8_t(rootLevel_);
    for (int i = 0; i < 3; ++i) r.origin[i] = -std::ldexp(1.0, rootLevel_ - 1);
  }
}

void LooseOctree::insertAt(uint32_t c, int s, uint32_t e) {
  for (;;) {
    Cluster& cl = clusters_[c];
    ++cl.subtree[s];
    const int level = cl.level;
    if (cl.child[s] == kInvalidIndex) {
      pushHeld(c, s, e);
      if (cl.held[s] > uint32_t(kLeafCapacity) && level > kMinLevel) split(c, s);
      return;
    }
    if (minLevelOf(elements_.get<0>(e)) > level - 1) {
      pushHeld(c, s, e);
      return;
    }
    double o[3], ctr[3];
    nodeOrigin(cl, s, o);
    centreOf(elements_.get<0>(e), ctr);
    const int slot = childSlotFor(o, level, ctr);
    c = cl.child[s];
    s = slot;
  }
}

void LooseOctree::split(uint32_t c, int s) {
  const uint32_t child = clusters_.allocate();
  Cluster& ch = clusters_[child];
  Cluster& cl = clusters_[c];
  ch.level = int8_t(cl.level - 1);
  nodeOrigin(cl, s, ch.origin);
  for (int o = 0; o < 8; ++o) ch.child[o] = ch.head[o] = kInvalidIndex, ch.held[o] = ch.subtree[o] = 0;
  cl.child[s] = child;
  // Re-distribute: elements that fit a child go down, the rest stay.
  uint32_t e = cl.head[s];
  cl.head[s] = kInvalidIndex;
  cl.held[s] = 0;
  while (e != kInvalidIndex) {
    const uint32_t next = elements_.get<1>(e);
    if (minLevelOf(elements_.get<0>(e)) <= ch.level) {
      double ctr[3];
      centreOf(elements_.get<0>(e), ctr);
      insertAt(child, childSlotFor(ch.origin, cl.level, ctr), e);
    } else {
      pushHeld(c, s, e);
    }
    e = next;
  }
}

void LooseOctree::freeSubtree(uint32_t cluster, std::vector<uint32_t>& elems) {
  for (int o = 0; o < 8; ++o) {
    const Cluster& cl = clusters_[cluster];
    forEachHeld(cl, o, [&](uint32_t e) { elems.push_back(e); });
    if (cl.child[o] != kInvalidIndex) freeSubtree(cl.child[o], elems);
  }
  clusters_.free(cluster);
}

void LooseOctree::remove(uint32_t handle) {
  if (!elements_.isLive(handle))
    throw InvalidInput("LooseOctree::remove: handle " + std::to_string(handle) + " is not an element of this index");
  detach(handle);
  elements_.free(handle);
}

void LooseOctree::detach(uint32_t handle) {
  const ElementRecord& r = elements_.get<0>(handle);
  const int m = minLevelOf(r);
  double ctr[3];
  centreOf(r, ctr);
  // Walk down to the holding node, decrementing subtree counts; remember the topmost node that
  // falls to <= 8 elements so its subtree can be merged.
  uint32_t c = rootCluster_;
  int s = 0;
  uint32_t mergeC = kInvalidIndex;
  int mergeS = 0;
  for (;;) {
    Cluster& cl = clusters_[c];
    --cl.subtree[s];
    if (mergeC == kInvalidIndex && cl.child[s] != kInvalidIndex && cl.subtree[s] <= uint32_t(kLeafCapacity)) mergeC = c, mergeS = s;
    if (cl.child[s] == kInvalidIndex || m > cl.level - 1) break;
    double o[3];
    nodeOrigin(cl, s, o);
    const int slot = childSlotFor(o, cl.level, ctr);
    c = cl.child[s];
    s = slot;
  }
  // Unlink from the holding node's list.
  Cluster& hold = clusters_[c];
  uint32_t* link = &hold.head[s];
  while (*link != handle) {
    if (*link == kInvalidIndex) throw std::logic_error("LooseOctree: element missing from its node");
    link = &elements_.get<1>(*link);
  }
  *link = elements_.get<1>(handle);
  --hold.held[s];
  if (mergeC != kInvalidIndex) {
    std::vector<uint32_t> elems;
    Cluster& mc = clusters_[mergeC];
    freeSubtree(mc.child[mergeS], elems);
    mc.child[mergeS] = kInvalidIndex;
    for (uint32_t e : elems) pushHeld(mergeC, mergeS, e);
  }
}

void LooseOctree::update(uint32_t handle, const Aabb& bounds, uint32_t filter) {
  if (!elements_.isLive(handle))
    throw InvalidInput("LooseOctree::update: handle " + std::to_string(handle) + " is not an element of this index");
  validateInput(bounds, "LooseOctree::update");
  if (clusters_.capacity() - clusters_.size() < 1024) throw CapacityExceeded("LooseOctree::update: node pool is full");
  detach(handle);
  ElementRecord& r = elements_.get<0>(handle);
  for (int k = 0; k < 3; ++k) r.min[k] = bounds.min[k], r.max[k] = bounds.max[k];
  r.filter = filter;
  double ctr[3];
  centreOf(r, ctr);
  growRootToHold(ctr, minLevelOf(r));
  insertAt(rootCluster_, 0, handle);
}

void LooseOctree::validateNode(uint32_t c, int s, uint32_t& total) const {
  const Cluster& cl = clusters_[c];
  double o[3];
  nodeOrigin(cl, s, o);
  const double w = std::ldexp(1.0, cl.level);
  uint32_t held = 0;
  forEachHeld(cl, s, [&](uint32_t e) {
    ++held;
    const ElementRecord& r = elements_.get<0>(e);
    double ctr[3];
    centreOf(r, ctr);
    for (int i = 0; i < 3; ++i)
      if (!(ctr[i] >= o[i] && ctr[i] < o[i] + w)) throw std::logic_error("LooseOctree::validate: centre outside cube");
    if (minLevelOf(r) > cl.level && c != rootCluster_) throw std::logic_error("LooseOctree::validate: element too large for its node");
    if (!looseBounds(cl, s).contains(r.bounds())) throw std::logic_error("LooseOctree::validate: element outside loose bounds");
  });
  if (held != cl.held[s]) throw std::logic_error("LooseOctree::validate: held count");
  uint32_t sub = held;
  if (cl.child[s] != kInvalidIndex)
    for (int k = 0; k < 8; ++k) validateNode(cl.child[s], k, sub);
  if (sub != cl.subtree[s]) throw std::logic_error("LooseOctree::validate: subtree count");
  total += sub;
}

void LooseOctree::validate() const {
  uint32_t total = 0;
  validateNode(rootCluster_, 0, total);
  if (total != size()) throw std::logic_error("LooseOctree::validate: element count");
}

void LooseOctree::overlap(const Aabb& box, uint32_t mask, std::vector<uint32_t>& out, QueryStats* stats) const {
  overlap(box, mask, [&](uint32_t e) { out.push_back(e); }, stats);
}

void LooseOctree::overlap(const Obb& box, uint32_t mask, std::vector<uint32_t>& out, QueryStats* stats) const {
  overlap(box, mask, [&](uint32_t e) { out.push_back(e); }, stats);
}

}  // namespace bw
