#include "world/dynamic_bounds_tree.h"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "collision/core/errors.h"
#include "collision/core/morton.h"
#include "jobs/chunked_for.h"

namespace bw {

namespace {

WorldAabb merged(const WorldAabb& a, const WorldAabb& b) { return {a.min.cwiseMin(b.min), a.max.cwiseMax(b.max)}; }

// Half the surface area: the insertion heuristic's cost (only ratios and sums of it matter).
double halfArea(const WorldAabb& b) {
  const Vec3d d = b.max - b.min;
  return d.x() * d.y() + d.y() * d.z() + d.z() * d.x();
}

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

uint32_t DynamicBoundsTree::refit(uint32_t leaf, const WorldAabb& box, uint32_t maxGrown) {
  if (leaf >= nodes_.size() || !isLeaf(leaf) || nodes_[leaf].height != 0)
    throw InvalidInput("DynamicBoundsTree::refit: node " + std::to_string(leaf) + " is not a leaf");
  const auto holds = [&](uint32_t n) {
    const WorldAabb& b = nodes_[n].box;
    return (b.min.array() <= box.min.array()).all() && (box.max.array() <= b.max.array()).all();
  };
  uint32_t grown = 0;
  for (uint32_t n = nodes_[leaf].parent; n != kNull && !holds(n); n = nodes_[n].parent)
    if (++grown > maxGrown) {
      move(leaf, box);
      return 0;
    }
  nodes_[leaf].box = box;
  for (uint32_t n = nodes_[leaf].parent, k = 0; k < grown; n = nodes_[n].parent, ++k) nodes_[n].box = merged(nodes_[n].box, box);
  return grown;
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
  // Where the range's first and last codes first differ (the octree cell boundary between its
  // halves); a range of equal codes splits in the middle.
  const uint64_t first = codes_[r.begin].first, last = codes_[r.end - 1].first;
  uint32_t mid;
  if (first == last) {
    mid = r.begin + (r.end - r.begin) / 2;
  } else {
    const int bit = 63 - __builtin_clzll(first ^ last);
    const uint64_t above = last >> bit << bit;  // the first code on the upper side
    mid = uint32_t(std::lower_bound(codes_.begin() + r.begin, codes_.begin() + r.end, std::pair<uint64_t, uint32_t>{above, 0}) -
                   codes_.begin());
  }
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

void DynamicBoundsTree::buildSubtree(const Range& r) {
  if (r.end - r.begin == 1) {
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
  buildCount_ = n;
  nodes_.assign(2 * size_t(n) - 1, kFreeNode);
  codes_.resize(n);
  const uint32_t itemGrain = std::max<uint32_t>(1024, (n + 63) / 64);
  const uint32_t chunks = JobSystem::chunkCount(0, n, itemGrain);
  const auto forChunks = [&](uint32_t count, uint32_t grain, int at, const char* zone, const auto& body) {
    chunkedFor(jobs, profiler, count, grain, at, zone, body);
  };
  // 1. The centres' bounds (per chunk, joined in chunk order), then each item's Morton code on
  //    a 2^21 lattice over them; sorted by (code, item): near in space, near in the order.
  chunkLo_.resize(chunks);
  chunkHi_.resize(chunks);
  forChunks(n, itemGrain, stage, "dynamic tree: codes", [&](uint32_t begin, uint32_t end) {
    Vec3d lo = boxes[begin].min + boxes[begin].max, hi = lo;
    for (uint32_t k = begin + 1; k < end; ++k) {
      const Vec3d c = boxes[k].min + boxes[k].max;  // twice the centre: the same order
      lo = lo.cwiseMin(c);
      hi = hi.cwiseMax(c);
    }
    chunkLo_[begin / itemGrain] = lo;
    chunkHi_[begin / itemGrain] = hi;
  });
  Vec3d lo = chunkLo_[0], hi = chunkHi_[0];
  for (uint32_t c = 1; c < chunks; ++c) {
    lo = lo.cwiseMin(chunkLo_[c]);
    hi = hi.cwiseMax(chunkHi_[c]);
  }
  const double cells = double((1u << 21) - 1);
  const Vec3d scale = (hi - lo).unaryExpr([&](double e) { return e > 0 ? cells / e : 0.0; });
  forChunks(n, itemGrain, stage + 1, "dynamic tree: codes", [&](uint32_t begin, uint32_t end) {
    for (uint32_t k = begin; k < end; ++k) {
      const Vec3d q = ((boxes[k].min + boxes[k].max - lo).cwiseProduct(scale)).cwiseMax(0.0).cwiseMin(cells);
      codes_[k] = {mortonCode(uint64_t(q.x()), uint64_t(q.y()), uint64_t(q.z())), k};
    }
  });
  if (jobs) {
    sorter_.sort(codes_, false, *jobs, profiler, "dynamic tree: sort codes", stage + 2);
  } else {
    std::sort(codes_.begin(), codes_.end());
  }
  // 2. Leaves in that order (the boxes gathered once), inner nodes over ranges split where the
  //    codes first differ: the ranges above kSubtreeLeaves level by level, the rest whole, one
  //    job each, then the top ranges' boxes, children before parents.
  forChunks(n, itemGrain, stage + 6, "dynamic tree: leaves", [&](uint32_t begin, uint32_t end) {
    for (uint32_t p = begin; p < end; ++p) {
      const uint32_t item = codes_[p].second;
      nodes_[buildLeaf(p)] = {boxes[item], kNull, kNull, ids[item], 0};
      leafOf[item] = buildLeaf(p);
    }
  });
  root_ = n == 1 ? buildLeaf(0) : 0;
  level_.assign(1, Range{0, n, root_, kNull});
  whole_.clear();
  top_.clear();
  {
    const OptionalZone z(profiler, "dynamic tree: top ranges", stage + 7);
    while (!level_.empty()) {
      next_.clear();
      for (const Range& r : level_) {
        if (r.end - r.begin <= kSubtreeLeaves) {
          whole_.push_back(r);
          continue;
        }
        Range left, right;
        split(r, left, right);
        top_.push_back(r);
        next_.push_back(left);
        next_.push_back(right);
      }
      level_.swap(next_);
    }
  }
  const uint32_t subtrees = uint32_t(whole_.size());
  forChunks(subtrees, std::max<uint32_t>(1, (subtrees + 63) / 64), stage + 8, "dynamic tree: subtrees", [&](uint32_t begin, uint32_t end) {
    for (uint32_t k = begin; k < end; ++k) buildSubtree(whole_[k]);
  });
  {
    const OptionalZone z(profiler, "dynamic tree: top boxes", stage + 9);
    for (auto it = top_.rbegin(); it != top_.rend(); ++it) fix(it->node);
  }
  leaves_ = n;
}

// ------------------------------------------------------------------------- the tree against itself

template <class Emit>
uint64_t DynamicBoundsTree::crossPairs(uint32_t a, uint32_t b, std::vector<Task>& stack, Emit& emit) const {
  uint64_t tests = 0;
  stack.clear();
  stack.push_back({a, b});
  while (!stack.empty()) {
    const Task t = stack.back();
    stack.pop_back();
    const Node& x = nodes_[t.a];
    const Node& y = nodes_[t.b];
    ++tests;
    if (!x.box.overlaps(y.box)) continue;
    if (x.child1 == kNull && y.child1 == kNull) {
      emit(x.child2, y.child2);
      continue;
    }
    // Open the larger side (a leaf never opens).
    if (y.child1 != kNull && (x.child1 == kNull || halfArea(y.box) > halfArea(x.box))) {
      stack.push_back({t.a, y.child2});
      stack.push_back({t.a, y.child1});
    } else {
      stack.push_back({x.child2, t.b});
      stack.push_back({x.child1, t.b});
    }
  }
  return tests;
}

template <class Emit>
uint64_t DynamicBoundsTree::selfTask(uint32_t n, std::vector<Task>& stack, Emit& emit) const {
  if (isLeaf(n)) return 0;
  return selfTask(nodes_[n].child1, stack, emit) + selfTask(nodes_[n].child2, stack, emit) +
         crossPairs(nodes_[n].child1, nodes_[n].child2, stack, emit);
}

uint64_t DynamicBoundsTree::selfPairs(std::vector<BodyPair>& out, const uint8_t* wanted, JobSystem* jobs, Profiler* profiler, int stage) {
  out.clear();
  if (root_ == kNull) return 0;
  // The top of the traversal, breadth first, until there are enough tasks to share: a subtree
  // against itself becomes its children against themselves and each other; two subtrees
  // against each other become the larger one's children against the other (dropped when the
  // boxes miss). The tasks' order depends only on the tree.
  constexpr uint32_t kTasks = 256;
  constexpr int kRounds = 10;
  tasks_.assign(1, Task{root_, kNull});
  uint64_t topTests = 0;
  for (int round = 0; round < kRounds && tasks_.size() < kTasks; ++round) {
    nextTasks_.clear();
    for (const Task& t : tasks_) {
      if (t.b == kNull) {
        if (isLeaf(t.a)) continue;
        const Node& node = nodes_[t.a];
        nextTasks_.push_back({node.child1, kNull});
        nextTasks_.push_back({node.child2, kNull});
        nextTasks_.push_back({node.child1, node.child2});
        continue;
      }
      const Node& x = nodes_[t.a];
      const Node& y = nodes_[t.b];
      ++topTests;
      if (!x.box.overlaps(y.box)) continue;
      if (x.child1 == kNull && y.child1 == kNull) {
        nextTasks_.push_back(t);
      } else if (y.child1 != kNull && (x.child1 == kNull || halfArea(y.box) > halfArea(x.box))) {
        nextTasks_.push_back({t.a, y.child1});
        nextTasks_.push_back({t.a, y.child2});
      } else {
        nextTasks_.push_back({x.child1, t.b});
        nextTasks_.push_back({x.child2, t.b});
      }
    }
    tasks_.swap(nextTasks_);
  }
  const uint32_t count = uint32_t(tasks_.size());
  if (taskPairs_.size() < count) {
    taskPairs_.resize(count);
    taskStacks_.resize(count);
  }
  taskTests_.assign(count, 0);
  const auto run = [&](uint32_t k) {
    std::vector<BodyPair>& pairs = taskPairs_[k];
    pairs.clear();
    auto emit = [&](uint32_t p, uint32_t q) {
      if (!wanted || wanted[p] || wanted[q]) pairs.push_back(p < q ? BodyPair{p, q} : BodyPair{q, p});
    };
    const Task& t = tasks_[k];
    taskTests_[k] = t.b == kNull ? selfTask(t.a, taskStacks_[k], emit) : crossPairs(t.a, t.b, taskStacks_[k], emit);
  };
  chunkedFor(jobs, profiler, count, 1, stage, "dynamic tree: pairs", [&](uint32_t begin, uint32_t end) {
    for (uint32_t k = begin; k < end; ++k) run(k);
  });
  {
    const OptionalZone z(profiler, "dynamic tree: join pairs", stage + 1);
    taskOffset_.assign(count + 1, 0);
    for (uint32_t k = 0; k < count; ++k) taskOffset_[k + 1] = taskOffset_[k] + taskPairs_[k].size();
    out.resize(taskOffset_[count]);
    for (uint32_t k = 0; k < count; ++k) std::copy(taskPairs_[k].begin(), taskPairs_[k].end(), out.begin() + taskOffset_[k]);
  }
  if (jobs) {
    pairSorter_.sort(out, false, *jobs, profiler, "dynamic tree: sort pairs", stage + 2);
  } else {
    std::sort(out.begin(), out.end());
  }
  uint64_t tests = topTests;
  for (uint32_t k = 0; k < count; ++k) tests += taskTests_[k];
  return tests;
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
      // note: refit() lets boxes hold more than their children (never less).
      const WorldAabb m = merged(a.box, b.box);
      if ((m.min.array() < node.box.min.array()).any() || (m.max.array() > node.box.max.array()).any())
        fail(n, "box does not hold its children's");
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
