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
  std::vector<double> minX_;       // boxes_' min.x, apart: the search reads 8 bytes a step, not 48
  std::vector<uint32_t> bodies_;
  std::vector<double> reachX_;     // max of max.x over boxes_[0..k]
};

template <class Accept>
bool BodyBoxIndex::any(const WorldAabb& box, Accept&& accept) const {
  // The boxes starting at or before the query's end, scanned from the last one back until no
  // earlier box reaches the query's start.
  // note: branch-free halving (the first box whose min.x is beyond the query's end): a query
  // per pair of the frame, at random places, mispredicted every other step as a plain loop.
  size_t lo = 0, n = minX_.size();  // the answer lies in [lo, lo + n]
  if (n > 0) {
    while (n > 1) {
      const size_t half = n / 2;
      lo = minX_[lo + half] <= box.max.x() ? lo + half : lo;
      n -= half;
    }
    lo += minX_[lo] <= box.max.x() ? 1 : 0;
  }
  for (size_t k = lo; k-- > 0 && reachX_[k] >= box.min.x();)
    if (boxes_[k].overlaps(box) && accept(bodies_[k])) return true;
  return false;
}

}  // namespace bw
