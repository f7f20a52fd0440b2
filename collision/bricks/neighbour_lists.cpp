#include "collision/bricks/neighbour_lists.h"

#include <algorithm>

#include "collision/core/assert.h"

namespace bw {

uint32_t NeighbourLists::newSpill() {
  if (!freeSpill_.empty()) {
    const uint32_t s = freeSpill_.back();
    freeSpill_.pop_back();
    return s;
  }
  spill_.emplace_back();
  return uint32_t(spill_.size() - 1);
}

void NeighbourLists::releaseSpill(uint32_t s) {
  spill_[s].clear();
  freeSpill_.push_back(s);
}

void NeighbourLists::append(uint32_t id, uint32_t v) {
  Record& r = records_[id];
  if (r.count < kInline) {
    r.ids[r.count++] = v;
    return;
  }
  if (r.count == kInline) {  // the eighth: the list moves out
    const uint32_t s = newSpill();
    spill_[s].assign(r.ids, r.ids + kInline);
    r.ids[0] = s;
  }
  spill_[r.ids[0]].push_back(v);
  ++r.count;
}

void NeighbourLists::erase(uint32_t id, uint32_t v) {
  Record& r = records_[id];
  if (r.count <= kInline) {
    uint32_t* end = r.ids + r.count;
    uint32_t* at = std::find(r.ids, end, v);
    BW_ASSERT(at != end);
    std::copy(at + 1, end, at);
    --r.count;
    return;
  }
  const uint32_t s = r.ids[0];
  std::vector<uint32_t>& list = spill_[s];
  const auto at = std::find(list.begin(), list.end(), v);
  BW_ASSERT(at != list.end());
  list.erase(at);
  if (--r.count == kInline) {  // back inline
    std::copy(list.begin(), list.end(), r.ids);
    releaseSpill(s);
  }
}

void NeighbourLists::clear(uint32_t id) {
  Record& r = records_[id];
  if (r.count > kInline) releaseSpill(r.ids[0]);
  r.count = 0;
}

void NeighbourLists::takeFrom(NeighbourLists& from, uint32_t fromId, uint32_t toId) {
  Record& src = from.records_[fromId];
  Record& dst = records_[toId];
  BW_ASSERT(dst.count == 0);
  if (src.count <= kInline) {
    dst = src;
  } else {
    const uint32_t s = newSpill();
    spill_[s].swap(from.spill_[src.ids[0]]);  // the ids move, no copy; from keeps an empty vector
    from.releaseSpill(src.ids[0]);
    dst.count = src.count;
    dst.ids[0] = s;
  }
  src.count = 0;
}

}  // namespace bw
