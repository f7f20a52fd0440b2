#include "collision/terrain/voxel_regions.h"

#include <algorithm>
#include <queue>
#include <tuple>

#include "collision/core/hash.h"

namespace bw {

size_t DetachedVoxelSearch::Int3Hash::operator()(const Int3& v) const {
  return size_t(hashCombine(hashCombine(uint64_t(uint32_t(v.x)), uint64_t(uint32_t(v.y))), uint64_t(uint32_t(v.z))));
}

namespace {
// Lowest z first, then y, then x: the walk heads for the ground, in one fixed order.
struct HigherFirst {
  bool operator()(const Int3& a, const Int3& b) const { return std::tie(a.z, a.y, a.x) > std::tie(b.z, b.y, b.x); }
};
bool byZyx(const Int3& a, const Int3& b) { return std::tie(a.z, a.y, a.x) < std::tie(b.z, b.y, b.x); }
}  // namespace

void DetachedVoxelSearch::find(const VoxelTerrain& voxels, int32_t anchorZ, std::span<const Int3> seeds,
                               std::vector<std::vector<Int3>>& regions, uint64_t maxVoxels) {
  regions.clear();
  anchored_.clear();
  detached_.clear();
  visited_ = 0;
  gaveUp_ = 0;
  std::priority_queue<Int3, std::vector<Int3>, HigherFirst> open;
  for (const Int3& seed : seeds) {
    if (!voxels.contains(seed) || !voxels.get(seed).isSolid() || seed.z < anchorZ) continue;
    if (anchored_.count(seed) || detached_.count(seed)) continue;
    seen_.clear();
    open = {};
    open.push(seed);
    seen_.insert(seed);
    bool connected = false;
    while (!open.empty() && !connected) {
      const Int3 v = open.top();
      open.pop();
      ++visited_;
      if (v.z < anchorZ || anchored_.count(v)) {
        connected = true;
        break;
      }
      if (seen_.size() > maxVoxels) {
        connected = true;  // too long a walk: left in place
        ++gaveUp_;
        break;
      }
      const Int3 next[6] = {{v.x - 1, v.y, v.z}, {v.x + 1, v.y, v.z}, {v.x, v.y - 1, v.z},
                            {v.x, v.y + 1, v.z}, {v.x, v.y, v.z - 1}, {v.x, v.y, v.z + 1}};
      for (const Int3& n : next) {
        if (!voxels.contains(n) || seen_.count(n) || !voxels.get(n).isSolid()) continue;
        seen_.insert(n);
        open.push(n);
      }
    }
    if (connected) {
      anchored_.insert(seen_.begin(), seen_.end());
      continue;
    }
    std::vector<Int3> region(seen_.begin(), seen_.end());
    std::sort(region.begin(), region.end(), byZyx);
    detached_.insert(region.begin(), region.end());
    regions.push_back(std::move(region));
  }
}

std::vector<Brick> voxelRegionBricks(const VoxelTerrain& voxels, std::span<const Int3> region, float voxelSize) {
  // Runs along x: (z, y, x0, x1, material), in z, y, x order.
  struct Run {
    int32_t z, y, x0, x1;
    uint8_t material;
  };
  std::vector<Int3> sorted(region.begin(), region.end());
  std::sort(sorted.begin(), sorted.end(), byZyx);
  std::vector<Run> runs;
  for (const Int3& v : sorted) {
    const uint8_t m = voxels.get(v).material;
    if (!runs.empty()) {
      Run& r = runs.back();
      if (r.z == v.z && r.y == v.y && r.x1 + 1 == v.x && r.material == m) {
        r.x1 = v.x;
        continue;
      }
    }
    runs.push_back({v.z, v.y, v.x, v.x, m});
  }
  // Rows merged along y: runs with the same z, x0, x1 and material on consecutive y.
  std::sort(runs.begin(), runs.end(), [](const Run& a, const Run& b) {
    return std::tie(a.z, a.x0, a.x1, a.material, a.y) < std::tie(b.z, b.x0, b.x1, b.material, b.y);
  });
  std::vector<Brick> bricks;
  for (size_t i = 0; i < runs.size();) {
    size_t j = i + 1;
    while (j < runs.size() && runs[j].z == runs[i].z && runs[j].x0 == runs[i].x0 && runs[j].x1 == runs[i].x1 &&
           runs[j].material == runs[i].material && runs[j].y == runs[j - 1].y + 1)
      ++j;
    const Run& a = runs[i];
    const int32_t y1 = runs[j - 1].y;
    const Vec3f lo(float(a.x0), float(a.y), float(a.z)), hi(float(a.x1 + 1), float(y1 + 1), float(a.z + 1));
    Brick b = Brick::box((lo + hi) * (0.5f * voxelSize), (hi - lo) * (0.5f * voxelSize));
    b.material = a.material;
    bricks.push_back(b);
    i = j;
  }
  return bricks;
}

}  // namespace bw
