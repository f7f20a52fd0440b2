#pragma once
// Brute-force reference for spatial-index tests: every query is a scan over all elements.
#include <algorithm>
#include <map>
#include <vector>

#include "collision/core/obb.h"
#include "collision/core/ray.h"
#include "collision/index/spatial_query_types.h"

namespace bw::test {

struct BruteForceIndex {
  struct Item {
    Aabb bounds;
    uint32_t filter;
  };
  std::map<uint32_t, Item> items;  // by handle of the index under test

  std::vector<uint32_t> overlap(const Aabb& box, uint32_t mask) const {
    std::vector<uint32_t> out;
    for (auto& [h, it] : items)
      if ((it.filter & mask) && it.bounds.overlaps(box)) out.push_back(h);
    return out;
  }
  std::vector<uint32_t> overlap(const Obb& box, uint32_t mask) const {
    std::vector<uint32_t> out;
    for (auto& [h, it] : items)
      if ((it.filter & mask) && bw::overlaps(box, it.bounds)) out.push_back(h);
    return out;
  }
  std::vector<RayHit> raycastAll(const Ray& ray, uint32_t mask) const {
    std::vector<RayHit> out;
    for (auto& [h, it] : items) {
      float t;
      if ((it.filter & mask) && intersectRayAabb(ray, it.bounds, 0.f, ray.maxT, t)) out.push_back({h, t});
    }
    std::sort(out.begin(), out.end());
    return out;
  }
};

}  // namespace bw::test
