#include "collision/terrain/loose_kd_tree.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "collision/core/argument_checks.h"

namespace bw {
namespace {

using Record = KdTreeBuilder::TriRecord;

/// Running bounds and midpoint sum of one side of a partition.
struct SideStats {
  Aabb bounds = Aabb::empty();
  double midSum[3] = {0, 0, 0};  // sums of (min + max), i.e. twice the midpoints
  void add(const Record& r) {
    for (int i = 0; i < 3; ++i) {
      bounds.min[i] = std::min(bounds.min[i], r.min[i]);
      bounds.max[i] = std::max(bounds.max[i], r.max[i]);
      midSum[i] += double(r.min[i]) + double(r.max[i]);
    }
  }
};

int longestAxis(const Aabb& b) {
  const Vec3f e = b.extent();
  return e.x() >= e.y() ? (e.x() >= e.z() ? 0 : 2) : (e.y() >= e.z() ? 1 : 2);
}

/// One raycast stack entry: a node and the ray segment that can lie inside it.
struct RaySegment {
  uint32_t node;  // 4
  float tMin;     // 4
  float tMax;     // 4
};

}  // namespace

void LooseKdTree::clear() {
  nodes_.clear();
  nodes_.shrink_to_fit();
  bounds_ = Aabb::empty();
  depth_ = 0;
}

void LooseKdTree::build(const TriangleMeshView& mesh, KdTreeBuilder& b, KdHeightBoundsMode heightBounds) {
  if (mesh.triangleCount > kMaxTriangles) {
    throw InvalidInput("LooseKdTree::build: mesh.triangleCount is " + std::to_string(mesh.triangleCount) +
                       ", above the 2^29 limit of 30-bit node indices");
  }
  nodes_.clear();
  bounds_ = Aabb::empty();
  depth_ = 0;
  const uint32_t n = mesh.triangleCount;
  if (n == 0) return;
  b.records.resize(n);
  SideStats all;
  for (uint32_t t = 0; t < n; ++t) {
    Vec3f p0, p1, p2;
    mesh.corners(t, p0, p1, p2);
    Record& r = b.records[t];
    for (int i = 0; i < 3; ++i) {
      r.min[i] = std::min(std::min(p0[i], p1[i]), p2[i]);
      r.max[i] = std::max(std::max(p0[i], p1[i]), p2[i]);
    }
    r.id = t;
    all.add(r);
  }
  bounds_ = all.bounds;
  heights_.clear();
  heightAxis_ = -1;
  const Vec3f extent = bounds_.extent();
  int shortest = 0;
  for (int i = 1; i < 3; ++i)
    if (extent[i] < extent[shortest]) shortest = i;
  if (heightBounds == KdHeightBoundsMode::Auto && n >= kHeightBoundsMinTriangles &&
      extent[shortest] * 4.f <= extent.maxCoeff()) {
    heightAxis_ = shortest;
    b.heightLo.resize(2 * size_t(n));  // a tree over n triangles has at most 2n - 1 nodes
    b.heightHi.resize(2 * size_t(n));
  }
  // note: a tree over n triangles has at most 2n - 1 nodes and usually ~1.1n; reserve the
  // usual case and trim afterwards so bytes() is what is actually held.
  nodes_.reserve(size_t(n) + n / 4 + 1);
  nodes_.push_back({});
  depth_ = buildNode(0, 0, n, all.bounds, all.midSum, b, 1);
  if (heightAxis_ >= 0) quantiseHeights(b);
  layoutInTreelets(b);
}

void LooseKdTree::quantiseHeights(KdTreeBuilder& b) {
  const int a = heightAxis_;
  const float range = bounds_.max[a] - bounds_.min[a];
  heightBase_ = bounds_.min[a];
  // note: 65534 steps over the range, so code 65535 lies a whole step above the top: more than
  // any rounding of base + q * step when the range is not tiny against the base.
  heightStep_ = range > 0.f ? range / 65534.f : 1.f;
  auto noBounds = [&] {
    heights_.clear();
    heightAxis_ = -1;
  };
  if (!std::isfinite(heightBase_) || !std::isfinite(range)) return noBounds();
  heights_.resize(nodes_.size());
  for (size_t i = 0; i < nodes_.size(); ++i) {
    const float lo = b.heightLo[i], hi = b.heightHi[i];
    if (!(lo >= heightBase_ && hi <= bounds_.max[a])) return noBounds();  // NaN vertices: no bounds
    float qlo = std::floor((lo - heightBase_) / heightStep_), qhi = std::ceil((hi - heightBase_) / heightStep_);
    uint16_t dlo = uint16_t(std::clamp(qlo, 0.f, 65535.f)), dhi = uint16_t(std::clamp(qhi, 0.f, 65535.f));
    // Rounded outwards as the query will dequantise them, whatever the division's rounding did.
    while (dlo > 0 && heightOf(dlo) > lo) --dlo;
    while (dhi < 65535 && heightOf(dhi) < hi) ++dhi;
    // A range too small against its base to code in 16 bits (far from the origin): no bounds.
    if (heightOf(dlo) > lo || heightOf(dhi) < hi) return noBounds();
    heights_[i] = {dlo, dhi};
  }
}

void LooseKdTree::layoutInTreelets(KdTreeBuilder& b) {
  // The builder emits nodes depth-first, so the deep part of a root-to-leaf path is scattered
  // over the array and every level of a descent is a cache miss on big trees. Re-emit the tree
  // as treelets: kTreeletPairs sibling pairs of a subtree, breadth-first, stored contiguously
  // (168 bytes, about three cache lines), with the treelets below following depth-first.
  // A descent then touches one treelet per three levels. Pairs stay adjacent, so the node
  // format (children at child, child + 1) is unchanged.
  constexpr uint32_t kTreeletPairs = 7;
  const KdNode root = nodes_[0];
  if (root.axis() == KdNode::kLeafAxis) {
    nodes_.shrink_to_fit();
    return;
  }
  std::vector<KdNode>& out = b.layout;
  out.clear();
  out.reserve(nodes_.size());
  out.push_back(root);
  const bool heights = !heights_.empty();
  std::vector<KdHeightBounds>& outHeights = b.heightLayout;
  outHeights.clear();
  if (heights) {
    outHeights.reserve(heights_.size());
    outHeights.push_back(heights_[0]);
  }
  using Pending = KdTreeBuilder::PendingPair;  // a pair of nodes_ and the `out` node pointing at it
  std::vector<Pending>& waiting = b.pending;
  waiting.clear();
  waiting.push_back({root.payload(), 0});
  uint32_t treelet[kTreeletPairs];
  uint32_t parents[kTreeletPairs];
  while (!waiting.empty()) {
    const Pending start = waiting.back();
    waiting.pop_back();
    // Breadth-first gather of up to kTreeletPairs pairs under start.oldPair.
    uint32_t count = 0;
    treelet[count] = start.oldPair;
    parents[count++] = start.parent;
    const size_t frontierBegin = waiting.size();
    for (uint32_t i = 0; i < count; ++i) {
      const uint32_t base = uint32_t(out.size());
      out.push_back(nodes_[treelet[i]]);
      out.push_back(nodes_[treelet[i] + 1]);
      if (heights) {
        outHeights.push_back(heights_[treelet[i]]);
        outHeights.push_back(heights_[treelet[i] + 1]);
      }
      out[parents[i]].bits = (base << 2) | out[parents[i]].axis();
      for (uint32_t k = 0; k < 2; ++k) {
        const KdNode& n = out[base + k];
        if (n.axis() == KdNode::kLeafAxis) continue;
        if (count < kTreeletPairs) {
          treelet[count] = n.payload();
          parents[count++] = base + k;
        } else {
          waiting.push_back({n.payload(), base + k});
        }
      }
    }
    // Visit this treelet's frontier in order (left first) next: reverse the pushed range.
    std::reverse(waiting.begin() + std::ptrdiff_t(frontierBegin), waiting.end());
  }
  nodes_.swap(out);  // out was reserved to the exact size: no slack is kept
  if (heights) heights_.swap(outHeights);
}

uint32_t LooseKdTree::buildNode(uint32_t node, uint32_t begin, uint32_t end, const Aabb& bounds,
                                const double (&midSum)[3], KdTreeBuilder& b, uint32_t depth) {
  const uint32_t count = end - begin;
  Record* rec = b.records.data();
  if (heightAxis_ >= 0) {
    b.heightLo[node] = bounds.min[heightAxis_];
    b.heightHi[node] = bounds.max[heightAxis_];
  }
  if (count <= 2) {
    nodes_[node] = {rec[begin].id, count == 2 ? rec[begin + 1].id : 0u, (count << 2) | KdNode::kLeafAxis};
    return depth;
  }
  const int axis = longestAxis(bounds);
  const float mean2 = float(midSum[axis] / double(count));  // twice the mean midpoint
  // Partition by midpoint against the mean, collecting both sides' bounds in the same pass.
  SideStats left, right;
  uint32_t lo = begin, hi = end;
  while (lo < hi) {
    const Record& r = rec[lo];
    if (r.min[axis] + r.max[axis] < mean2) {
      left.add(r);
      ++lo;
    } else {
      --hi;
      right.add(r);
      std::swap(rec[lo], rec[hi]);
    }
  }
  uint32_t mid = lo;
  if ((mid - begin) * 4 < count || (end - mid) * 4 < count) {
    // Too skewed (or all midpoints equal): split at the median midpoint instead.
    mid = begin + count / 2;
    std::nth_element(rec + begin, rec + mid, rec + end, [axis](const Record& x, const Record& y) {
      return x.min[axis] + x.max[axis] < y.min[axis] + y.max[axis];
    });
    left = {};
    right = {};
    for (uint32_t i = begin; i < mid; ++i) left.add(rec[i]);
    for (uint32_t i = mid; i < end; ++i) right.add(rec[i]);
  }
  const uint32_t child = uint32_t(nodes_.size());
  nodes_.resize(nodes_.size() + 2);
  // Planes from all vertices of each side: tight, and possibly overlapping (loose).
  nodes_[node] = {std::bit_cast<uint32_t>(left.bounds.max[axis]), std::bit_cast<uint32_t>(right.bounds.min[axis]),
                  (child << 2) | uint32_t(axis)};
  if (depth >= kMaxDepth) throw CapacityExceeded("LooseKdTree::build: depth bound exceeded");
  const uint32_t dl = buildNode(child, begin, mid, left.bounds, left.midSum, b, depth + 1);
  const uint32_t dr = buildNode(child + 1, mid, end, right.bounds, right.midSum, b, depth + 1);
  return std::max(dl, dr);
}

namespace {

/// Vertex fetch of a float mesh.
struct FloatVertices {
  const Vec3f* v;
  Vec3f operator()(uint32_t i) const { return v[i]; }
};
/// Vertex fetch of a lattice mesh.
struct LatticeVertices {
  const LatticePoint* p;
  float s;
  Vec3f operator()(uint32_t i) const { return Vec3f(float(p[i].x) * s, float(p[i].y) * s, float(p[i].z) * s); }
};

}  // namespace

template <bool kCount>
bool LooseKdTree::raycastDispatch(const TriangleMeshView& m, const Ray& ray, KdRayHit& hit, uint32_t* visited) const {
  // One instantiation per index width and vertex format: no per-vertex branches in the loop.
  if (m.lattice) {
    const LatticeVertices v{m.lattice, m.latticeScale};
    return m.indices16 ? raycastImpl<kCount>(v, m.indices16, ray, hit, visited) : raycastImpl<kCount>(v, m.indices32, ray, hit, visited);
  }
  const FloatVertices v{m.vertices};
  return m.indices16 ? raycastImpl<kCount>(v, m.indices16, ray, hit, visited) : raycastImpl<kCount>(v, m.indices32, ray, hit, visited);
}

bool LooseKdTree::raycastClosest(const TriangleMeshView& mesh, const Ray& ray, KdRayHit& hit) const {
  return raycastDispatch<false>(mesh, ray, hit, nullptr);
}

bool LooseKdTree::raycastClosestCounted(const TriangleMeshView& mesh, const Ray& ray, KdRayHit& hit,
                                        uint32_t& nodesVisited) const {
  nodesVisited = 0;
  return raycastDispatch<true>(mesh, ray, hit, &nodesVisited);
}

template <bool kCount, class Vertices, class Index>
bool LooseKdTree::raycastImpl(const Vertices& vertices, const Index* indices, const Ray& ray, KdRayHit& hit,
                              uint32_t* nodesVisited) const {
  if (nodes_.empty()) return false;
  // Float robustness: every plane is pushed outwards by `pad` before it is intersected, so
  // rounding in (plane - origin) * invDir can only widen a segment, never drop a triangle the
  // ray touches (grazing hits on a plane included). The rounding of that product is a few ulps
  // of the largest coordinate involved, hence the pad scales with the origin and the bounds.
  const float scale = std::max({bounds_.min.cwiseAbs().maxCoeff(), bounds_.max.cwiseAbs().maxCoeff(),
                                ray.origin.cwiseAbs().maxCoeff()});
  const float pad = scale * (1.0f / 65536.0f);
  float tMin = 0.f, tMax = ray.maxT;
  for (int i = 0; i < 3; ++i) {
    const float lo = bounds_.min[i] - pad, hi = bounds_.max[i] + pad;
    if (ray.parallelMask & (1u << i)) {
      if (ray.origin[i] < lo || ray.origin[i] > hi) return false;
      continue;
    }
    float a = (lo - ray.origin[i]) * ray.invDir[i];
    float c = (hi - ray.origin[i]) * ray.invDir[i];
    if (a > c) std::swap(a, c);
    tMin = std::max(tMin, a);
    tMax = std::min(tMax, c);
  }
  if (!(tMin <= tMax)) return false;

  const WatertightRay wr = WatertightRay::make(ray.origin, ray.dir);
  const KdNode* nodes = nodes_.data();
  // Height bounds (wide meshes): the segment is clipped to each node's range on that axis.
  const KdHeightBounds* heights = heights_.empty() ? nullptr : heights_.data();
  const int ha = heightAxis_;
  const bool hParallel = ha >= 0 && (ray.parallelMask & (1u << ha));
  const float hOrigin = ha >= 0 ? ray.origin[ha] : 0.f, hInv = ha >= 0 ? ray.invDir[ha] : 0.f;
  RaySegment stack[kMaxDepth + 1];
  uint32_t sp = 0;
  RaySegment s{0, tMin, tMax};
  float best = ray.maxT;
  bool found = false;
  for (;;) {
    // note: the near child is followed directly and only the far one is pushed, so a descent
    // costs no stack traffic; popped segments starting beyond the best hit are skipped (early exit).
    const KdNode n = nodes[s.node];
    if constexpr (kCount) ++*nodesVisited;
    const uint32_t axis = n.axis();
    bool inRange = true;
    if (heights) {
      const KdHeightBounds hb = heights[s.node];
      const float lo = heightOf(hb.lo) - pad, hi = heightOf(hb.hi) + pad;
      if (hParallel) {
        inRange = hOrigin >= lo && hOrigin <= hi;
      } else {
        float ta = (lo - hOrigin) * hInv, tb = (hi - hOrigin) * hInv;
        if (ta > tb) std::swap(ta, tb);
        s.tMin = std::max(s.tMin, ta);
        s.tMax = std::min(s.tMax, tb);
        inRange = s.tMin <= s.tMax && s.tMin <= best;
      }
    }
    if (!inRange) {
      // The ray passes above or below everything in this subtree: on to the next segment.
    } else if (axis == KdNode::kLeafAxis) {
      const uint32_t tris[2] = {n.word0, n.word1};
      for (uint32_t i = 0; i < n.payload(); ++i) {
        const Index* tri = indices + 3 * size_t(tris[i]);
        float t;
        if (wr.intersect(vertices(tri[0]), vertices(tri[1]), vertices(tri[2]), 0.f, best, t) && (!found || t < best)) {
          best = t;
          hit = {t, tris[i]};
          found = true;
        }
      }
    } else {
      const uint32_t child = n.payload();
      const float leftPlane = splitOf(n.word0) + pad;   // left child lies at or below this
      const float rightPlane = splitOf(n.word1) - pad;  // right child lies at or above this
      const float o = ray.origin[axis];
      bool goNear, goFar;
      RaySegment nearSeg, farSeg;
      if (ray.parallelMask & (1u << axis)) {
        // The ray never crosses the planes: each child is either fully in reach or never.
        goNear = o <= leftPlane;
        goFar = o >= rightPlane;
        nearSeg = {child, s.tMin, s.tMax};
        farSeg = {child + 1, s.tMin, s.tMax};
      } else {
        const float inv = ray.invDir[axis];
        const float tl = (leftPlane - o) * inv;
        const float tr = (rightPlane - o) * inv;
        if (inv > 0.f) {
          // Moving up the axis: inside the left child for t <= tl, the right child for t >= tr.
          goNear = tl >= s.tMin;
          goFar = tr <= s.tMax;
          nearSeg = {child, s.tMin, std::min(tl, s.tMax)};
          farSeg = {child + 1, std::max(tr, s.tMin), s.tMax};
        } else {
          // Moving down: inside the right child for t <= tr, the left child for t >= tl.
          goNear = tr >= s.tMin;
          goFar = tl <= s.tMax;
          nearSeg = {child + 1, s.tMin, std::min(tr, s.tMax)};
          farSeg = {child, std::max(tl, s.tMin), s.tMax};
        }
      }
      if (goNear) {
        if (goFar) stack[sp++] = farSeg;
        s = nearSeg;
        continue;
      }
      if (goFar) {
        s = farSeg;
        continue;
      }
    }
    // Pop the next segment that can still beat the best hit.
    do {
      if (sp == 0) return found;
      s = stack[--sp];
    } while (s.tMin > best);
  }
}

std::string LooseKdTree::validate(const TriangleMeshView& mesh) const {
  std::ostringstream err;
  if (mesh.triangleCount == 0) return nodes_.empty() ? "" : "nodes in a tree over no triangles";
  std::vector<uint8_t> seen(mesh.triangleCount, 0);
  struct Item {
    uint32_t node, depth;
    float lo[3], hi[3];  // constraints inherited from ancestors' planes
  };
  std::vector<Item> walk;
  Item root{0, 1, {}, {}};
  for (int i = 0; i < 3; ++i) {
    root.lo[i] = bounds_.min[i];
    root.hi[i] = bounds_.max[i];
  }
  walk.push_back(root);
  uint32_t maxDepth = 0;
  while (!walk.empty()) {
    Item it = walk.back();
    walk.pop_back();
    if (it.node >= nodes_.size()) return "node index out of range";
    maxDepth = std::max(maxDepth, it.depth);
    const KdNode& n = nodes_[it.node];
    if (heightAxis_ >= 0) {
      // The subtree's triangles must lie within its height bounds too.
      if (heights_.size() != nodes_.size()) return "height bounds not one per node";
      it.lo[heightAxis_] = std::max(it.lo[heightAxis_], heightOf(heights_[it.node].lo));
      it.hi[heightAxis_] = std::min(it.hi[heightAxis_], heightOf(heights_[it.node].hi));
    }
    if (n.axis() == KdNode::kLeafAxis) {
      if (n.payload() > 2 || n.payload() == 0) return "leaf with a bad triangle count";
      const uint32_t tris[2] = {n.word0, n.word1};
      for (uint32_t k = 0; k < n.payload(); ++k) {
        if (tris[k] >= mesh.triangleCount || seen[tris[k]]++) {
          err << "triangle " << tris[k] << " out of range or in two leaves";
          return err.str();
        }
        Vec3f c[3];
        mesh.corners(tris[k], c[0], c[1], c[2]);
        for (const Vec3f& p : c) {
          for (int i = 0; i < 3; ++i) {
            if (p[i] < it.lo[i] || p[i] > it.hi[i]) {
              err << "triangle " << tris[k] << " outside its ancestors' planes";
              return err.str();
            }
          }
        }
      }
      continue;
    }
    const uint32_t child = n.payload();
    if (child + 1 >= nodes_.size() || child <= it.node) return "child index not after its parent";
    Item l = it, r = it;
    l.node = child;
    r.node = child + 1;
    l.depth = r.depth = it.depth + 1;
    l.hi[n.axis()] = std::min(l.hi[n.axis()], splitOf(n.word0));
    r.lo[n.axis()] = std::max(r.lo[n.axis()], splitOf(n.word1));
    walk.push_back(l);
    walk.push_back(r);
  }
  for (uint32_t t = 0; t < mesh.triangleCount; ++t) {
    if (!seen[t]) {
      err << "triangle " << t << " in no leaf";
      return err.str();
    }
  }
  if (maxDepth != depth_) return "stored depth differs from the walked depth";
  return "";
}

}  // namespace bw
