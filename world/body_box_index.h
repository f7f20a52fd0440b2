#pragma once
/// Bodies' world boxes sorted along x, for one question asked many times a frame: is any body
/// inside this box? The edit load asks it before it places a brick (a game does not build a
/// brick into a crate standing there). Built in O(n log n), each query scans only the boxes
/// whose x ranges reach the query's (a prefix maximum of the boxes' max x ends the scan).
#include <cstdint>
#include <vector>

#include "world/broadphase.h"

namespace bw {

class BodyBoxIndex {
 public:
  /// boxes[k] belongs to bodies[k].
  void build(std::vector<WorldAabb> boxes, std::vector<uint32_t> bodies);
  /// Whether a box overlapping `box` belongs to a body for which accept(body) is true.
  template <class Accept>
  bool any(const WorldAabb& box, Accept&& accept) const;

 private:
  std::vector<WorldAabb> boxes_;   // sorted by min.x
  std::vector<uint32_t> bodies_;
  std::vector<double> reachX_;     // max of max.x over boxes_[0..k]
};

template <class Accept>
bool BodyBoxIndex::any(const WorldAabb& box, Accept&& accept) const {
  // The boxes starting at or before the query's end, scanned from the last one back until no
  // earlier box reaches the query's start.
  size_t lo = 0, hi = boxes_.size();
  while (lo < hi) {
    const size_t mid = (lo + hi) / 2;
    if (boxes_[mid].min.x() <= box.max.x()) lo = mid + 1; else hi = mid;
  }
  for (size_t k = lo; k-- > 0 && reachX_[k] >= box.min.x();)
    if (boxes_[k].overlaps(box) && accept(bodies_[k])) return true;
  return false;
}

}  // namespace bw
