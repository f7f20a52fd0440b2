// Fuzz target: the .brs reader (parseBrs). Any byte string either loads or throws InvalidInput;
// what loads is consistent (counts add up, every brick is a valid brick inside the reported
// bounds) and small loads place into a grid, whose index must then be canonical.
#include "collision/bricks/brick_geometry.h"
#include "collision/bricks/brick_grid.h"
#include "collision/content/brs_reader.h"
#include "collision/core/errors.h"
#include "fuzz/fuzz_support.h"

namespace {

constexpr size_t kGridBricksChecked = 4096;  // larger loads are checked without building a grid

void checkLoaded(const bw::BrsLoadResult& r) {
  FUZZ_CHECK(r.records.size() == r.totalBricks, "%zu records of %u bricks", r.records.size(), r.totalBricks);
  FUZZ_CHECK(r.bricks.size() + r.collisionOff == r.totalBricks, "%zu bricks + %u collision off != %u", r.bricks.size(),
             r.collisionOff, r.totalBricks);
  for (const bw::Brick& b : r.bricks) {
    bw::validateBrick(b, "brs fuzz");  // throws (a finding: not InvalidInput from parseBrs) when bad
    const bw::Aabb box = bw::brickBounds(b);
    FUZZ_CHECK(r.bounds.contains(box), "a brick's bounds lie outside the reported bounds");
  }
  if (r.bricks.empty() || r.bricks.size() > kGridBricksChecked) return;
  bw::BrickGrid grid(bw::BrickGrid::Config(uint32_t(r.bricks.size())));
  grid.placeBricks(r.bricks);
  FUZZ_CHECK(grid.brickCount() == r.bricks.size(), "grid holds %u of %zu bricks", grid.brickCount(), r.bricks.size());
  grid.index().validate();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  bw::BrsLoadResult loaded;
  try {
    loaded = bw::parseBrs(data, size, "fuzz.brs");
  } catch (const bw::InvalidInput&) {
    return 0;  // refused with a message: the documented outcome for a bad file
  } catch (const bw::CapacityExceeded&) {
    return 0;  // more bricks than a grid holds: also refused with a message
  }
  checkLoaded(loaded);
  return 0;
}
