#pragma once
// Query templates of OctoBvh (included by octobvh.h). Kept as templates so callbacks and exact
// hooks inline into the traversal loops.
#include <algorithm>
#include <bit>

namespace bw {

namespace octobvh_detail {
/// Depth-first stack bound: <= 15 pending nodes per level (a node's children and forced cluster)
/// over kMaxLevel - kMinLevel + 2 levels.
constexpr int kStackSize = 15 * (octobvh::kMaxLevel - octobvh::kMinLevel + 2) + 16;
struct RayEntry {
  uint32_t node;  // cluster << 3 | slot
  float t;        // entry parameter of the node's tight bounds
};
}  // namespace octobvh_detail

template <class F>
void OctoBvh::forEachHeld(const NodeCluster& cl, int s, F&& f) const {
  using namespace octobvh;
  if (cl.numHeld[s] == kOverflow) {
    uint32_t left = overflow_[cl.leaf[s]].count;
    for (uint32_t b = cl.leaf[s]; b != kInvalidIndex && left; b = overflow_[b].next)
      for (uint32_t i = 0; i < 14 && left; ++i, --left) f(overflow_[b].elements[i]);
  } else if (cl.numHeld[s] == 1) {
    f(cl.leaf[s]);  // a single element is stored inline
  } else if (cl.numHeld[s] && cl.numHeld[s] != kForcedCluster) {
    const LeafBlock& lb = leaves_[cl.leaf[s]];
    for (int i = 0; i < cl.numHeld[s]; ++i) f(lb.elements[i]);
  }
}

namespace octobvh_detail {
/// Bit o set when node o of the cluster matches the mask and its tight bounds overlap box.
/// note: written as a branch-free loop over the SoA arrays so the compiler vectorises it.
inline unsigned overlapMask(const octobvh::NodeCluster& ch, const Aabb& box, uint32_t mask, unsigned& candidates) {
  unsigned hits = 0, cand = 0;
  for (int o = 0; o < 8; ++o) {
    const bool match = (ch.filter[o] & mask) != 0;
    const bool ov = (ch.minX[o] <= box.max.x()) & (ch.maxX[o] >= box.min.x()) & (ch.minY[o] <= box.max.y()) &
                    (ch.maxY[o] >= box.min.y()) & (ch.minZ[o] <= box.max.z()) & (ch.maxZ[o] >= box.min.z());
    cand |= unsigned(match) << o;
    hits |= unsigned(match & ov) << o;
  }
  candidates = cand;
  return hits;
}

inline bool elementOverlaps(const octobvh::ElementRecord& r, const Aabb& b) {
  return r.min[0] <= b.max.x() && r.max[0] >= b.min.x() && r.min[1] <= b.max.y() && r.max[1] >= b.min.y() &&
         r.min[2] <= b.max.z() && r.max[2] >= b.min.z();
}
}  // namespace octobvh_detail

// The one depth-first overlap walk behind every overlap form: nodes are culled by the SoA test
// against `outer`; accept(cluster, slot) may reject a node further (the OBB's SAT) or take it
// whole (a LOD box) by returning false; onElement(e, record) tests and reports one element.
template <class OnElement, class Accept>
void OctoBvh::walkOverlap(const Aabb& outer, uint32_t mask, QueryStats* stats, OnElement&& onElement,
                          Accept&& accept) const {
  using namespace octobvh;
  using namespace octobvh_detail;
  const NodeCluster& root = clusters_[rootCluster_];
  uint64_t tests = 0, elementTests = 0;
  if (root.filter[0] & mask) {
    ++tests;
    uint32_t stack[kStackSize];
    int sp = 0;
    if (root.bounds(0).overlaps(outer) && accept(rootCluster_, 0)) stack[sp++] = nodeRef(rootCluster_, 0);
    while (sp) {
      const uint32_t ref = stack[--sp];
      const NodeCluster& cl = clusters_[ref >> 3];
      const int s = int(ref & 7);
      forEachHeld(cl, s, [&](uint32_t e) {
        const ElementRecord& r = elements_[e];
        if (!(r.filter & mask)) return;
        ++tests;
        ++elementTests;
        onElement(e, r);
      });
      cl.forEachSubCluster(s, [&](uint32_t c) {
        unsigned candidates;
        unsigned hits = overlapMask(clusters_[c], outer, mask, candidates);
        tests += unsigned(std::popcount(candidates));
        while (hits) {
          const int o = std::countr_zero(hits);
          hits &= hits - 1;
          if (accept(c, o)) stack[sp++] = nodeRef(c, o);
        }
      });
    }
  }
  if (stats) {
    stats->boxTests += tests;
    stats->elementTests += elementTests;
  }
}

template <class F, class Exact>
void OctoBvh::overlap(const Aabb& box, uint32_t mask, F&& f, QueryStats* stats, Exact&& exact) const {
  walkOverlap(
      box, mask, stats,
      [&](uint32_t e, const octobvh::ElementRecord& r) {
        if (octobvh_detail::elementOverlaps(r, box) && exact(e, r.bounds())) f(e);
      },
      [](uint32_t, int) { return true; });
}

template <class F, class Exact>
void OctoBvh::overlap(const Obb& box, uint32_t mask, F&& f, QueryStats* stats, Exact&& exact) const {
  // note: the cheap AABB-of-the-OBB test (the walk's cull) rejects most nodes before the 15-axis SAT.
  const Aabb outer = box.bounds();
  walkOverlap(
      outer, mask, stats,
      [&](uint32_t e, const octobvh::ElementRecord& r) {
        const Aabb eb = r.bounds();
        if (eb.overlaps(outer) && bw::overlaps(box, eb) && exact(e, eb)) f(e);
      },
      [&](uint32_t c, int o) { return bw::mayOverlap(box, clusters_[c].bounds(o)); });
}

template <class F, class L>
void OctoBvh::overlapLod(const Aabb& box, uint32_t mask, float lodFraction, F&& onElement, L&& onLod,
                         QueryStats* stats) const {
  using namespace octobvh;
  const float threshold = lodFraction * box.extent().maxCoeff();
  walkOverlap(
      box, mask, stats,
      [&](uint32_t e, const ElementRecord& r) {
        if (octobvh_detail::elementOverlaps(r, box)) onElement(e);
      },
      [&](uint32_t c, int o) {
        // A subtree is "small" when its tight bounds' largest extent is below the threshold.
        const NodeCluster& cl = clusters_[c];
        if (!(cl.maxX[o] - cl.minX[o] < threshold && cl.maxY[o] - cl.minY[o] < threshold &&
              cl.maxZ[o] - cl.minZ[o] < threshold))
          return true;
        onLod(LodBox{cl.bounds(o), cl.filter[o], subtreeCount(c, o)});
        return false;
      });
}

inline std::array<uint8_t, 8> OctoBvh::rayChildOrder(const Vec3f& dir) {
  // Axes by decreasing |dir|: the major axis gets the most significant bit of the visit counter,
  // so all four children on the near side of the major split come first. Each bit is flipped
  // for axes the ray travels down (negative component), making "near" bit value 0.
  int axis[3] = {0, 1, 2};
  const float mag[3] = {std::abs(dir.x()), std::abs(dir.y()), std::abs(dir.z())};
  std::stable_sort(axis, axis + 3, [&](int a, int b) { return mag[a] > mag[b]; });
  std::array<uint8_t, 8> order{};
  for (int k = 0; k < 8; ++k) {
    int slot = 0;
    for (int rank = 0; rank < 3; ++rank) {
      const int a = axis[rank];
      const int bit = ((k >> (2 - rank)) & 1) ^ (dir[a] < 0.f ? 1 : 0);
      slot |= bit << a;
    }
    order[k] = uint8_t(slot);
  }
  return order;
}

namespace octobvh_detail {
/// Shared ray traversal: calls onElement(e, tEnterBox) for elements whose bounds the ray enters
/// before the current limit; onElement returns the new limit (pruning farther nodes) and may
/// set `stop` to end the traversal. Once `tiesPruned` is set, nodes and elements entered exactly
/// at the limit are skipped too: a closest-hit search keeps the first hit it meets at a given t
/// (a ray that starts inside bricks has every node around its origin at t = 0).
/// `grow` expands every node and element box before the ray test: a sweep of a shape whose
/// bounds have half extents `grow` is a ray against the grown boxes (article 000, "Sweep Query").
template <class Tree, class OnElement>
void traverseRay(const Tree& tree, const Ray& ray, uint32_t mask, const std::array<uint8_t, 8>& order, float& limit,
                 bool& stop, const bool& tiesPruned, uint64_t& tests, uint64_t& elementTests, OnElement&& onElement,
                 const Vec3f& grow = Vec3f::Zero()) {
  using namespace octobvh;
  const uint32_t rootC = tree.rootCluster();
  const NodeCluster& root = tree.cluster(rootC);
  if (!(root.filter[0] & mask)) return;
  ++tests;
  float t;
  if (!intersectRayAabb(ray, root.bounds(0).expanded(grow), 0.f, limit, t)) return;
  RayEntry stack[kStackSize];
  int sp = 0;
  stack[sp++] = {nodeRef(rootC, 0), t};
  while (sp && !stop) {
    const RayEntry top = stack[--sp];
    if (top.t > limit || (tiesPruned && top.t == limit)) continue;  // a hit this close was found since
    const NodeCluster& cl = tree.cluster(top.node >> 3);
    const int s = int(top.node & 7);
    tree.forEachHeldPublic(cl, s, [&](uint32_t e) {
      if (stop) return;
      const ElementRecord& r = tree.element(e);
      if (!(r.filter & mask)) return;
      ++tests;
      ++elementTests;
      float te;
      if (intersectRayAabb(ray, r.bounds().expanded(grow), 0.f, limit, te) && !(tiesPruned && te == limit))
        limit = onElement(e, te, stop);
    });
    // The forced cluster first, then the children, each pushed far-to-near: the nearest child is
    // popped first.
    auto push = [&](uint32_t c) {
      const NodeCluster& ch = tree.cluster(c);
      for (int k = 7; k >= 0; --k) {
        const int o = order[k];
        if (!(ch.filter[o] & mask)) continue;
        ++tests;
        float tc;
        if (intersectRayAabb(ray, ch.bounds(o).expanded(grow), 0.f, limit, tc) && !(tiesPruned && tc == limit))
          stack[sp++] = {nodeRef(c, o), tc};
      }
    };
    if (cl.child[s] == kInvalidIndex) continue;
    if (cl.forced(s) != kInvalidIndex) push(cl.forced(s));
    push(cl.child[s]);
  }
}
}  // namespace octobvh_detail

template <class Exact>
RayHit OctoBvh::raycastClosest(const Ray& ray, uint32_t mask, QueryStats* stats, Exact&& exact,
                               RayChildOrder orderKind) const {
  std::array<uint8_t, 8> order = rayChildOrder(ray.dir);
  if (orderKind == RayChildOrder::Reversed) std::reverse(order.begin(), order.end());
  RayHit best{RayHit().element, ray.maxT};
  float limit = ray.maxT;
  bool stop = false, found = false;
  uint64_t tests = 0, elementTests = 0;
  octobvh_detail::traverseRay(*this, ray, mask, order, limit, stop, found, tests, elementTests,
                              [&](uint32_t e, float tBox, bool&) {
                                float th;
                                if (exact(e, tBox, limit, th) && th <= limit && (!found || th < best.t)) {
                                  best = {e, th};
                                  found = true;
                                }
                                return best.hit() ? best.t : limit;
                              });
  if (stats) {
    stats->boxTests += tests;
    stats->elementTests += elementTests;
  }
  return best;
}

template <class Exact>
RayHit OctoBvh::sweepClosest(const Ray& ray, const Vec3f& halfExtents, uint32_t mask, Exact&& exact,
                             QueryStats* stats) const {
  RayHit best{RayHit().element, ray.maxT};
  float limit = ray.maxT;
  bool stop = false, found = false;
  uint64_t tests = 0, elementTests = 0;
  octobvh_detail::traverseRay(
      *this, ray, mask, rayChildOrder(ray.dir), limit, stop, found, tests, elementTests,
      [&](uint32_t e, float tBox, bool&) {
        float th;
        if (exact(e, tBox, limit, th) && th <= limit && (!found || th < best.t)) {
          best = {e, th};
          found = true;
        }
        return best.hit() ? best.t : limit;
      },
      halfExtents);
  if (stats) {
    stats->boxTests += tests;
    stats->elementTests += elementTests;
  }
  return best;
}

namespace octobvh_detail {
inline constexpr bool kNoTiePruning = false;  // every-hit and any-hit searches keep every t
}  // namespace octobvh_detail

template <class Exact>
RayHit OctoBvh::raycastAny(const Ray& ray, uint32_t mask, QueryStats* stats, Exact&& exact) const {
  RayHit found;
  float limit = ray.maxT;
  bool stop = false;
  uint64_t tests = 0, elementTests = 0;
  octobvh_detail::traverseRay(*this, ray, mask, rayChildOrder(ray.dir), limit, stop, octobvh_detail::kNoTiePruning, tests, elementTests,
                              [&](uint32_t e, float tBox, bool& halt) {
                                float th;
                                if (exact(e, tBox, limit, th) && th <= limit) {
                                  found = {e, th};
                                  halt = true;
                                }
                                return limit;
                              });
  if (stats) {
    stats->boxTests += tests;
    stats->elementTests += elementTests;
  }
  return found;
}

template <class Exact>
void OctoBvh::raycastAll(const Ray& ray, uint32_t mask, std::vector<RayHit>& out, QueryStats* stats,
                         Exact&& exact) const {
  const size_t first = out.size();
  float limit = ray.maxT;
  bool stop = false;
  uint64_t tests = 0, elementTests = 0;
  octobvh_detail::traverseRay(*this, ray, mask, rayChildOrder(ray.dir), limit, stop, octobvh_detail::kNoTiePruning, tests, elementTests,
                              [&](uint32_t e, float tBox, bool&) {
                                float th;
                                if (exact(e, tBox, limit, th) && th <= limit) out.push_back({e, th});
                                return limit;
                              });
  std::sort(out.begin() + first, out.end());
  if (stats) {
    stats->boxTests += tests;
    stats->elementTests += elementTests;
  }
}

}  // namespace bw
