#pragma once
/// A dynamic bounding-volume tree over world boxes (double, per the precision rule): binary,
/// one proxy per leaf, nodes in one array linked by index, a free list threaded through the
/// freed nodes' `parent`. It holds the broadphase's moving proxies (their fattened boxes), which
/// change a few at a time, where StaticBoundsTree holds the static ones, built once.
///
///   DynamicBoundsTree tree;
///   uint32_t leaf = tree.insert(box, id);
///   tree.move(leaf, newBox);                          // remove and insert, same leaf index
///   tree.query(q, [&](uint32_t id) { ... });          // ids of leaves overlapping q
///   tree.build(boxes, ids, leafOf, &jobs);            // or all at once, in bulk
///
/// Insertion descends by the surface-area heuristic (into the child whose growth costs least,
/// stopping where a new parent for the node costs less than going down) and rebalances every
/// ancestor by rotations (a node whose children's heights differ by more than one lifts the
/// taller), which keeps the height near logarithmic under any order of edits. build() makes a
/// tree in bulk as a linear BVH does: the items sorted by the Morton code of their centres on a
/// 2^21 lattice (ties by item), each range split where its first and last codes first differ
/// (an octree cell boundary), in O(n) after the sort. A range of k leaves owns k - 1 inner nodes
/// at an index fixed by the leaf counts, so its subtree is built by one job that never
/// allocates; the tree does not depend on the thread count. (Median splits on the longest axis,
/// tried first, cost over 2x more at 1M: nth_element moves every item at every level.)
/// Determinism: the structure depends only on the sequence of calls.
/// Thread safety: query() is const and may run on any number of threads; edits alone.
#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "jobs/job_system.h"
#include "jobs/parallel_sort.h"
#include "jobs/profiler.h"
#include "world/broadphase.h"

namespace bw {

class DynamicBoundsTree {
 public:
  static constexpr uint32_t kNull = std::numeric_limits<uint32_t>::max();
  /// Profiler stages build() uses, from its `stage` argument on (centres' bounds, codes, their
  /// sort, leaves, top ranges, subtrees, top boxes).
  static constexpr int kBuildStages = 10;

  /// Adds a leaf for `box` with payload `id`; returns the leaf's node index (stable until it is
  /// removed).
  uint32_t insert(const WorldAabb& box, uint32_t id);
  /// Takes the leaf out and frees it.
  void remove(uint32_t leaf);
  /// Gives the leaf a new box (taken out and inserted again; the index stays).
  void move(uint32_t leaf, const WorldAabb& box);
  /// Gives the leaf a new box in place when at most `maxGrown` ancestors must grow to hold it
  /// (they grow, up to the first that already holds it, and never shrink: the tree stays
  /// correct but loosens a little); otherwise moves it as move() does. Returns the ancestors
  /// grown (0 after a move).
  uint32_t refit(uint32_t leaf, const WorldAabb& box, uint32_t maxGrown);
  /// Replaces the whole tree by one built in bulk over boxes[k] with payload ids[k];
  /// leafOf[k] becomes the leaf of item k. With jobs, the codes, their sort, the leaves and the
  /// subtrees are made in parallel (zones at stage .. stage + kBuildStages - 1 with a profiler).
  void build(const std::vector<WorldAabb>& boxes, const std::vector<uint32_t>& ids, std::vector<uint32_t>& leafOf,
             JobSystem* jobs = nullptr, Profiler* profiler = nullptr, int stage = -1);
  /// Removes every leaf.
  void clear();

  /// Leaves in the tree.
  uint32_t leafCount() const { return leaves_; }
  /// The root's height (a leaf's is 0; -1 when empty).
  int height() const { return root_ == kNull ? -1 : nodes_[root_].height; }
  /// A leaf's box and payload id.
  const WorldAabb& box(uint32_t leaf) const { return nodes_[leaf].box; }
  uint32_t id(uint32_t leaf) const { return nodes_[leaf].child2; }
  /// Every pair of leaves whose boxes overlap, as (smaller id, larger id), sorted: the tree
  /// against itself (each subtree against itself, then its two children against each other),
  /// which after a bulk build costs far less than one query per leaf. With `wanted` (indexed by
  /// id), only pairs with at least one wanted leaf. The top of the traversal is cut into tasks
  /// run as parallel jobs with their own lists, joined in task order. Returns the box tests made.
  uint64_t selfPairs(std::vector<BodyPair>& out, const uint8_t* wanted = nullptr, JobSystem* jobs = nullptr, Profiler* profiler = nullptr,
                     int stage = -1);
  /// Profiler stages selfPairs() uses (the traversal, the join, the sort's four).
  static constexpr int kSelfPairStages = 6;
  /// The ids of all leaves in node order: a bulk-built tree's leaves lie in the order of its
  /// splits (near in space, near in the list), and move() keeps a leaf's index, so queries made
  /// in this order walk the tree coherently.
  void leafIds(std::vector<uint32_t>& out) const;
  /// Checks every link, height, box (holding its children's) and the free list (tests); throws
  /// std::logic_error naming the node that is wrong.
  void validate() const;

  /// Calls f(id) for every leaf whose box overlaps `box` (closed intervals). Returns the box
  /// tests made.
  template <class F>
  uint64_t query(const WorldAabb& box, F&& f) const {
    if (root_ == kNull) return 0;
    // note: a depth-first walk holds at most height + 1 nodes.
    if (nodes_[root_].height < int(kStackDepth)) {
      std::array<uint32_t, kStackDepth> stack;
      return walk(box, f, stack.data());
    }
    std::vector<uint32_t> stack(size_t(nodes_[root_].height) + 1);
    return walk(box, f, stack.data());
  }

 private:
  static constexpr uint32_t kStackDepth = 96;

  template <class F>
  uint64_t walk(const WorldAabb& box, F& f, uint32_t* stack) const {
    uint32_t top = 0;
    uint64_t tests = 0;
    stack[top++] = root_;
    while (top > 0) {
      const Node& node = nodes_[stack[--top]];
      ++tests;
      if (!node.box.overlaps(box)) continue;
      if (node.child1 == kNull) {
        f(node.child2);
        continue;
      }
      stack[top++] = node.child2;
      stack[top++] = node.child1;
    }
    return tests;
  }
  /// Ranges up to this many leaves are built whole in one job (a few microseconds of work);
  /// the ranges above are split on the calling thread (a binary search each). 2048 left
  /// city_rain's 2,000 crates one job.
  static constexpr uint32_t kSubtreeLeaves = 256;

  struct Node {
    WorldAabb box;    // 48
    uint32_t parent;  // 4  kNull at the root; a free node's next free node
    uint32_t child1;  // 4  kNull for a leaf
    uint32_t child2;  // 4  a leaf's payload id
    int32_t height;   // 4  0 for a leaf, -1 for a free node
  };
  static_assert(sizeof(Node) == 64, "a node is one cache line");
  static const Node kFreeNode;  // zeroed box (Eigen leaves a default-constructed vector unset)

  // A range of build items [begin, end) to become the subtree at `node` under `parent`.
  struct Range {
    uint32_t begin, end, node, parent;
  };

  bool isLeaf(uint32_t n) const { return nodes_[n].child1 == kNull; }
  uint32_t allocate();
  void release(uint32_t n);
  void insertLeaf(uint32_t leaf);
  void removeLeaf(uint32_t leaf);
  void replaceChild(uint32_t parent, uint32_t from, uint32_t to);
  void fix(uint32_t n);  // box and height from the children
  void refitUpward(uint32_t n);
  uint32_t balance(uint32_t n);
  uint32_t rotateUp(uint32_t a, uint32_t up);

  // selfPairs(): a task is a subtree against itself (b == kNull) or two subtrees against each
  // other.
  struct Task {
    uint32_t a, b;
  };
  // Both return the box tests made.
  template <class Emit>
  uint64_t crossPairs(uint32_t a, uint32_t b, std::vector<Task>& stack, Emit& emit) const;
  template <class Emit>
  uint64_t selfTask(uint32_t n, std::vector<Task>& stack, Emit& emit) const;

  // Bulk build: the leaf node of build position p, a range's split into two, a whole subtree.
  uint32_t buildLeaf(uint32_t p) const { return buildCount_ - 1 + p; }
  void split(const Range& r, Range& left, Range& right);
  void buildSubtree(const Range& r);

  std::vector<Node> nodes_;
  uint32_t root_ = kNull;
  uint32_t free_ = kNull;
  uint32_t leaves_ = 0;

  // build()'s scratch: (Morton code, item) in build order, the centres' bounds per chunk, the
  // ranges of each level.
  std::vector<std::pair<uint64_t, uint32_t>> codes_;
  ParallelSorter<std::pair<uint64_t, uint32_t>> sorter_;
  std::vector<Vec3d> chunkLo_, chunkHi_;
  uint32_t buildCount_ = 0;
  std::vector<Range> level_, next_, whole_, top_;
  // selfPairs()'s scratch: the tasks, each task's pairs and stack.
  std::vector<Task> tasks_, nextTasks_;
  std::vector<std::vector<BodyPair>> taskPairs_;
  std::vector<std::vector<Task>> taskStacks_;
  std::vector<size_t> taskOffset_;
  std::vector<uint64_t> taskTests_;
  ParallelSorter<BodyPair> pairSorter_;
};

}  // namespace bw
