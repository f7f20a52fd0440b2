#include "world/body_box_index.h"

#include <algorithm>
#include <numeric>

namespace bw {

void BodyBoxIndex::build(std::vector<WorldAabb> boxes, std::vector<uint32_t> bodies) {
  std::vector<uint32_t> order(boxes.size());
  std::iota(order.begin(), order.end(), 0u);
  // note: ties broken by body, so the order (and any accept with side effects) is deterministic.
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return boxes[a].min.x() != boxes[b].min.x() ? boxes[a].min.x() < boxes[b].min.x() : bodies[a] < bodies[b];
  });
  boxes_.resize(boxes.size());
  minX_.resize(boxes.size());
  bodies_.resize(boxes.size());
  reachX_.resize(boxes.size());
  double reach = -1e300;
  for (size_t k = 0; k < order.size(); ++k) {
    boxes_[k] = boxes[order[k]];
    minX_[k] = boxes_[k].min.x();
    bodies_[k] = bodies[order[k]];
    reach = std::max(reach, boxes_[k].max.x());
    reachX_[k] = reach;
  }
}

}  // namespace bw
