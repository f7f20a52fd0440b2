#pragma once
/// A plain loose octree: the baseline OctoBVH is measured against (article 000, "Loose
/// Octrees"). Same element and query API as OctoBvh and the same box-test counting.
///
/// Rules: lattice cubes like the OctoBVH's; an element lives in the deepest existing node whose
/// cube holds its centre and whose width is at least its largest extent; a node with more than
/// 8 elements splits and passes down the elements that fit a child; a subtree left with <= 8
/// elements merges back. Queries test each node's loose cube (the cube grown by half its width
/// on every side), never tight bounds, and there are no forced splits: a stack of large plates
/// stays in one node. Not canonical (the structure depends on edit order).
///
/// Thread safety: queries are const and may run concurrently; edits need exclusive access.
#include <array>
#include <cstdint>
#include <vector>

#include "collision/core/obb.h"
#include "collision/core/ray.h"
#include "collision/core/virtual_pool.h"
#include "collision/index/octobvh_layout.h"
#include "collision/index/spatial_query_types.h"

namespace bw {

class LooseOctree {
 public:
  struct Config {
    uint32_t maxElements = 1u << 22;  ///< reservation size
  };
  /// Eight sibling nodes. 20 bytes per node.
  struct Cluster {
    double origin[3];      // 24   origin of the parent's cube (children offset by half its width)
    uint32_t child[8];     // 56   cluster of each node's children, or kInvalidIndex
    uint32_t head[8];      // 88   first element held at each node (list through `next`)
    uint32_t held[8];      // 120  elements held at each node
    uint32_t subtree[8];   // 152  elements in each node's subtree
    int8_t level;          // 153  level of these nodes
    uint8_t pad[7];        // 160
  };
  static_assert(sizeof(Cluster) == 160);

  LooseOctree() : LooseOctree(Config{}) {}
  explicit LooseOctree(Config config);

  uint32_t insert(const Aabb& bounds, uint32_t filter, uint32_t payload);
  void remove(uint32_t handle);
  void update(uint32_t handle, const Aabb& bounds, uint32_t filter);

  uint32_t size() const { return elements_.size(); }
  bool empty() const { return elements_.size() == 0; }
  bool contains(uint32_t handle) const { return elements_.isLive(handle); }
  Aabb bounds(uint32_t handle) const { return elements_.get<0>(handle).bounds(); }
  uint32_t filter(uint32_t handle) const { return elements_.get<0>(handle).filter; }
  uint32_t payload(uint32_t handle) const { return elements_.get<0>(handle).payload; }
  /// Loose bounds of the root cube.
  Aabb rootBounds() const;
  template <class F>
  void forEachElement(F&& f) const { elements_.forEachLive(std::forward<F>(f)); }

  template <class F, class Exact = AabbOverlapExact>
  void overlap(const Aabb& box, uint32_t mask, F&& f, QueryStats* stats = nullptr, Exact&& exact = {}) const;
  void overlap(const Aabb& box, uint32_t mask, std::vector<uint32_t>& out, QueryStats* stats = nullptr) const;
  template <class F, class Exact = AabbOverlapExact>
  void overlap(const Obb& box, uint32_t mask, F&& f, QueryStats* stats = nullptr, Exact&& exact = {}) const;
  void overlap(const Obb& box, uint32_t mask, std::vector<uint32_t>& out, QueryStats* stats = nullptr) const;

  template <class Exact = AabbRayExact>
  RayHit raycastClosest(const Ray& ray, uint32_t mask, QueryStats* stats = nullptr, Exact&& exact = {},
                        RayChildOrder order = RayChildOrder::FrontToBack) const;
  template <class Exact = AabbRayExact>
  RayHit raycastAny(const Ray& ray, uint32_t mask, QueryStats* stats = nullptr, Exact&& exact = {}) const;
  template <class Exact = AabbRayExact>
  void raycastAll(const Ray& ray, uint32_t mask, std::vector<RayHit>& out, QueryStats* stats = nullptr,
                  Exact&& exact = {}) const;

  /// Throws std::logic_error on a broken invariant (placement, counts, list integrity).
  void validate() const;
  /// Bytes of live nodes, and of elements (records + list links).
  uint64_t nodeBytes() const { return uint64_t(clusters_.size()) * sizeof(Cluster); }
  uint64_t elementBytes() const { return uint64_t(elements_.size()) * (sizeof(octobvh::ElementRecord) + 4); }
  uint64_t nodeCount() const { return uint64_t(clusters_.size()) * 8; }

 private:
  Aabb looseBounds(const Cluster& cl, int s) const;
  void growRootToHold(const double centre[3], int minLevel);
  void insertAt(uint32_t c, int s, uint32_t e);
  void split(uint32_t c, int s);
  void detach(uint32_t handle);
  void freeSubtree(uint32_t cluster, std::vector<uint32_t>& elems);
  void pushHeld(uint32_t c, int s, uint32_t e);
  void validateNode(uint32_t c, int s, uint32_t& total) const;
  template <class F>
  void forEachHeld(const Cluster& cl, int s, F&& f) const {
    for (uint32_t e = cl.head[s]; e != kInvalidIndex; e = elements_.get<1>(e)) f(e);
  }
  template <class Hit, class OnElement>
  void walkOverlap(uint32_t mask, QueryStats* stats, Hit&& hit, OnElement&& onElement) const;
  template <class Hit>
  void traverseRay(const Ray& ray, uint32_t mask, const std::array<uint8_t, 8>& order, float& limit, bool& stop,
                   QueryStats* stats, Hit&& onElement) const;

  Config config_;
  ParallelVirtualPool<octobvh::ElementRecord, uint32_t> elements_;  // record, next in node list
  VirtualPool<Cluster> clusters_;
  uint32_t rootCluster_;  ///< slot 0 is the root node
  int rootLevel_ = octobvh::kMinLevel + 1;
};

}  // namespace bw

#include "collision/index/octobvh.h"
#include "collision/index/loose_octree_queries.h"
