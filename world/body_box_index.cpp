#include "world/body_box_index.h"

#include <algorithm>
#include <cmath>

namespace bw {

void BodyBoxIndex::build(std::vector<WorldAabb> boxes, std::vector<uint32_t> bodies) {
  const size_t n = boxes.size();
  boxes_.resize(n);
  minX_.resize(n);
  bodies_.resize(n);
  reachX_.resize(n);
  bucketStart_.assign(n + 1, 0);
  occupancy_.build(boxes);
  if (n == 0) return;
  // One bucket per box over the span of min x: a bucket is a monotone function of min x, so
  // sorting by bucket first (counting) and then inside each bucket orders the boxes exactly as
  // one sort by min x would, in O(n) for boxes spread along x.
  lowX_ = boxes[0].min.x();
  double highX = lowX_;
  for (const WorldAabb& b : boxes) {
    lowX_ = std::min(lowX_, b.min.x());
    highX = std::max(highX, b.min.x());
  }
  // note: a span beyond double's reach (an infinite box) puts every box in one bucket.
  bucketScale_ = highX > lowX_ && std::isfinite(highX - lowX_) ? double(n) / (highX - lowX_) : 0.0;
  std::vector<uint32_t> bucket(n);
  for (size_t i = 0; i < n; ++i) {
    bucket[i] = uint32_t(bucketOf(boxes[i].min.x()));
    ++bucketStart_[bucket[i] + 1];
  }
  for (size_t b = 0; b < n; ++b) bucketStart_[b + 1] += bucketStart_[b];
  std::vector<uint32_t> order(n), next(bucketStart_.begin(), bucketStart_.end() - 1);
  for (uint32_t i = 0; i < n; ++i) order[next[bucket[i]]++] = i;
  // note: ties broken by body, so the order (and any accept with side effects) is deterministic.
  const auto before = [&](uint32_t a, uint32_t b) {
    return boxes[a].min.x() != boxes[b].min.x() ? boxes[a].min.x() < boxes[b].min.x() : bodies[a] < bodies[b];
  };
  for (size_t b = 0; b < n; ++b)
    if (bucketStart_[b + 1] - bucketStart_[b] > 1) std::sort(order.begin() + bucketStart_[b], order.begin() + bucketStart_[b + 1], before);
  double reach = -1e300;
  for (size_t k = 0; k < n; ++k) {
    boxes_[k] = boxes[order[k]];
    minX_[k] = boxes_[k].min.x();
    bodies_[k] = bodies[order[k]];
    reach = std::max(reach, boxes_[k].max.x());
    reachX_[k] = reach;
  }
}

}  // namespace bw
