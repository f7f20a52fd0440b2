#pragma once
// Query templates of OctoBvh (included by octobvh.h). Kept as templates so callbacks and exact
// hooks inline into the traversal loops.
#include <algorithm>
#include <bit>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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
/// Asks for the cache lines of a cluster's bounds (its first 192 bytes) ahead of their use.
inline void prefetchBounds(const octobvh::NodeCluster& cl) {
  const char* p = reinterpret_cast<const char*>(&cl);
  __builtin_prefetch(p);
  __builtin_prefetch(p + 64);
  __builtin_prefetch(p + 128);
}

/// Nodes counted in an 8-bit mask. note: std::popcount is a libgcc call on baseline x86-64
/// (no POPCNT instruction without -mpopcnt); the table is one load.
inline unsigned popcount8(unsigned bits) {
  static constexpr auto kTable = [] {
    std::array<uint8_t, 256> t{};
    for (int i = 0; i < 256; ++i) t[size_t(i)] = uint8_t(std::popcount(unsigned(i)));
    return t;
  }();
  return kTable[bits & 255u];
}

/// Bit o set when node o of the cluster matches the mask; the nodes a query may enter.
inline unsigned filterMask(const octobvh::NodeCluster& ch, uint32_t mask) {
#if defined(__SSE2__)
  const __m128i m = _mm_set1_epi32(int(mask)), zero = _mm_setzero_si128();
  const __m128i lo = _mm_cmpeq_epi32(_mm_and_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(ch.filter)), m), zero);
  const __m128i hi = _mm_cmpeq_epi32(_mm_and_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(ch.filter + 4)), m), zero);
  return ~(unsigned(_mm_movemask_ps(_mm_castsi128_ps(lo))) | unsigned(_mm_movemask_ps(_mm_castsi128_ps(hi))) << 4) & 255u;
#else
  unsigned cand = 0;
  for (int o = 0; o < 8; ++o) cand |= unsigned((ch.filter[o] & mask) != 0) << o;
  return cand;
#endif
}

/// Bit o set when node o of the cluster matches the mask and its tight bounds overlap box.
/// The portable form; overlapMask is the same, bit for bit, with SSE2 where the target has it.
inline unsigned overlapMaskPortable(const octobvh::NodeCluster& ch, const Aabb& box, uint32_t mask, unsigned& candidates) {
  unsigned hits = 0, cand = 0;
  for (int o = 0; o < 8; ++o) {
    const bool match = (ch.filter[o] & mask) != 0;
    // note: `&` on 0/1 values, not `&&`: no branch per axis (clang warns on `&` between bools).
    const unsigned ov = unsigned(ch.minX[o] <= box.max.x()) & unsigned(ch.maxX[o] >= box.min.x()) &
                        unsigned(ch.minY[o] <= box.max.y()) & unsigned(ch.maxY[o] >= box.min.y()) &
                        unsigned(ch.minZ[o] <= box.max.z()) & unsigned(ch.maxZ[o] >= box.min.z());
    cand |= unsigned(match) << o;
    hits |= (unsigned(match) & ov) << o;
  }
  candidates = cand;
  return hits;
}

/// overlapMaskPortable for all 8 nodes in two halves of 4 (SSE2 is part of every x86-64).
inline unsigned overlapMask(const octobvh::NodeCluster& ch, const Aabb& box, uint32_t mask, unsigned& candidates) {
#if defined(__SSE2__)
  const unsigned cand = filterMask(ch, mask);
  candidates = cand;
  if (!cand) return 0;
  unsigned hits = 0;
  for (int h = 0; h < 8; h += 4) {
    __m128 ov = _mm_and_ps(_mm_cmple_ps(_mm_loadu_ps(ch.minX + h), _mm_set1_ps(box.max.x())),
                           _mm_cmpge_ps(_mm_loadu_ps(ch.maxX + h), _mm_set1_ps(box.min.x())));
    ov = _mm_and_ps(ov, _mm_and_ps(_mm_cmple_ps(_mm_loadu_ps(ch.minY + h), _mm_set1_ps(box.max.y())),
                                   _mm_cmpge_ps(_mm_loadu_ps(ch.maxY + h), _mm_set1_ps(box.min.y()))));
    ov = _mm_and_ps(ov, _mm_and_ps(_mm_cmple_ps(_mm_loadu_ps(ch.minZ + h), _mm_set1_ps(box.max.z())),
                                   _mm_cmpge_ps(_mm_loadu_ps(ch.maxZ + h), _mm_set1_ps(box.min.z()))));
    hits |= unsigned(_mm_movemask_ps(ov)) << h;
  }
  return hits & cand;
#else
  return overlapMaskPortable(ch, box, mask, candidates);
#endif
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
        tests += popcount8(candidates);
        const NodeCluster& ch = clusters_[c];
        while (hits) {
          const int o = std::countr_zero(hits);
          hits &= hits - 1;
          if (!accept(c, o)) continue;
          stack[sp++] = nodeRef(c, o);
          // note: the node's children and what it holds are what its visit reads first.
          if (ch.child[o] != kInvalidIndex) prefetchBounds(clusters_[ch.child[o]]);
          prefetchHeld(ch, o);
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
  // Ties keep the lower axis first. note: an insertion sort by hand, not std::stable_sort, which
  // asks the heap for a buffer: that was a fifth of a short containment ray's instructions.
  int axis[3] = {0, 1, 2};
  const float mag[3] = {std::abs(dir.x()), std::abs(dir.y()), std::abs(dir.z())};
  for (int i = 1; i < 3; ++i)
    for (int j = i; j > 0 && mag[axis[j]] > mag[axis[j - 1]]; --j) std::swap(axis[j], axis[j - 1]);
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
/// A ray (or sweep: a ray against boxes grown by `grow`) set up for testing 8 nodes at once.
struct RaySlabs {
  float origin[3], invDir[3], grow[3];
  bool parallel[3];  // the ray never leaves this axis's slab: tested by containment
  static RaySlabs of(const Ray& ray, const Vec3f& grow) {
    RaySlabs r{};
    for (int i = 0; i < 3; ++i) {
      r.origin[i] = ray.origin[i];
      r.invDir[i] = ray.invDir[i];
      r.grow[i] = grow[i];
      r.parallel[i] = (ray.parallelMask >> i) & 1u;
    }
    return r;
  }
  /// intersectRayAabb(ray, record's bounds grown by `grow`, 0, limit, t), read straight from the
  /// record's floats (the same operations in the same order).
  bool enters(const octobvh::ElementRecord& e, float limit, float& t) const {
    float t0 = 0.f, t1 = limit;
    for (int i = 0; i < 3; ++i) {
      const float bmin = e.min[i] - grow[i], bmax = e.max[i] + grow[i];
      if (parallel[i]) {
        if (origin[i] < bmin || origin[i] > bmax) return false;
        continue;
      }
      float a = (bmin - origin[i]) * invDir[i], c = (bmax - origin[i]) * invDir[i];
      if (a > c) std::swap(a, c);
      t0 = a > t0 ? a : t0;
      t1 = c < t1 ? c : t1;
      if (t0 > t1) return false;
    }
    t = t0;
    return true;
  }
};

/// Bit o set when node o of the cluster matches the mask and its (grown) tight bounds meet the
/// ray within [0, limit] (before limit once ties are pruned), with its entry t in t[o] for the
/// nodes hit: intersectRayAabb's slab test, bit for bit. The portable form; rayMask is the same
/// with SSE2.
inline unsigned rayMaskPortable(const octobvh::NodeCluster& ch, const RaySlabs& r, float limit, bool tiesPruned,
                                uint32_t mask, float t[8], unsigned& candidates) {
  const unsigned cand = filterMask(ch, mask);
  candidates = cand;
  const float* lo[3] = {ch.minX, ch.minY, ch.minZ};
  const float* hi[3] = {ch.maxX, ch.maxY, ch.maxZ};
  float t0[8], t1[8];
  bool inside[8];
  for (int o = 0; o < 8; ++o) t0[o] = 0.f, t1[o] = limit, inside[o] = true;
  for (int a = 0; a < 3; ++a) {
    const float g = r.grow[a], org = r.origin[a], inv = r.invDir[a];
    if (r.parallel[a]) {
      for (int o = 0; o < 8; ++o) inside[o] = inside[o] & (org >= lo[a][o] - g) & (org <= hi[a][o] + g);
      continue;
    }
    for (int o = 0; o < 8; ++o) {
      const float p = (lo[a][o] - g - org) * inv, q = (hi[a][o] + g - org) * inv;
      const float n = p > q ? q : p, f = p > q ? p : q;
      t0[o] = n > t0[o] ? n : t0[o];
      t1[o] = f < t1[o] ? f : t1[o];
    }
  }
  unsigned hits = 0;
  for (int o = 0; o < 8; ++o) {
    const bool hit = inside[o] & (t0[o] <= t1[o]) & !(tiesPruned & (t0[o] == limit));
    hits |= unsigned(hit) << o;
    t[o] = t0[o];
  }
  return hits & cand;
}

/// rayMaskPortable for all 8 nodes in two halves of 4: minps/maxps with these operand orders
/// are exactly its ternaries.
inline unsigned rayMask(const octobvh::NodeCluster& ch, const RaySlabs& r, float limit, bool tiesPruned, uint32_t mask,
                        float t[8], unsigned& candidates) {
#if defined(__SSE2__)
  const unsigned cand = filterMask(ch, mask);
  candidates = cand;
  if (!cand) return 0;
  const float* lo[3] = {ch.minX, ch.minY, ch.minZ};
  const float* hi[3] = {ch.maxX, ch.maxY, ch.maxZ};
  unsigned hits = 0;
  for (int h = 0; h < 8; h += 4) {
    __m128 t0 = _mm_setzero_ps(), t1 = _mm_set1_ps(limit);
    __m128 inside = _mm_castsi128_ps(_mm_set1_epi32(-1));
    for (int a = 0; a < 3; ++a) {
      const __m128 g = _mm_set1_ps(r.grow[a]), org = _mm_set1_ps(r.origin[a]);
      const __m128 bmin = _mm_sub_ps(_mm_loadu_ps(lo[a] + h), g), bmax = _mm_add_ps(_mm_loadu_ps(hi[a] + h), g);
      if (r.parallel[a]) {
        inside = _mm_and_ps(inside, _mm_and_ps(_mm_cmpge_ps(org, bmin), _mm_cmple_ps(org, bmax)));
        continue;
      }
      const __m128 inv = _mm_set1_ps(r.invDir[a]);
      const __m128 p = _mm_mul_ps(_mm_sub_ps(bmin, org), inv), q = _mm_mul_ps(_mm_sub_ps(bmax, org), inv);
      t0 = _mm_max_ps(_mm_min_ps(q, p), t0);  // n = p > q ? q : p; t0 = n > t0 ? n : t0
      t1 = _mm_min_ps(_mm_max_ps(p, q), t1);  // f = p > q ? p : q; t1 = f < t1 ? f : t1
    }
    __m128 hit = _mm_and_ps(inside, _mm_cmple_ps(t0, t1));
    if (tiesPruned) hit = _mm_andnot_ps(_mm_cmpeq_ps(t0, _mm_set1_ps(limit)), hit);
    _mm_storeu_ps(t + h, t0);
    hits |= unsigned(_mm_movemask_ps(hit)) << h;
  }
  return hits & cand;
#else
  return rayMaskPortable(ch, r, limit, tiesPruned, mask, t, candidates);
#endif
}

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
  const RaySlabs slabs = RaySlabs::of(ray, grow);
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
      if (slabs.enters(r, limit, te) && !(tiesPruned && te == limit)) limit = onElement(e, te, stop);
    });
    // The forced cluster first, then the children, each pushed far-to-near: the nearest child is
    // popped first.
    auto push = [&](uint32_t c) {
      float tc[8];
      unsigned candidates;
      const unsigned hits = rayMask(tree.cluster(c), slabs, limit, tiesPruned, mask, tc, candidates);
      tests += popcount8(candidates);
      const NodeCluster& ch = tree.cluster(c);
      for (int k = 7; k >= 0; --k) {
        const int o = order[k];
        if (!(hits >> o & 1u)) continue;
        stack[sp++] = {nodeRef(c, o), tc[o]};
        // note: the node's children and what it holds are what its visit reads first; fetch them now.
        if (ch.child[o] != kInvalidIndex) prefetchBounds(tree.cluster(ch.child[o]));
        tree.prefetchHeld(ch, o);
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
