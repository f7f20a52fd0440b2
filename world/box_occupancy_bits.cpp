#include "world/box_occupancy_bits.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bw {

int BoxOccupancyBits::cellOf(double v, int axis) const {
  const double t = (v - bounds_.min[axis]) * scale_[axis];
  // note: compared as doubles first: a box far outside the built bounds (a query) must not
  // overflow the conversion.
  return t <= 0.0 ? 0 : t >= double(kCells - 1) ? kCells - 1 : int(t);
}

BoxOccupancyBits::CellRange BoxOccupancyBits::cellsOf(const WorldAabb& box) const {
  CellRange r;
  for (int k = 0; k < 3; ++k) {
    r.lo[k] = cellOf(box.min[k], k);
    r.hi[k] = cellOf(box.max[k], k);
  }
  return r;
}

void BoxOccupancyBits::build(const std::vector<WorldAabb>& boxes) {
  empty_ = boxes.empty();
  off_ = false;
  if (empty_) return;
  Vec3d lo = boxes[0].min, hi = boxes[0].max;
  for (const WorldAabb& b : boxes) {
    // note: an inverted box (min above max) still overlaps some boxes by WorldAabb::overlaps'
    // rule, which cells cannot express: it too leaves the filter off.
    if (!b.min.allFinite() || !b.max.allFinite() || (b.min.array() > b.max.array()).any()) off_ = true;
    lo = lo.cwiseMin(b.min);
    hi = hi.cwiseMax(b.max);
  }
  bounds_ = {lo, hi};
  if (off_) {  // the joint bounds must then let everything through
    bounds_ = {Vec3d::Constant(-std::numeric_limits<double>::infinity()), Vec3d::Constant(std::numeric_limits<double>::infinity())};
    return;
  }
  for (int k = 0; k < 3; ++k) {
    scale_[k] = hi[k] > lo[k] ? double(kCells) / (hi[k] - lo[k]) : 0.0;
    // A span beyond double's reach leaves the filter off rather than guessing.
    if (!std::isfinite(scale_[k])) off_ = true;
  }
  if (off_) return;
  rows_.assign(size_t(kCells) * kCells, 0);
  size_t rows = 0;
  for (const WorldAabb& b : boxes) {
    const CellRange r = cellsOf(b);
    rows += size_t(r.hi[1] - r.lo[1] + 1) * size_t(r.hi[2] - r.lo[2] + 1);
    if (rows > kRowBudget * boxes.size()) {
      off_ = true;
      return;
    }
    const uint64_t bits = (~0ull >> (63 - (r.hi[0] - r.lo[0]))) << r.lo[0];
    for (int z = r.lo[2]; z <= r.hi[2]; ++z)
      for (int y = r.lo[1]; y <= r.hi[1]; ++y) rows_[size_t(z) * kCells + size_t(y)] |= bits;
  }
}

bool BoxOccupancyBits::mayOverlap(const WorldAabb& box) const {
  // note: also false for a NaN coordinate, as every comparison with it is.
  if (empty_ || !bounds_.overlaps(box)) return false;
  if (off_) return true;
  const CellRange r = cellsOf(box);
  for (int k = 0; k < 3; ++k)
    if (r.hi[k] < r.lo[k]) return true;  // an inverted query: left to the exact test
  if ((r.hi[1] - r.lo[1] + 1) * (r.hi[2] - r.lo[2] + 1) > kQueryRows) return true;
  const uint64_t bits = (~0ull >> (63 - (r.hi[0] - r.lo[0]))) << r.lo[0];
  for (int z = r.lo[2]; z <= r.hi[2]; ++z)
    for (int y = r.lo[1]; y <= r.hi[1]; ++y)
      if (rows_[size_t(z) * kCells + size_t(y)] & bits) return true;
  return false;
}

}  // namespace bw
