#pragma once
/// OctoBVH (article 000): a loose octree whose nodes store tight bounds, with forced splits of
/// overfilled nodes, filter bits and a canonical structure.
///
///   bw::OctoBvh tree;
///   uint32_t h = tree.insert(brickBounds, /*filter*/ 1, /*payload*/ brickIndex);
///   tree.overlap(queryBox, mask, [&](uint32_t element) { ... });
///   bw::RayHit hit = tree.raycastClosest(bw::Ray::make(origin, dir, 200.f), mask);
///   tree.remove(h);
///
/// Structure (a pure function of the element set, whatever the order of edits):
/// - An element's min level is the smallest L with 2^L >= its largest extent; it is placed by
///   its centre. The root is the cube [-2^R, 2^R)^3 with the smallest R holding every centre
///   and every min level; below it every node is a lattice cube [k 2^L, (k+1) 2^L).
/// - A node whose subtree holds <= 8 elements is a leaf holding them all. Otherwise elements
///   that fit a child (min level < L) go to the child holding their centre and the rest stay;
///   if more than 8 would stay, all of them are forced down by centre: into the children when
///   nothing fits a child, else into a second cluster of 8 octant nodes, the node's forced
///   cluster, beside its children. Giants forced down among small bricks would stretch the
///   small bricks' tight bounds to their own size, so every query near a giant would walk the
///   small bricks' subtrees (the dense build of issue 20: 3x the box tests); apart, the
///   children's bounds stay tight and a forced cluster holds only giants.
/// - Recursion stops at level kMinLevel, where a leaf may hold more than 8.
/// Inserts and removes re-evaluate these rules only along the path they touch; tight bounds,
/// filter ORs and counts are kept up to date incrementally.
///
/// Thread safety: queries are const and may run concurrently; edits need exclusive access.
/// Errors: bad input (NaN, inf, inverted bounds, |coordinate| > 2^30, unknown handle) throws
/// InvalidInput and a full pool throws CapacityExceeded, both before anything is modified.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "collision/core/assert.h"
#include "collision/core/obb.h"
#include "collision/core/overwrite_vector.h"
#include "collision/core/ray.h"
#include "collision/core/virtual_pool.h"
#include "collision/index/octobvh_layout.h"
#include "collision/index/spatial_query_types.h"

namespace bw {

class OctoBvh {
 public:
  struct Config {
    uint32_t maxElements = 1u << 22;  ///< reservation size (virtual; costs nothing until used)
  };
  /// Memory use by kind (live pool slots, not virtual reservations).
  struct MemoryStats {
    uint64_t clusters = 0, nodes = 0, nonEmptyNodes = 0, leafBlocks = 0, overflowBlocks = 0, elements = 0;
    uint64_t nodeBytes = 0, leafBytes = 0, elementBytes = 0;
    uint64_t totalBytes() const { return nodeBytes + leafBytes + elementBytes; }
  };
  /// Shape figures of the tree.
  struct ShapeStats {
    int depth = 0;                   ///< levels from the root to the deepest node
    uint64_t leaves = 0;             ///< non-empty nodes without children
    uint64_t innerNodes = 0;         ///< nodes with children
    uint64_t forcedNodes = 0;        ///< inner nodes that force-split
    uint64_t forcedClusters = 0;     ///< of those, nodes whose forced elements sit in a forced cluster
    uint64_t forcedElements = 0;     ///< elements sitting below their min level
  };

  OctoBvh() : OctoBvh(Config{}) {}
  explicit OctoBvh(Config config);

  // ---- edits ----
  /// Adds an element; returns its stable handle.
  uint32_t insert(const Aabb& bounds, uint32_t filter, uint32_t payload);
  /// Removes an element by handle.
  void remove(uint32_t handle);
  /// Removes many elements at once (live, distinct handles; InvalidInput otherwise, before
  /// anything changes): the same tree as removing them one by one, in one walk down their
  /// paths that frees whole subtrees and refits each node once.
  void removeMany(std::span<const uint32_t> handles);
  /// Moves/resizes an element and changes its filter bits; the handle stays.
  void update(uint32_t handle, const Aabb& bounds, uint32_t filter);
  /// Builds the tree of the given elements in one pass (same structure as inserting them one
  /// by one). The tree must be empty. Returns the handles in input order.
  std::vector<uint32_t> bulkLoad(std::span<const Aabb> bounds, std::span<const uint32_t> filters,
                                 std::span<const uint32_t> payloads);
  /// bulkLoad of bounds that already passed an OctoBvh's checks (read back from a tree: a grid's
  /// part moving to a grid of its own), so they are not checked box by box again.
  std::vector<uint32_t> bulkLoadValid(std::span<const Aabb> bounds, std::span<const uint32_t> filters,
                                      std::span<const uint32_t> payloads);
  /// Removes every element.
  void clear();

  // ---- element access ----
  /// Live elements.
  uint32_t size() const { return elements_.size(); }
  bool empty() const { return elements_.size() == 0; }
  /// Whether `handle` names a live element (any value may be asked).
  bool contains(uint32_t handle) const { return elements_.isLive(handle); }
  /// A live element's bounds, filter bits and payload, as inserted or last updated.
  /// Precondition: contains(handle) (checked by BW_ASSERT in debug and sanitizer builds; a dead
  /// handle's slot holds whatever the pool left there).
  Aabb bounds(uint32_t handle) const {
    BW_ASSERT(contains(handle));
    return elements_[handle].bounds();
  }
  uint32_t filter(uint32_t handle) const {
    BW_ASSERT(contains(handle));
    return elements_[handle].filter;
  }
  uint32_t payload(uint32_t handle) const {
    BW_ASSERT(contains(handle));
    return elements_[handle].payload;
  }
  /// Asks the cache for a live element's record ahead of bounds()/filter()/payload() (a caller
  /// walking thousands of handles in a random order).
  void prefetchElement(uint32_t handle) const { __builtin_prefetch(&elements_[handle]); }
  /// Asks the cache for what removing or updating these elements will read: their records, the
  /// clusters on their paths from the root, their holders' lists and the records on them. A
  /// lone edit's walk is a chain of ~12 dependent misses; these walks go in lockstep, so their
  /// misses overlap. Read-only: the edits that follow leave the same tree. For a loop editing
  /// many elements one by one: call it on the next kPrefetchGroup before editing them (more
  /// than that may be evicted before use). Dead handles are skipped. Returns how many walks
  /// found their element at the node they ended at: every live handle's (a check for tests).
  size_t prefetchPaths(std::span<const uint32_t> handles) const;
  /// The same for inserting elements of these bounds: the clusters on the paths they will take
  /// and the lists at their ends (a leaf that splits reads every record on it). Boxes that are
  /// not valid elements, or would grow the root, are skipped.
  void prefetchInsertPaths(std::span<const Aabb> bounds) const;
  static constexpr size_t kPrefetchGroup = 32;
  /// Tight bounds of everything (empty box when the tree is empty).
  Aabb rootBounds() const { return clusters_[rootCluster_].bounds(0); }
  /// Level of the root cube: it spans [-2^(level-1), 2^(level-1)).
  int rootLevel() const { return rootLevel_; }
  /// Calls f(handle) for every element in handle order.
  template <class F>
  void forEachElement(F&& f) const { elements_.forEachLive(std::forward<F>(f)); }

  // ---- queries (all take a filter mask: an element matches when filter & mask != 0) ----
  /// f(handle) for every element overlapping box whose exact(handle, elementBounds) is true.
  template <class F, class Exact = AabbOverlapExact>
  void overlap(const Aabb& box, uint32_t mask, F&& f, QueryStats* stats = nullptr, Exact&& exact = {}) const;
  /// Collecting form: appends handles to out.
  void overlap(const Aabb& box, uint32_t mask, std::vector<uint32_t>& out, QueryStats* stats = nullptr) const;
  /// Oriented-box overlap (separating-axis test against node and element bounds).
  template <class F, class Exact = AabbOverlapExact>
  void overlap(const Obb& box, uint32_t mask, F&& f, QueryStats* stats = nullptr, Exact&& exact = {}) const;
  void overlap(const Obb& box, uint32_t mask, std::vector<uint32_t>& out, QueryStats* stats = nullptr) const;
  /// Collision LOD: a subtree whose bounds' largest extent is below lodFraction times the query
  /// box's largest extent is reported once through onLod as a solid box instead of descending.
  template <class F, class L>
  void overlapLod(const Aabb& box, uint32_t mask, float lodFraction, F&& onElement, L&& onLod,
                  QueryStats* stats = nullptr) const;

  /// Closest hit along the ray within [0, ray.maxT]; exact(handle, tEnterBox, tMax, tHit).
  /// Of several hits at the same t, the first the traversal meets (the same one for the same tree
  /// state): nodes entered at the best t are not opened to look for a lower handle.
  template <class Exact = AabbRayExact>
  RayHit raycastClosest(const Ray& ray, uint32_t mask, QueryStats* stats = nullptr, Exact&& exact = {},
                        RayChildOrder order = RayChildOrder::FrontToBack) const;
  /// Sweep of a shape whose bounds have the given half extents along the ray (t in ray units):
  /// traversal against bounds grown by the extents; exact(handle, tEnterGrownBox, tMax, tHit)
  /// gives the shape's real time of impact.
  template <class Exact>
  RayHit sweepClosest(const Ray& ray, const Vec3f& halfExtents, uint32_t mask, Exact&& exact,
                      QueryStats* stats = nullptr) const;
  /// Some hit (the first found), or none.
  template <class Exact = AabbRayExact>
  RayHit raycastAny(const Ray& ray, uint32_t mask, QueryStats* stats = nullptr, Exact&& exact = {}) const;
  /// Every hit within [0, ray.maxT], sorted by t then handle.
  template <class Exact = AabbRayExact>
  void raycastAll(const Ray& ray, uint32_t mask, std::vector<RayHit>& out, QueryStats* stats = nullptr,
                  Exact&& exact = {}) const;

  // ---- diagnostics ----
  /// Hash of the structure (node levels, counts, bounds, held elements by bounds/filter/payload):
  /// equal for equal element sets whatever the edit history; independent of handle values.
  uint64_t structureHash() const;
  /// Walks the whole tree and throws std::logic_error describing the first broken invariant
  /// (counts, tight bounds, filter ORs, min levels, canonical placement). For tests.
  void validate() const;
  MemoryStats memoryStats() const;
  ShapeStats shapeStats() const;
  size_t residentBytes() const;

  /// Child visiting order for a ray direction, computed once per ray (see octobvh_queries.h).
  static std::array<uint8_t, 8> rayChildOrder(const Vec3f& dir);

  // Read-only access to the layout, for tools that draw or inspect the tree.
  const octobvh::NodeCluster& cluster(uint32_t c) const { return clusters_[c]; }
  uint32_t rootCluster() const { return rootCluster_; }
  const octobvh::ElementRecord& element(uint32_t h) const { return elements_[h]; }
  /// f(handle) for each element held directly at node (cluster, slot).
  template <class F>
  void forEachHeldPublic(const octobvh::NodeCluster& cl, int s, F&& f) const { forEachHeld(cl, s, std::forward<F>(f)); }
  /// Asks for what node (cl, s) holds, ahead of a walk's visit: its single element's record, or
  /// its leaf block (at 1M most of an overlap query's time went to these misses).
  void prefetchHeld(const octobvh::NodeCluster& cl, int s) const {
    if (cl.numHeld[s] == 1) __builtin_prefetch(&elements_[cl.leaf[s]]);
    else if (cl.numHeld[s] > 1 && cl.numHeld[s] <= octobvh::kLeafCapacity) __builtin_prefetch(&leaves_[cl.leaf[s]]);
  }

 private:
  using NodeCluster = octobvh::NodeCluster;
  struct Cube {  // lattice cube of a node: origin (exact in double) and level
    double origin[3];
    int level;
    // note: inline, as every level of every edit calls both.
    int childSlotFor(const double c[3]) const {
      const double half = octobvh::pow2(level - 1);
      return (c[0] >= origin[0] + half ? 1 : 0) | (c[1] >= origin[1] + half ? 2 : 0) | (c[2] >= origin[2] + half ? 4 : 0);
    }
    Cube child(int slot) const {
      const double half = octobvh::pow2(level - 1);
      return {{origin[0] + ((slot & 1) ? half : 0.0), origin[1] + ((slot & 2) ? half : 0.0),
               origin[2] + ((slot & 4) ? half : 0.0)},
              level - 1};
    }
  };

  /// An element's centre on the finest lattice: in units of 2^kMinLevel from the root cube's
  /// low corner, so the child holding it below a node of level L is bit L-1-kMinLevel of each
  /// axis. Exact, as Cube::childSlotFor is: c >= k 2^L + 2^(L-1) is floor(c 2^-kMinLevel) >=
  /// (k 2^L + 2^(L-1)) 2^-kMinLevel, an integer for L > kMinLevel, and the scaling and floor
  /// are exact in double. Walks that leave the tree as it is use it instead of a Cube (three
  /// shifts a level, not double arithmetic); valid while the root level stays.
  struct Lattice {
    int64_t x[3];
    int slotBelow(int level) const {
      const int sh = level - 1 - octobvh::kMinLevel;
      return int((x[0] >> sh) & 1) | int((x[1] >> sh) & 1) << 1 | int((x[2] >> sh) & 1) << 2;
    }
  };
  Lattice latticeOf(const double c[3]) const {
    Lattice at;
    const int64_t corner = int64_t(1) << (rootLevel_ - 1 - octobvh::kMinLevel);
    for (int k = 0; k < 3; ++k) {
      const double v = c[k] * octobvh::pow2(-octobvh::kMinLevel);  // |v| < 2^41
      int64_t f = int64_t(v);  // toward zero, then down: floor without a libm call
      f -= double(f) > v ? 1 : 0;
      at.x[k] = f + corner;
    }
    return at;
  }
  /// The cube of the node of level `level` on the path of the lattice point `at`.
  Cube cubeAt(const Lattice& at, int level) const {
    const int sh = level - octobvh::kMinLevel;
    const double root = -octobvh::pow2(rootLevel_ - 1), unit = octobvh::pow2(octobvh::kMinLevel);
    Cube cube;
    for (int k = 0; k < 3; ++k) cube.origin[k] = root + double((at.x[k] >> sh) << sh) * unit;
    cube.level = level;
    return cube;
  }
  /// A prefetch walk (octobvh_prefetch.cpp): where it is, where it goes, whose path it is.
  struct PathWalk {
    Lattice at;
    uint32_t c;
    int s;
    int minLevel;
    uint32_t e;  ///< the element, or kInvalidIndex for an insert's path
  };
  size_t prefetchWalks(PathWalk* walks, size_t count) const;
  /// An element and where it goes, computed once per edit rather than at every level.
  struct Placement {
    uint32_t e;
    int minLevel;
    double ctr[3];
  };
  Placement placementOf(uint32_t e) const {
    Placement p{e, octobvh::minLevelOf(elements_[e]), {}};
    octobvh::centreOf(elements_[e], p.ctr);
    return p;
  }
  void validateElement(const Aabb& b, const char* context) const;
  void reserveHeadroom(const char* context) const;
  Cube rootCube() const {
    const double o = -octobvh::pow2(rootLevel_ - 1);
    return {{o, o, o}, rootLevel_};
  }
  void growRootToHold(const double centre[3], int minLevel);
  /// Whether element e keeps the root from shrinking (its centre outside the half-size root
  /// cube or its min level too large for it): only removing such an element can let it shrink.
  bool holdsRootUp(const Placement& p) const;
  void shrinkRoot();
  int canonicalRootLevel(const std::vector<uint32_t>& elems) const;

  void insertAt(uint32_t c, int s, Cube cube, const Placement& p);
  void removeAt(uint32_t c, int s, Cube cube, const Placement& p);
  void passDown(uint32_t sub, const Cube& cube, const Placement& p);
  bool updateInPlace(const Placement& old, const Placement& p, const octobvh::ElementRecord& moved);
  /// The cluster an element of min level `minLevel` lives in below inner node (cl, s) of level
  /// `level` (the children, or the node's forced cluster), or kInvalidIndex when the node holds
  /// it: the placement rules, for walks that leave the structure as it is on the way down.
  uint32_t clusterBelow(const NodeCluster& cl, int s, int level, int minLevel) const {
    if (minLevel < level) return cl.child[s];
    if (cl.numHeld[s] == octobvh::kForcedCluster) return cl.leaf[s];
    return clusters_[cl.child[s]].forcedCount > 0 ? cl.child[s] : kInvalidIndex;
  }
  void mergeIntoLeaf(uint32_t c, int s, uint32_t removed);
  /// Frees everything at and below node (c, s) and makes it a leaf holding `rest` (not refitted).
  void replaceWithLeaf(uint32_t c, int s, const std::vector<uint32_t>& rest);
  /// An element as a build sorts it: its centre and min level, computed once.
  struct BuildItem {
    double ctr[3];
    uint32_t e;
    int8_t minLevel;
    uint8_t slot;  ///< the child cube holding the centre, at the level being partitioned
  };
  /// The canonical subtree of the given elements at the (empty) node (c, s).
  void buildFrom(uint32_t c, int s, const Cube& cube, const uint32_t* elems, uint32_t count);
  static void buildItemOf(const octobvh::ElementRecord& r, uint32_t e, BuildItem& it);
  /// The element handle a build holds at a node: the item's own, or during bulkLoad the record
  /// written now (see bulk_).
  uint32_t placeBuilt(uint32_t e);
  void build(uint32_t c, int s, const Cube& cube, BuildItem* items, uint32_t count);
  /// A leaf at the (empty) node (c, s) holding the items, in their order.
  void buildLeaf(uint32_t c, int s, const BuildItem* items, uint32_t count);
  /// bulkLoad's build (octobvh_sorted_build.cpp): build()'s tree from its inputs sorted once by
  /// their paths (sortForBuild, with rootLevel_ set), node (c, s) at `depth` below the root.
  /// Only during bulkLoad (bulk_ set): an item is an input position.
  struct SortedItem {
    uint64_t key;   ///< the item's path and natural depth (sortedBuildKey)
    uint32_t item;  ///< its input position
  };
  uint64_t sortedBuildKey(const BuildItem& it) const;
  /// The inputs' keys, sorted (by key, then position).
  OverwriteVector<SortedItem> sortForBuild(std::span<const Aabb> bounds) const;
  void buildSorted(uint32_t c, int s, const Cube& cube, int depth, const SortedItem* sorted, uint32_t count);
  void buildOctantsSorted(uint32_t sub, const Cube& cube, int depth, const SortedItem* sorted, uint32_t count);
  /// build()'s subtree of a run of sorted items (where keys cannot order them further).
  void buildRunUnsorted(uint32_t c, int s, const Cube& cube, const SortedItem* sorted, uint32_t count, bool octants);
  void buildOctants(uint32_t sub, const Cube& cube, BuildItem* items, uint32_t count);
  /// Sorts the items by the child cube of `cube` holding their centres (counts and starts per
  /// octant), in place; the order within an octant is the build's (leaves keep it).
  static void partitionByOctant(const Cube& cube, BuildItem* items, uint32_t n, uint32_t start[8], uint32_t counts[8]);
  void removeManyAt(uint32_t c, int s, const Cube& cube, BuildItem* items, uint32_t k);
  /// Frees a big build's items (32 B per element built) once done; small ones (a leaf split on
  /// insert) keep theirs, so edits do not allocate.
  void releaseBuildScratch();
  void gatherSubtree(uint32_t c, int s, std::vector<uint32_t>& out) const;
  void freeSubtreeClusters(uint32_t cluster);
  /// What refit computes for a node: its tight bounds, filter bits and largest min level.
  struct NodeSummary {
    float lo[3], hi[3];
    uint32_t filter;
    int8_t maxMinLevel;
  };
  /// Recomputes node (c, s)'s summary from what it holds and its sub clusters' nodes; says
  /// whether it changed, and gives the one it had in `before` when asked.
  bool refit(uint32_t c, int s, NodeSummary* before = nullptr);
  NodeSummary summaryOf(uint32_t c, int s) const {
    const octobvh::NodeCluster& cl = clusters_[c];
    return {{cl.minX[s], cl.minY[s], cl.minZ[s]}, {cl.maxX[s], cl.maxY[s], cl.maxZ[s]}, cl.filter[s], cl.maxMinLevel[s]};
  }
  /// Whether node (c, s)'s summary stays as it is when one node it merges (a node of its child
  /// or forced cluster) changed from `before` to `after`: each face, the filter and the min level
  /// either did not move, or were not the node's own extreme and did not pass it. Then refitting
  /// it (reading its 8 or 16 lanes) would change nothing, and nothing above it changes either.
  bool summaryStays(uint32_t c, int s, const NodeSummary& before, const NodeSummary& after) const;
  void clearNode(uint32_t c, int s);
  uint32_t allocCluster(int level);

  // held-element lists (leaf blocks, or overflow chains at kMinLevel)
  uint32_t heldCount(uint32_t c, int s) const {
    const NodeCluster& cl = clusters_[c];
    if (cl.numHeld[s] == octobvh::kForcedCluster) return 0;
    return cl.numHeld[s] == octobvh::kOverflow ? overflow_[cl.leaf[s]].count : cl.numHeld[s];
  }
  /// Elements in the node's subtree: held, in its children and in its forced cluster.
  uint32_t subtreeCount(uint32_t c, int s) const {
    uint32_t n = heldCount(c, s);
    clusters_[c].forEachSubCluster(s, [&](uint32_t sub) { n += clusters_[sub].childTotal; });
    return n;
  }
  void heldAdd(uint32_t c, int s, uint32_t e);
  void heldRemove(uint32_t c, int s, uint32_t e);
  bool heldRemoveChanges(uint32_t c, int s, const Placement& p);
  void heldTake(uint32_t c, int s, std::vector<uint32_t>& out);
  /// Empties the node's held list, freeing its blocks (the elements stay in the pool).
  void heldDrop(uint32_t c, int s);
  template <class F>
  void forEachHeld(const NodeCluster& cl, int s, F&& f) const;
  template <class OnElement, class Accept>
  void walkOverlap(const Aabb& outer, uint32_t mask, QueryStats* stats, OnElement&& onElement, Accept&& accept) const;

  uint64_t hashNode(uint32_t c, int s) const;
  void validateNode(uint32_t c, int s, const Cube& cube, std::vector<uint32_t>& seen) const;
  void shapeNode(uint32_t c, int s, int depth, ShapeStats& st) const;

  Config config_;
  VirtualPool<octobvh::ElementRecord> elements_;
  VirtualPool<NodeCluster> clusters_;
  VirtualPool<octobvh::LeafBlock> leaves_;
  VirtualPool<octobvh::OverflowBlock> overflow_;
  uint32_t rootCluster_ = kInvalidIndex;  ///< slot 0 is the root node
  int rootLevel_ = octobvh::kMinLevel + 1;
  std::vector<uint32_t> mergeScratch_;  ///< mergeIntoLeaf's (edits are exclusive): no allocation per merge
  std::vector<BuildItem> buildScratch_; ///< buildFrom's and removeMany's items (kept when small)
  std::vector<BuildItem> runScratch_;   ///< buildRunUnsorted's copy of a run's items
  const uint8_t* removing_ = nullptr;   ///< during removeMany: by handle, 1 for those it takes
  /// During bulkLoad: the build's items name input positions, and each element's record is
  /// allocated and written from the input when the build places it at its node.
  struct BulkInput {
    const Aabb* bounds;
    const uint32_t* filters;
    const uint32_t* payloads;
    uint32_t* handles;  ///< handles[input] = its element's handle
    const uint32_t* fresh;  ///< the handles allocated for the build, taken in placement order
    uint32_t placed;        ///< how many of them are taken
  };
  std::vector<uint32_t> bulkLoadCheckingBounds(std::span<const Aabb> bounds, std::span<const uint32_t> filters,
                                        std::span<const uint32_t> payloads, bool checkBounds);
  BulkInput* bulk_ = nullptr;
};

}  // namespace bw

#include "collision/index/octobvh_queries.h"
