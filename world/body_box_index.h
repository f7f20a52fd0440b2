#pragma once
/// Bodies' world boxes sorted along x, for one question asked many times a frame: is any body
/// inside this box? The edit load asks it before it places a brick (a game does not build a
/// brick into a crate standing there). Built in O(n) for boxes spread along x (O(n log n) at
/// worst), each query finds its place among them through a bucket of min x values and scans only
/// the boxes whose x ranges reach the query's (a prefix maximum of the boxes' max x ends the scan).
#include <cstdint>
#include <vector>

#include "world/box_occupancy_bits.h"
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
  // Bucket b holds the boxes whose min x maps to b (bucketOf); they are boxes_[bucketStart_[b],
  // bucketStart_[b + 1]).
  std::vector<uint32_t> bucketStart_;
  BoxOccupancyBits occupancy_;  // most queries meet no box: a few bit tests say so
  double lowX_ = 0, bucketScale_ = 0;

  /// Monotone in x (a subtraction, a product by a non-negative constant, a truncation, a
  /// clamp), so x <= y gives bucketOf(x) <= bucketOf(y).
  size_t bucketOf(double x) const {
    const double t = bucketScale_ > 0 ? (x - lowX_) * bucketScale_ : 0.0;
    const size_t last = bucketStart_.size() - 2;
    return t >= double(last) ? last : t > 0 ? size_t(t) : 0;  // note: NaN to 0, never converted
  }
};

template <class Accept>
bool BodyBoxIndex::any(const WorldAabb& box, Accept&& accept) const {
  // The boxes starting at or before the query's end, scanned from the last one back until no
  // earlier box reaches the query's start.
  // The first box whose min.x is beyond the query's end lies in the bucket of the query's end
  // (boxes in earlier buckets start before it, in later ones after it) or just past it.
  if (!occupancy_.mayOverlap(box) || !(box.max.x() >= lowX_)) return false;
  const size_t b = bucketOf(box.max.x());
  size_t lo = bucketStart_[b], n = bucketStart_[b + 1] - lo;  // the answer lies in [lo, lo + n]
  // note: branch-free halving: a query per pair of the frame, at random places, mispredicted
  // every other step as a plain loop.
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
