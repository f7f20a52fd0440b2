#pragma once
/// Repeats one build on an X/Y grid of tiles, to turn a real save into a build of the size the
/// article measures (Lighthouse_Island, 25,427 bricks, tiled 10 x 10 = 2,542,700 bricks).
///
///   const bw::BrsLoadResult save = bw::loadBrs(path);
///   const int n = bw::tilesForTarget(save.bricks.size(), 2'500'000);   // 10
///   std::vector<bw::Brick> city = bw::tileBuild(save.bricks, save.bounds, n, n, 4.f);
///
/// Tile (i, j) is the build moved by (i * (bounds.extent().x + gap), j * (bounds.extent().y + gap), 0);
/// tile (0, 0) is the input itself. Output order is tile by tile (i fastest), each tile in input
/// order, so brick k of tile (i, j) is at index (j * tilesX + i) * bricks.size() + k.
/// Offsets are added in double and rounded once to float, so every tile's bricks sit exactly
/// where a direct placement at that offset would put them. tileLights() moves a build's lights
/// by exactly the same offsets in the same order, so lights stay on their tile's bricks.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "collision/bricks/brick.h"
#include "collision/content/build_light.h"
#include "collision/core/aabb.h"

namespace bw {

/// Most bricks tileBuild() will produce (2 GiB of bricks at 32 bytes each).
constexpr uint64_t kMaxTiledBricks = uint64_t(1) << 26;
/// Most tiles per axis accepted by tileBuild() and returned by tilesForTarget().
constexpr int kMaxTilesPerAxis = 4096;

/// Copies `bricks` (whose bounds are `bounds`) onto tilesX x tilesY tiles spaced by the bounds'
/// X/Y extent plus `gap`. Throws InvalidInput when a tile count is outside 1..kMaxTilesPerAxis,
/// gap is not finite or negative, bounds are not finite or inverted (unless bricks is empty),
/// the brick count would exceed kMaxTiledBricks, or a tiled brick would leave the grid-local
/// coordinate range (+-2^30). Nothing is allocated before the checks pass.
std::vector<Brick> tileBuild(std::span<const Brick> bricks, const Aabb& bounds, int tilesX, int tilesY, float gap);

/// The lights of the build tileBuild() tiled: light k of tile (i, j) is at index
/// (j * tilesX + i) * lights.size() + k, moved by that tile's offset (the same double sum,
/// rounded once). `bounds` are the bricks' bounds, the ones given to tileBuild(). Throws
/// InvalidInput like tileBuild() (with kMaxTiledBricks as the light limit); no lights, no output.
std::vector<BuildLight> tileLights(std::span<const BuildLight> lights, const Aabb& bounds, int tilesX, int tilesY, float gap);

/// Tiles per axis n (1..kMaxTilesPerAxis) such that n * n * bricksPerTile is closest to target
/// (ties go to the smaller n). Throws InvalidInput when bricksPerTile or target is 0.
int tilesForTarget(size_t bricksPerTile, size_t target);

}  // namespace bw
