#include "world/static_bounds_tree.h"

#include <algorithm>
#include <string>

#include "collision/core/argument_checks.h"

namespace bw {

void StaticBoundsTree::build(const std::vector<WorldAabb>& boxes, const std::vector<uint32_t>& ids) {
  if (boxes.size() != ids.size())
    throw InvalidInput("StaticBoundsTree::build: " + std::to_string(boxes.size()) + " boxes but " + std::to_string(ids.size()) + " ids");
  items_.resize(boxes.size());
  for (size_t k = 0; k < boxes.size(); ++k) items_[k] = {boxes[k], ids[k]};
  nodes_.clear();
  if (items_.empty()) return;
  nodes_.reserve(2 * (items_.size() / kLeafSize + 1));
  nodes_.push_back(emptyNode());
  split(0, 0, uint32_t(items_.size()));
}

void StaticBoundsTree::split(uint32_t node, uint32_t begin, uint32_t end) {
  WorldAabb box = items_[begin].box;
  Vec3d cmin = (box.min + box.max) * 0.5, cmax = cmin;
  for (uint32_t k = begin + 1; k < end; ++k) {
    const WorldAabb& b = items_[k].box;
    box.min = box.min.cwiseMin(b.min);
    box.max = box.max.cwiseMax(b.max);
    const Vec3d c = (b.min + b.max) * 0.5;
    cmin = cmin.cwiseMin(c);
    cmax = cmax.cwiseMax(c);
  }
  nodes_[node].box = box;
  if (end - begin <= kLeafSize) {
    nodes_[node].first = begin;
    nodes_[node].count = end - begin;
    return;
  }
  int axis = 0;
  (cmax - cmin).maxCoeff(&axis);
  const uint32_t mid = begin + (end - begin) / 2;
  // Ties by id: the tree (and so the order queries report in) is a pure function of the input.
  std::nth_element(items_.begin() + begin, items_.begin() + mid, items_.begin() + end, [axis](const Item& a, const Item& b) {
    const double ca = a.box.min[axis] + a.box.max[axis], cb = b.box.min[axis] + b.box.max[axis];
    return ca < cb || (ca == cb && a.id < b.id);
  });
  const uint32_t left = uint32_t(nodes_.size());
  nodes_[node].first = left;
  nodes_[node].count = 0;
  nodes_.push_back(emptyNode());
  nodes_.push_back(emptyNode());
  split(left, begin, mid);
  split(left + 1, mid, end);
}

}  // namespace bw
