#include "collision/bricks/brick_connectivity.h"

#include <algorithm>
#include <string>

#include "collision/bricks/brick_geometry.h"
#include "collision/core/argument_checks.h"

namespace bw {

namespace {
constexpr uint32_t kMaxBricksPerTurn = 64;
constexpr size_t kListsAhead = 4;
}  // namespace

float BrickConnectivity::toleranceAt(const Aabb& a) {
  // Four float steps of the coordinates at hand, at least kTolerance: bricks far from the grid
  // origin are placed no finer than that.
  const float m = std::max(a.min.cwiseAbs().maxCoeff(), a.max.cwiseAbs().maxCoeff());
  return std::max(kTolerance, m * 4.8e-7f);
}

bool BrickConnectivity::touches(const Aabb& a, const Aabb& b) {
  // Overlap length along each axis (negative: a gap). Touching across a face: no gap beyond the
  // tolerance on any axis, and an overlap beyond it on at least two (an edge or a corner is not
  // a joint that holds).
  const float tol = std::max(toleranceAt(a), toleranceAt(b));
  int across = 0;
  for (int i = 0; i < 3; ++i) {
    const float overlap = std::min(a.max[i], b.max[i]) - std::max(a.min[i], b.min[i]);
    if (overlap < -tol) return false;
    across += overlap > tol;
  }
  return across >= 2;
}

BrickConnectivity::BrickConnectivity(const BrickGrid& grid) {
  grid.forEachBrick([&](uint32_t id) { adjacency_.grow(id + 1); });
  live_.assign(adjacency_.size(), 0);
  grid.forEachBrick([&](uint32_t id) {
    live_[id] = 1;
    const Aabb box = brickBounds(grid.brick(id));
    scratch_.clear();
    grid.overlapBricks(box.expanded(2.f * toleranceAt(box)), ~0u, scratch_);
    for (uint32_t o : scratch_)
      if (o > id && touches(box, brickBounds(grid.brick(o)))) link(id, o);
  });
  // The searches' marks sized with the links, not by the first removal: a 100k-brick grid's
  // 800 KB first touched there cost its first cut ~0.26 ms of page faults (Split_CutInTwo).
  marks_.resize(adjacency_.size());
}

BrickConnectivity::BrickConnectivity(BrickConnectivity& from, std::span<const uint32_t> oldIds, std::span<const uint32_t> newIds) {
  const char* context = "BrickConnectivity (a part's links)";
  if (oldIds.size() != newIds.size())
    throw InvalidInput(std::string(context) + ": " + std::to_string(oldIds.size()) + " old ids for " + std::to_string(newIds.size()) + " new ones");
  uint32_t top = 0;
  for (uint32_t id : newIds) top = std::max(top, id + 1);
  // Old id -> new id, through a map sized by the old ids; checked whole before anything moves.
  std::vector<uint32_t> renumber(from.adjacency_.size(), ~0u);
  for (size_t k = 0; k < oldIds.size(); ++k) {
    if (oldIds[k] >= from.adjacency_.size() || !from.live_[oldIds[k]])
      throw InvalidInput(std::string(context) + ": brick " + std::to_string(oldIds[k]) + " is not linked");
    renumber[oldIds[k]] = newIds[k];
  }
  // note: the ids come in the search's order, a cache miss per list: asked for ahead.
  constexpr size_t kAhead = 8;
  for (size_t k = 0; k < oldIds.size(); ++k) {
    if (k + kAhead < oldIds.size()) from.adjacency_.prefetch(oldIds[k + kAhead]);
    for (uint32_t n : from.adjacency_[oldIds[k]])
      if (renumber[n] == ~0u)
        throw InvalidInput(std::string(context) + ": brick " + std::to_string(oldIds[k]) + " has a neighbour outside the part");
  }
  adjacency_.grow(top);
  live_.assign(top, 0);
  for (size_t k = 0; k < oldIds.size(); ++k) {
    if (k + kAhead < oldIds.size()) from.adjacency_.prefetch(oldIds[k + kAhead]);
    adjacency_.takeFrom(from.adjacency_, oldIds[k], newIds[k]);
    from.live_[oldIds[k]] = 0;
    for (uint32_t& n : adjacency_.mutableList(newIds[k])) n = renumber[n];
    live_[newIds[k]] = 1;
  }
}

void BrickConnectivity::link(uint32_t a, uint32_t b) {
  adjacency_.append(a, b);
  adjacency_.append(b, a);
}

void BrickConnectivity::placed(const BrickGrid& grid, uint32_t id) {
  if (id >= adjacency_.size()) {
    adjacency_.grow(id + 1);
    live_.resize(size_t(id) + 1, 0);
  }
  adjacency_.clear(id);
  live_[id] = 1;
  const Aabb box = brickBounds(grid.brick(id));
  scratch_.clear();
  grid.overlapBricks(box.expanded(2.f * toleranceAt(box)), ~0u, scratch_);
  // note: sorted, so a brick's list (and every search after it) does not depend on the index's order.
  std::sort(scratch_.begin(), scratch_.end());
  for (uint32_t o : scratch_)
    if (o != id && touches(box, brickBounds(grid.brick(o)))) link(id, o);
}

void BrickConnectivity::removing(uint32_t id, std::vector<uint32_t>& seeds) {
  if (id >= adjacency_.size() || !live_[id]) return;
  for (uint32_t n : adjacency_[id]) {
    adjacency_.erase(n, id);  // keeps the list's order
    seeds.push_back(n);
  }
  adjacency_.clear(id);
  live_[id] = 0;
}

std::span<const uint32_t> BrickConnectivity::neighbours(uint32_t id) const {
  if (id >= adjacency_.size()) return {};
  return adjacency_[id];
}

uint32_t BrickConnectivity::find(uint32_t s) {
  while (parent_[s] != s) s = parent_[s] = parent_[parent_[s]];
  return s;
}

void BrickConnectivity::detached(std::span<const uint32_t> seeds, std::vector<std::vector<uint32_t>>& pieces, ConnectivityStats* stats) {
  ConnectivityStats st;
  // The live seeds, each once, in ascending order (the searches' order).
  scratch_.clear();
  for (uint32_t s : seeds)
    if (s < live_.size() && live_[s]) scratch_.push_back(s);
  std::sort(scratch_.begin(), scratch_.end());
  scratch_.erase(std::unique(scratch_.begin(), scratch_.end()), scratch_.end());
  const uint32_t k = uint32_t(scratch_.size());
  if (k < 2) {
    if (stats) *stats = st;
    return;
  }
  if (marks_.size() < adjacency_.size()) marks_.resize(adjacency_.size());
  if (++epoch_ == 0) {  // the stamps wrapped: clear them once
    for (Mark& m : marks_) m.stamp = 0;
    epoch_ = 1;
  }
  if (queues_.size() < k) queues_.resize(k);
  heads_.assign(k, 0);
  parent_.resize(k);
  reported_.assign(k, 0);
  for (uint32_t i = 0; i < k; ++i) {
    parent_[i] = i;
    queues_[i].assign(1, scratch_[i]);
    marks_[scratch_[i]] = {epoch_, i};
  }
  uint32_t groups = k;  // groups of searches still growing and not reported
  // Bricks each search takes per turn: one while the searches may still meet nearby (the
  // common case ends within a few turns), then more, so the bookkeeping after each round
  // (which searches ran dry) stays small beside the walk when a big piece is walked whole.
  uint32_t perTurn = 1;
  while (groups > 1) {
    for (uint32_t i = 0; i < k && groups > 1; ++i) {
      for (uint32_t taken = 0; taken < perTurn && heads_[i] < queues_[i].size() && groups > 1; ++taken) {
        const uint32_t u = queues_[i][heads_[i]++];
        ++st.visited;
        // The queue's next lists, asked for ahead: a search walks a piece in a random order.
        if (heads_[i] + kListsAhead < queues_[i].size()) adjacency_.prefetch(queues_[i][heads_[i] + kListsAhead]);
        for (uint32_t v : adjacency_[u]) {
          Mark& m = marks_[v];
          if (m.stamp != epoch_) {
            m = {epoch_, i};
            queues_[i].push_back(v);
            continue;
          }
          if (m.owner == i) continue;  // this search's own brick (most edges)
          const uint32_t a = find(i), b = find(m.owner);
          if (a == b) continue;
          parent_[std::max(a, b)] = std::min(a, b);  // the searches met: one part
          --groups;
        }
      }
    }
    perTurn = std::min<uint32_t>(perTurn * 2, kMaxBricksPerTurn);
    // A group whose searches have all run dry has walked a whole part: it fell off.
    active_.assign(k, 0);
    for (uint32_t i = 0; i < k; ++i)
      if (heads_[i] < queues_[i].size()) active_[find(i)] = 1;
    for (uint32_t r = 0; r < k && groups > 1; ++r) {
      if (find(r) != r || reported_[r] || active_[r]) continue;
      std::vector<uint32_t>& piece = pieces.emplace_back();
      for (uint32_t i = 0; i < k; ++i)
        if (find(i) == r) piece.insert(piece.end(), queues_[i].begin(), queues_[i].end());
      reported_[r] = 1;
      ++st.pieces;
      --groups;
    }
  }
  if (stats) *stats = st;
}

}  // namespace bw
