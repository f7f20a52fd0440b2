#pragma once
/// A coarse bit grid over a set of world boxes: 64 x 64 x 64 cells over the boxes' joint bounds,
/// a cell's bit set when a box reaches it. It answers "may any box overlap this one?" in a few
/// word tests, without false negatives, so most queries that meet nothing stop there (the edit
/// questions asked once per pair each frame: does this body's box meet a brick just edited?).
#include <array>
#include <cstdint>
#include <vector>

#include "world/broadphase.h"

namespace bw {

class BoxOccupancyBits {
 public:
  static constexpr int kCells = 64;  // per axis; a word is one row of cells along x

  /// Marks the cells every box reaches. Boxes reaching too many rows (more than kRowBudget
  /// per box on average), a coordinate that is not finite or an inverted box switch the filter
  /// off: every query is then a "may".
  void build(const std::vector<WorldAabb>& boxes);
  /// False only when no box built from overlaps `box` (closed intervals, as WorldAabb::overlaps;
  /// a box with a NaN coordinate overlaps nothing, there as here).
  bool mayOverlap(const WorldAabb& box) const;

 private:
  static constexpr int kRowBudget = 16;
  static constexpr int kQueryRows = 64;  // a query reaching more rows goes straight to a "may"
  struct CellRange {
    int lo[3], hi[3];
  };
  /// The cells a box reaches on each axis, clamped to the grid: monotone in each coordinate
  /// (a subtraction, a product by a non-negative constant, a truncation, a clamp), so two
  /// overlapping boxes always have overlapping ranges. Requires finite coordinates.
  CellRange cellsOf(const WorldAabb& box) const;
  int cellOf(double v, int axis) const;

  std::vector<uint64_t> rows_;  // rows_[z * kCells + y], bit x
  WorldAabb bounds_{};  // of all boxes built from; cells start at its min corner
  std::array<double, 3> scale_{};
  bool empty_ = true, off_ = false;
};

}  // namespace bw
