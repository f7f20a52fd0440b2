#pragma once
/// What a step's edits did to the grids, brick by brick, for something that mirrors the world
/// (the Bullet baseline's chunk compounds, a recording): World::recordEdits(true), then after
/// each step (or World::applyFrameEdits()) World::lastEdits().
///
/// Order: the edit load's placements and removals as made, then the bricks split parts took
/// from their grids (and debris that vanished); `splits` lists the parts' new grids and bodies,
/// each built from its grid as the frame leaves it. Replaying `bricks` in order on a copy of the
/// grids taken before the step (a placement adds `value` under id `brick`, a removal drops the
/// brick with that id) gives the grids after it; ids freed by a removal may be used again by a
/// later placement of the same frame. The log of a step starts with World::removeBricks()' edits
/// and splits made since the previous step. Edits made through World::editGrid() are not in
/// `bricks` (the world does not see them brick by brick): `wholeGrids` names the grids handed
/// out since the previous step, which a mirror takes again whole (after `bricks`).
#include <cstdint>
#include <vector>

#include "collision/bricks/brick.h"

namespace bw {

struct BrickEdit {
  uint32_t grid;    ///< World grid index
  uint32_t brick;   ///< brick id in that grid
  bool placed;      ///< placed (value is the brick) or removed
  Brick value;      ///< the brick placed or removed, as it was
};

struct SplitEdit {
  uint32_t fromGrid;  ///< the grid the part left
  uint32_t grid;      ///< the part's own grid (a new World grid index)
  uint32_t body;      ///< the part's dynamic body (a new World body id)
};

struct EditLog {
  std::vector<BrickEdit> bricks;
  std::vector<SplitEdit> splits;
  std::vector<uint32_t> wholeGrids;  ///< grids edited through World::editGrid(), ascending, each once
  void clear() {
    bricks.clear();
    splits.clear();
    wholeGrids.clear();
  }
};

}  // namespace bw
