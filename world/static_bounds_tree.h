#pragma once
/// The broadphase's static proxies (static bodies, and the boxes covering large static grids)
/// in a bounding-volume tree built in bulk, queried by every moving proxy, in parallel.
///
/// Why a tree and not the sweep: a static box (a city's cover box is tens of metres long) in
/// the sweep's sorted list is swept past every moving body inside its extent on the sweep axis,
/// every frame, though static boxes never pair with each other; city_rain spent 40% of its
/// critical path there. Static proxies change only when a static grid is edited or a body
/// becomes static, so the tree is rebuilt then (O(s log s)) and only read in between.
///
/// Layout: binary nodes in one array (double bounds, per the precision rule), children of a
/// node next to each other, leaves of at most kLeafSize proxies; built by median split on the
/// longest axis of the node's centres.
/// Thread safety: query() is const and may run on any number of threads; build() alone.
#include <array>
#include <cstdint>
#include <vector>

#include "world/broadphase.h"

namespace bw {

class StaticBoundsTree {
 public:
  static constexpr uint32_t kLeafSize = 4;

  /// Builds over boxes[k] with payload ids[k] (same length).
  void build(const std::vector<WorldAabb>& boxes, const std::vector<uint32_t>& ids);
  bool empty() const { return nodes_.empty(); }
  uint32_t size() const { return uint32_t(items_.size()); }

  /// Calls f(id) for every proxy whose box overlaps `box` (closed intervals, as
  /// WorldAabb::overlaps), in tree order. Returns the box tests made.
  template <class F>
  uint64_t query(const WorldAabb& box, F&& f) const {
    if (nodes_.empty()) return 0;
    uint64_t tests = 0;
    std::array<uint32_t, 64> stack;  // depth <= log2(items / kLeafSize) + 1, far below 64
    uint32_t top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = nodes_[stack[--top]];
      ++tests;
      if (!node.box.overlaps(box)) continue;
      if (node.count > 0) {
        for (uint32_t k = node.first; k < node.first + node.count; ++k) {
          ++tests;
          if (items_[k].box.overlaps(box)) f(items_[k].id);
        }
        continue;
      }
      stack[top++] = node.first + 1;
      stack[top++] = node.first;
    }
    return tests;
  }

 private:
  struct Item {
    WorldAabb box;
    uint32_t id;
  };
  struct Node {
    WorldAabb box;
    uint32_t first;  // leaf: first item; inner: index of the left child (the right one follows)
    uint32_t count;  // items in a leaf, 0 for an inner node
  };
  // A node for split() to fill (zeroed: Eigen leaves a default-constructed vector unset).
  static Node emptyNode() { return {WorldAabb{Vec3d::Zero(), Vec3d::Zero()}, 0, 0}; }
  void split(uint32_t node, uint32_t begin, uint32_t end);

  std::vector<Item> items_;
  std::vector<Node> nodes_;
};

}  // namespace bw
