#include "collision/content/build_tiling.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "collision/core/argument_checks.h"
#include "collision/index/octobvh_layout.h"

namespace bw {

namespace {

// The X/Y step between tiles, after every check tileBuild() documents (`context` names the
// caller in errors, `what` the items). Nothing is tiled when perTile is 0, so the bounds are
// checked only when there is something to move.
struct TileSteps {
  double x = 0.0, y = 0.0;
};
TileSteps tileSteps(uint64_t perTile, const Aabb& bounds, int tilesX, int tilesY, float gap, const char* context,
                    const char* what) {
  requireInRange(tilesX, 1, kMaxTilesPerAxis, context, "tilesX");
  requireInRange(tilesY, 1, kMaxTilesPerAxis, context, "tilesY");
  requireFinite(gap, context, "gap");
  if (gap < 0.f) throw InvalidInput(std::string(context) + ": gap is " + std::to_string(gap) + ", expected >= 0");
  // note: with perTile <= 2^26 checked first, perTile * tiles <= 2^26 * 2^24 cannot overflow uint64.
  const uint64_t tiles = uint64_t(tilesX) * uint64_t(tilesY);
  if (perTile > kMaxTiledBricks || perTile * tiles > kMaxTiledBricks)
    throw InvalidInput(std::string(context) + ": " + std::to_string(tilesX) + " x " + std::to_string(tilesY) + " tiles of " +
                       std::to_string(perTile) + " " + what + " exceed the limit of " + std::to_string(kMaxTiledBricks) +
                       " " + what);
  if (perTile == 0) return {};
  requireFinite(bounds.min, context, "bounds.min");
  requireFinite(bounds.max, context, "bounds.max");
  if (bounds.isEmpty()) throw InvalidInput(std::string(context) + ": bounds are inverted (min > max)");

  const double stepX = double(bounds.extent().x()) + double(gap);
  const double stepY = double(bounds.extent().y()) + double(gap);
  // The farthest tile's bounds must stay inside the range every grid index accepts.
  const double reachX = std::max(std::abs(double(bounds.min.x())), std::abs(double(bounds.max.x()) + stepX * (tilesX - 1)));
  const double reachY = std::max(std::abs(double(bounds.min.y())), std::abs(double(bounds.max.y()) + stepY * (tilesY - 1)));
  if (!(reachX < octobvh::kMaxCoordinate) || !(reachY < octobvh::kMaxCoordinate))
    throw InvalidInput(std::string(context) + ": the tiled build reaches beyond the grid-local range +-2^30");
  return {stepX, stepY};
}

// Copies `items` onto every tile, tile by tile (i fastest), moving each position by the tile's
// offset: added in double, rounded once to float.
template <class T>
std::vector<T> tileItems(std::span<const T> items, const TileSteps& step, int tilesX, int tilesY) {
  std::vector<T> out;
  if (items.empty()) return out;
  out.reserve(items.size() * size_t(tilesX) * size_t(tilesY));
  for (int j = 0; j < tilesY; ++j)
    for (int i = 0; i < tilesX; ++i) {
      const double dx = step.x * i, dy = step.y * j;
      for (const T& item : items) {
        T t = item;
        t.position.x() = float(double(item.position.x()) + dx);
        t.position.y() = float(double(item.position.y()) + dy);
        out.push_back(t);
      }
    }
  return out;
}

}  // namespace

std::vector<Brick> tileBuild(std::span<const Brick> bricks, const Aabb& bounds, int tilesX, int tilesY, float gap) {
  const TileSteps step = tileSteps(bricks.size(), bounds, tilesX, tilesY, gap, "tileBuild", "bricks");
  return tileItems(bricks, step, tilesX, tilesY);
}

std::vector<BuildLight> tileLights(std::span<const BuildLight> lights, const Aabb& bounds, int tilesX, int tilesY, float gap) {
  const TileSteps step = tileSteps(lights.size(), bounds, tilesX, tilesY, gap, "tileLights", "lights");
  return tileItems(lights, step, tilesX, tilesY);
}

int tilesForTarget(size_t bricksPerTile, size_t target) {
  if (bricksPerTile == 0) throw InvalidInput("tilesForTarget: bricksPerTile is 0");
  if (target == 0) throw InvalidInput("tilesForTarget: target is 0");
  auto error = [&](int n) {
    const double total = double(n) * double(n) * double(bricksPerTile);
    return std::abs(total - double(target));
  };
  // note: n * n * bricksPerTile grows monotonically in n, so the best n is next to sqrt(target / perTile).
  int n = int(std::floor(std::sqrt(double(target) / double(bricksPerTile))));
  n = std::clamp(n, 1, kMaxTilesPerAxis);
  if (n < kMaxTilesPerAxis && error(n + 1) < error(n)) ++n;
  return n;
}

}  // namespace bw
