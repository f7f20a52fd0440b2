#include "collision/content/build_tiling.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "collision/core/argument_checks.h"
#include "collision/index/octobvh_layout.h"

namespace bw {

std::vector<Brick> tileBuild(std::span<const Brick> bricks, const Aabb& bounds, int tilesX, int tilesY, float gap) {
  constexpr const char* kContext = "tileBuild";
  requireInRange(tilesX, 1, kMaxTilesPerAxis, kContext, "tilesX");
  requireInRange(tilesY, 1, kMaxTilesPerAxis, kContext, "tilesY");
  requireFinite(gap, kContext, "gap");
  if (gap < 0.f) throw InvalidInput(std::string(kContext) + ": gap is " + std::to_string(gap) + ", expected >= 0");
  // note: with perTile <= 2^26 checked first, perTile * tiles <= 2^26 * 2^24 cannot overflow uint64.
  const uint64_t perTile = bricks.size();
  const uint64_t tiles = uint64_t(tilesX) * uint64_t(tilesY);
  if (perTile > kMaxTiledBricks || perTile * tiles > kMaxTiledBricks)
    throw InvalidInput(std::string(kContext) + ": " + std::to_string(tilesX) + " x " + std::to_string(tilesY) +
                       " tiles of " + std::to_string(perTile) + " bricks exceed the limit of " +
                       std::to_string(kMaxTiledBricks) + " bricks");
  if (perTile == 0) return {};
  requireFinite(bounds.min, kContext, "bounds.min");
  requireFinite(bounds.max, kContext, "bounds.max");
  if (bounds.isEmpty()) throw InvalidInput(std::string(kContext) + ": bounds are inverted (min > max)");

  const double stepX = double(bounds.extent().x()) + double(gap);
  const double stepY = double(bounds.extent().y()) + double(gap);
  // The farthest tile's bounds must stay inside the range every grid index accepts.
  const double reachX = std::max(std::abs(double(bounds.min.x())), std::abs(double(bounds.max.x()) + stepX * (tilesX - 1)));
  const double reachY = std::max(std::abs(double(bounds.min.y())), std::abs(double(bounds.max.y()) + stepY * (tilesY - 1)));
  if (!(reachX < octobvh::kMaxCoordinate) || !(reachY < octobvh::kMaxCoordinate))
    throw InvalidInput(std::string(kContext) + ": the tiled build reaches beyond the grid-local range +-2^30");

  std::vector<Brick> out;
  out.reserve(size_t(perTile * tiles));
  for (int j = 0; j < tilesY; ++j)
    for (int i = 0; i < tilesX; ++i) {
      const double dx = stepX * i, dy = stepY * j;
      for (const Brick& b : bricks) {
        Brick t = b;
        t.position.x() = float(double(b.position.x()) + dx);
        t.position.y() = float(double(b.position.y()) + dy);
        out.push_back(t);
      }
    }
  return out;
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
