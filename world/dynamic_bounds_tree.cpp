#include "world/dynamic_bounds_tree.h"

#include <algorithm>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>

#include "collision/core/errors.h"

namespace bw {

namespace {

WorldAabb merged(const WorldAabb& a, const WorldAabb& b) { return {a.min.cwiseMin(b.min), a.max.cwiseMax(b.max)}; }

// Half the surface area: the insertion heuristic's cost (only ratios and sums of it matter).
double halfArea(const WorldAabb& b) {
  const Vec3d d = b.max - b.min;
  return d.x() * d.y() + d.y() * d.z() + d.z() * d.x();
}

struct MaybeZone {
  std::optional<ProfileZone> zone;
  MaybeZone(Profiler* profiler, const char* name, int stage) {
    if (profiler) zone.emplace(*profiler, name, stage);
  }
};

}  // namespace

const DynamicBoundsTree::Node DynamicBoundsTree::kFreeNode{{Vec3d::Zero(), Vec3d::Zero()}, kNull, kNull, kNull, -1};

uint32_t DynamicBoundsTree::allocate() {
  if (free_ != kNull) {
    const uint32_t n = free_;
    free_ = nodes_[n].parent;
    return n;
  }
  nodes_.push_back(kFreeNode);
  return uint32_t(nodes_.size() - 1);
}

void DynamicBoundsTree::release(uint32_t n) {
  nodes_[n].parent = free_;
  nodes_[n].child1 = kNull;
  nodes_[n].height = -1;
  free_ = n;
}

void DynamicBoundsTree::clear() {
  nodes_.clear();
  root_ = free_ = kNull;
  leaves_ = 0;
}

uint32_t DynamicBoundsTree::insert(const WorldAabb& box, uint32_t id) {
  const uint32_t leaf = allocate();
  nodes_[leaf] = {box, kNull, kNull, id, 0};
  insertLeaf(leaf);
  ++leaves_;
  return leaf;
}

void DynamicBoundsTree::remove(uint32_t leaf) {
  if (leaf >= nodes_.size() || !isLeaf(leaf) || nodes_[leaf].height != 0)
    throw InvalidInput("DynamicBoundsTree::remove: node " + std::to_string(leaf) + " is not a leaf");
  removeLeaf(leaf);
  release(leaf);
  --leaves_;
}

void DynamicBoundsTree::move(uint32_t leaf, const WorldAabb& box) {
  if (leaf >= nodes_.size() || !isLeaf(leaf) || nodes_[leaf].height != 0)
    throw InvalidInput("DynamicBoundsTree::move: node " + std::to_string(leaf) + " is not a leaf");
  removeLeaf(leaf);
  nodes_[leaf].box = box;
  insertLeaf(leaf);
}

void DynamicBoundsTree::replaceChild(uint32_t parent, uint32_t from, uint32_t to) {
  if (parent == kNull) {
    root_ = to;
  } else if (nodes_[parent].child1 == from) {
    nodes_[parent].child1 = to;
  } else {
    nodes_[parent].child2 = to;
  }
  nodes_[to].parent = parent;
}

void DynamicBoundsTree::fix(uint32_t n) {
  Node& node = nodes_[n];
  const Node& a = nodes_[node.child1];
  const Node& b = nodes_[node.child2];
  node.box = merged(a.box, b.box);
  node.height = 1 + std::max(a.height, b.height);
}

void DynamicBoundsTree::insertLeaf(uint32_t leaf) {
  if (root_ == kNull) {
    root_ = leaf;
    nodes_[leaf].parent = kNull;
    return;
  }
  const WorldAabb box = nodes_[leaf].box;
  // Down to the sibling: at each inner node, a new parent here costs twice the merged area
  // (the parent's own area, counted for both of its boxes' tests); going down into a child
  // costs that child's growth plus what every ancestor from here grows by.
  uint32_t at = root_;
  while (!isLeaf(at)) {
    const Node& node = nodes_[at];
    const double area = halfArea(node.box);
    const double combined = halfArea(merged(node.box, box));
    const double here = 2 * combined;
    const double inherited = 2 * (combined - area);
    const auto down = [&](uint32_t c) {
      const double grown = halfArea(merged(nodes_[c].box, box));
      return (isLeaf(c) ? grown : grown - halfArea(nodes_[c].box)) + inherited;
    };
    const double c1 = down(node.child1), c2 = down(node.child2);
    if (here < c1 && here < c2) break;
    at = c1 <= c2 ? node.child1 : node.child2;
  }
  const uint32_t sibling = at;
  const uint32_t above = nodes_[sibling].parent;
  const uint32_t parent = allocate();  // note: may move nodes_: no references held across it
  nodes_[parent] = {merged(box, nodes_[sibling].box), kNull, sibling, leaf, nodes_[sibling].height + 1};
  replaceChild(above, sibling, parent);
  nodes_[sibling].parent = parent;
  nodes_[leaf].parent = parent;
  // note: the new parent's box and height are already right, so it is balanced here and the
  // early-stopping refit starts above it.
  refitUpward(nodes_[balance(parent)].parent);
}

void DynamicBoundsTree::removeLeaf(uint32_t leaf) {
  if (leaf == root_) {
    root_ = kNull;
    return;
  }
  const uint32_t parent = nodes_[leaf].parent;
  const uint32_t above = nodes_[parent].parent;
  const uint32_t sibling = nodes_[parent].child1 == leaf ? nodes_[parent].child2 : nodes_[parent].child1;
  replaceChild(above, parent, sibling);
  release(parent);
  refitUpward(above);
}

// Boxes and heights from n up to the root, balancing on the way; stops at the first node that
// neither rotated nor changed (nothing above it can change).
void DynamicBoundsTree::refitUpward(uint32_t n) {
  while (n != kNull) {
    const WorldAabb before = nodes_[n].box;
    const int32_t height = nodes_[n].height;
    const uint32_t top = balance(n);
    if (top == n && nodes_[n].height == height && nodes_[n].box.min == before.min && nodes_[n].box.max == before.max) return;
    n = nodes_[top].parent;
  }
}

// Fixes a's box and height; a node whose children's heights differ by more than one lifts its
// taller child (one AVL rotation: it restores balance where the edit changed a height by one; a
// new parent over a tall sibling and a leaf stays lopsided, as the insertion heuristic chose).
// Returns the node now in a's place, fixed.
uint32_t DynamicBoundsTree::balance(uint32_t a) {
  if (isLeaf(a)) return a;
  fix(a);
  if (nodes_[a].height < 2) return a;
  const int32_t diff = nodes_[nodes_[a].child2].height - nodes_[nodes_[a].child1].height;
  if (diff > 1) return rotateUp(a, nodes_[a].child2);
  if (diff < -1) return rotateUp(a, nodes_[a].child1);
  return a;
}

// `up`, a child of `a`, takes a's place with `a` as its first child; up keeps its taller child
// and hands the shorter one to `a` (in place of itself). Returns up.
uint32_t DynamicBoundsTree::rotateUp(uint32_t a, uint32_t up) {
  const uint32_t f = nodes_[up].child1, g = nodes_[up].child2;
  const bool fTaller = nodes_[f].height > nodes_[g].height;
  const uint32_t keep = fTaller ? f : g, give = fTaller ? g : f;
  replaceChild(nodes_[a].parent, a, up);
  if (nodes_[a].child1 == up) {
    nodes_[a].child1 = give;
  } else {
    nodes_[a].child2 = give;
  }
  nodes_[give].parent = a;
  nodes_[up].child1 = a;
  nodes_[up].child2 = keep;
  nodes_[a].parent = up;
  fix(a);
  fix(up);
  return up;
}

// ------------------------------------------------------------------------------- bulk build

void DynamicBoundsTree::split(const Range& r, Range& left, Range& right) {
  // note: centres compared as min + max (twice the centre): the same order, one add fewer.
  const auto centre = [](const Item& i, int a) { return i.box.min[a] + i.box.max[a]; };
  Vec3d lo = items_[r.begin].box.min + items_[r.begin].box.max, hi = lo;
  for (uint32_t p = r.begin + 1; p < r.end; ++p) {
    const Vec3d c = items_[p].box.min + items_[p].box.max;
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  int axis;
  (hi - lo).maxCoeff(&axis);
  const uint32_t mid = r.begin + (r.end - r.begin) / 2;
  // Ties broken by item index: a strict total order, so the split is a pure function of the
  // range's items.
  std::nth_element(items_.begin() + r.begin, items_.begin() + mid, items_.begin() + r.end, [&](const Item& a, const Item& b) {
    const double ca = centre(a, axis), cb = centre(b, axis);
    return ca < cb || (ca == cb && a.item < b.item);
  });
  // A range of k leaves owns the k - 1 inner nodes from its own: the left range the next
  // (mid - begin - 1), the right range those after them.
  const uint32_t leftCount = mid - r.begin, rightCount = r.end - mid;
  left = {r.begin, mid, leftCount == 1 ? buildLeaf(r.begin) : r.node + 1, r.node};
  right = {mid, r.end, rightCount == 1 ? buildLeaf(mid) : r.node + leftCount, r.node};
  Node& node = nodes_[r.node];
  node.parent = r.parent;
  node.child1 = left.node;
  node.child2 = right.node;
}

void DynamicBoundsTree::finishLeaf(uint32_t p) {
  Node& leaf = nodes_[buildLeaf(p)];
  leaf.box = items_[p].box;
  leaf.child1 = kNull;
  leaf.child2 = (*buildIds_)[items_[p].item];
  leaf.height = 0;
}

void DynamicBoundsTree::buildSubtree(const Range& r) {
  if (r.end - r.begin == 1) {
    finishLeaf(r.begin);
    nodes_[r.node].parent = r.parent;
    return;
  }
  Range left, right;
  split(r, left, right);
  buildSubtree(left);
  buildSubtree(right);
  fix(r.node);
}

void DynamicBoundsTree::build(const std::vector<WorldAabb>& boxes, const std::vector<uint32_t>& ids, std::vector<uint32_t>& leafOf,
                              JobSystem* jobs, Profiler* profiler, int stage) {
  if (boxes.size() != ids.size())
    throw InvalidInput("DynamicBoundsTree::build: " + std::to_string(boxes.size()) + " boxes but " + std::to_string(ids.size()) + " ids");
  const uint32_t n = uint32_t(boxes.size());
  clear();
  leafOf.resize(n);
  if (n == 0) return;
  buildIds_ = &ids;
  buildCount_ = n;
  nodes_.assign(2 * size_t(n) - 1, kFreeNode);
  items_.resize(n);
  const auto forEach = [&](uint32_t count, uint32_t grain, int at, const char* zone, const auto& body) {
    if (!jobs) {
      const MaybeZone z(profiler, zone, at);
      for (uint32_t k = 0; k < count; ++k) body(k);
      return;
    }
    jobs->parallelFor(0, count, grain, [&](uint32_t begin, uint32_t end) {
      const MaybeZone z(profiler, zone, at);
      for (uint32_t k = begin; k < end; ++k) body(k);
    });
  };
  const uint32_t itemGrain = std::max<uint32_t>(1024, (n + 63) / 64);
  forEach(n, itemGrain, stage, "dynamic tree: items", [&](uint32_t k) {
    items_[k] = {boxes[k], k};
  });
  root_ = n == 1 ? buildLeaf(0) : 0;
  // Ranges above kSubtreeLeaves split level by level, a level's ranges in parallel; the rest
  // are built whole, one job each; the top ranges' boxes last, children before parents.
  level_.assign(1, Range{0, n, root_, kNull});
  whole_.clear();
  top_.clear();
  int at = stage + 1;
  while (!level_.empty()) {
    next_.clear();
    for (const Range& r : level_) (r.end - r.begin > kSubtreeLeaves ? next_ : whole_).push_back(r);
    level_.swap(next_);
    if (level_.empty()) break;
    children_.resize(2 * level_.size());
    forEach(uint32_t(level_.size()), 1, std::min(at, stage + kBuildStages - 3), "dynamic tree: split level",
            [&](uint32_t k) { split(level_[k], children_[2 * k], children_[2 * k + 1]); });
    if (at < stage + kBuildStages - 3) ++at;
    top_.insert(top_.end(), level_.begin(), level_.end());
    level_.assign(children_.begin(), children_.end());
  }
  forEach(uint32_t(whole_.size()), 1, stage + kBuildStages - 2, "dynamic tree: subtrees", [&](uint32_t k) { buildSubtree(whole_[k]); });
  {
    const MaybeZone z(profiler, "dynamic tree: top boxes", stage + kBuildStages - 1);
    for (auto it = top_.rbegin(); it != top_.rend(); ++it) fix(it->node);
  }
  forEach(n, itemGrain, stage + kBuildStages - 1, "dynamic tree: leaves", [&](uint32_t p) { leafOf[items_[p].item] = buildLeaf(p); });
  leaves_ = n;
  buildIds_ = nullptr;
}

void DynamicBoundsTree::leafIds(std::vector<uint32_t>& out) const {
  out.clear();
  for (const Node& node : nodes_)
    if (node.height == 0) out.push_back(node.child2);
}

void DynamicBoundsTree::validate() const {
  const auto fail = [](uint32_t n, const char* what) {
    throw std::logic_error("DynamicBoundsTree: node " + std::to_string(n) + ": " + what);
  };
  std::vector<uint8_t> seen(nodes_.size(), 0);
  uint32_t leaves = 0;
  if (root_ != kNull) {
    if (nodes_[root_].parent != kNull) fail(root_, "the root has a parent");
    std::vector<uint32_t> stack{root_};
    while (!stack.empty()) {
      const uint32_t n = stack.back();
      stack.pop_back();
      if (n >= nodes_.size() || seen[n]) fail(n, "reached twice or out of range");
      seen[n] = 1;
      const Node& node = nodes_[n];
      if (node.child1 == kNull) {
        if (node.height != 0) fail(n, "a leaf's height is not 0");
        ++leaves;
        continue;
      }
      for (const uint32_t c : {node.child1, node.child2}) {
        if (c >= nodes_.size() || nodes_[c].parent != n) fail(n, "a child does not name it as its parent");
        stack.push_back(c);
      }
      const Node& a = nodes_[node.child1];
      const Node& b = nodes_[node.child2];
      if (node.height != 1 + std::max(a.height, b.height)) fail(n, "wrong height");
      const WorldAabb m = merged(a.box, b.box);
      if (m.min != node.box.min || m.max != node.box.max) fail(n, "box is not its children's union");
    }
  }
  if (leaves != leaves_) throw std::logic_error("DynamicBoundsTree: " + std::to_string(leaves) + " leaves reached, " + std::to_string(leaves_) + " counted");
  for (uint32_t f = free_; f != kNull; f = nodes_[f].parent) {
    if (f >= nodes_.size() || seen[f]) fail(f, "on the free list twice, or also in the tree");
    seen[f] = 1;
  }
  for (uint32_t n = 0; n < nodes_.size(); ++n)
    if (!seen[n]) fail(n, "neither in the tree nor free");
}

}  // namespace bw
