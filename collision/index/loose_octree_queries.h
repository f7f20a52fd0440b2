#pragma once
// Query templates of LooseOctree (included by loose_octree.h): the same traversals as the
// OctoBVH's, against loose cubes instead of tight bounds.
#include <algorithm>

namespace bw {

namespace loose_detail {
constexpr int kStackSize = 7 * (octobvh::kMaxLevel - octobvh::kMinLevel + 2) + 16;
struct RayEntry {
  uint32_t node;
  float t;
};
}  // namespace loose_detail

// The one overlap walk: `hit` tests a box (loose node cube or element bounds) against the query.
template <class Hit, class OnElement>
void LooseOctree::walkOverlap(uint32_t mask, QueryStats* stats, Hit&& hit, OnElement&& onElement) const {
  using namespace octobvh;
  uint64_t tests = 0, elementTests = 0;
  uint32_t stack[loose_detail::kStackSize];
  int sp = 0;
  if (clusters_[rootCluster_].subtree[0]) {
    ++tests;
    if (hit(looseBounds(clusters_[rootCluster_], 0))) stack[sp++] = nodeRef(rootCluster_, 0);
  }
  while (sp) {
    const uint32_t ref = stack[--sp];
    const Cluster& cl = clusters_[ref >> 3];
    const int s = int(ref & 7);
    forEachHeld(cl, s, [&](uint32_t e) {
      const ElementRecord& r = elements_.template get<0>(e);
      if (!(r.filter & mask)) return;
      ++tests;
      ++elementTests;
      const Aabb b = r.bounds();
      if (hit(b)) onElement(e, b);
    });
    if (cl.child[s] == kInvalidIndex) continue;
    const Cluster& ch = clusters_[cl.child[s]];
    for (int o = 0; o < 8; ++o) {
      if (!ch.subtree[o]) continue;
      ++tests;
      if (hit(looseBounds(ch, o))) stack[sp++] = nodeRef(cl.child[s], o);
    }
  }
  if (stats) {
    stats->boxTests += tests;
    stats->elementTests += elementTests;
  }
}

template <class F, class Exact>
void LooseOctree::overlap(const Aabb& box, uint32_t mask, F&& f, QueryStats* stats, Exact&& exact) const {
  walkOverlap(mask, stats, [&](const Aabb& b) { return b.overlaps(box); },
              [&](uint32_t e, const Aabb& b) {
                if (exact(e, b)) f(e);
              });
}

template <class F, class Exact>
void LooseOctree::overlap(const Obb& box, uint32_t mask, F&& f, QueryStats* stats, Exact&& exact) const {
  const Aabb outer = box.bounds();
  // note: cubes and elements both pass the rounding-tolerant test (obb.h mayOverlap: a cube
  // must not be culled when an element inside it overlaps); elements then the exact one.
  walkOverlap(mask, stats, [&](const Aabb& b) { return b.overlaps(outer) && bw::mayOverlap(box, b); },
              [&](uint32_t e, const Aabb& b) {
                if (bw::overlaps(box, b) && exact(e, b)) f(e);
              });
}

template <class Hit>
void LooseOctree::traverseRay(const Ray& ray, uint32_t mask, const std::array<uint8_t, 8>& order, float& limit,
                              bool& stop, QueryStats* stats, Hit&& onElement) const {
  using namespace octobvh;
  uint64_t tests = 0, elementTests = 0;
  loose_detail::RayEntry stack[loose_detail::kStackSize];
  int sp = 0;
  float t;
  if (clusters_[rootCluster_].subtree[0]) {
    ++tests;
    if (intersectRayAabb(ray, looseBounds(clusters_[rootCluster_], 0), 0.f, limit, t)) stack[sp++] = {nodeRef(rootCluster_, 0), t};
  }
  while (sp && !stop) {
    const loose_detail::RayEntry top = stack[--sp];
    if (top.t > limit) continue;
    const Cluster& cl = clusters_[top.node >> 3];
    const int s = int(top.node & 7);
    forEachHeld(cl, s, [&](uint32_t e) {
      if (stop) return;
      const ElementRecord& r = elements_.template get<0>(e);
      if (!(r.filter & mask)) return;
      ++tests;
      ++elementTests;
      float te;
      if (intersectRayAabb(ray, r.bounds(), 0.f, limit, te)) limit = onElement(e, te, stop);
    });
    if (cl.child[s] == kInvalidIndex) continue;
    const Cluster& ch = clusters_[cl.child[s]];
    for (int k = 7; k >= 0; --k) {
      const int o = order[k];
      if (!ch.subtree[o]) continue;
      ++tests;
      float tc;
      if (intersectRayAabb(ray, looseBounds(ch, o), 0.f, limit, tc)) stack[sp++] = {nodeRef(cl.child[s], o), tc};
    }
  }
  if (stats) {
    stats->boxTests += tests;
    stats->elementTests += elementTests;
  }
}

template <class Exact>
RayHit LooseOctree::raycastClosest(const Ray& ray, uint32_t mask, QueryStats* stats, Exact&& exact,
                                   RayChildOrder orderKind) const {
  std::array<uint8_t, 8> order = OctoBvh::rayChildOrder(ray.dir);
  if (orderKind == RayChildOrder::Reversed) std::reverse(order.begin(), order.end());
  RayHit best{RayHit().element, ray.maxT};
  float limit = ray.maxT;
  bool stop = false;
  traverseRay(ray, mask, order, limit, stop, stats, [&](uint32_t e, float tBox, bool&) {
    float th;
    if (exact(e, tBox, limit, th) && th <= limit && (th < best.t || (th == best.t && e < best.element))) best = {e, th};
    return best.hit() ? best.t : limit;
  });
  return best;
}

template <class Exact>
RayHit LooseOctree::raycastAny(const Ray& ray, uint32_t mask, QueryStats* stats, Exact&& exact) const {
  RayHit found;
  float limit = ray.maxT;
  bool stop = false;
  traverseRay(ray, mask, OctoBvh::rayChildOrder(ray.dir), limit, stop, stats, [&](uint32_t e, float tBox, bool& halt) {
    float th;
    if (exact(e, tBox, limit, th) && th <= limit) {
      found = {e, th};
      halt = true;
    }
    return limit;
  });
  return found;
}

template <class Exact>
void LooseOctree::raycastAll(const Ray& ray, uint32_t mask, std::vector<RayHit>& out, QueryStats* stats,
                             Exact&& exact) const {
  const size_t first = out.size();
  float limit = ray.maxT;
  bool stop = false;
  traverseRay(ray, mask, OctoBvh::rayChildOrder(ray.dir), limit, stop, stats, [&](uint32_t e, float tBox, bool&) {
    float th;
    if (exact(e, tBox, limit, th) && th <= limit) out.push_back({e, th});
    return limit;
  });
  std::sort(out.begin() + first, out.end());
}

}  // namespace bw
