// Brick connectivity (collision/bricks/brick_connectivity.h) against brute force: the face
// contact rule, the adjacency after building and placing, and on seeded random grids (unit
// cubes, flat plates, thin rods, far from the grid origin), long sequences of removals and
// carved holes whose detached pieces must be exactly the flood-fill components that left the
// rest; plus the work of a removal that splits nothing against one that cuts a grid in two.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <random>
#include <set>

#include "collision/bricks/brick_connectivity.h"
#include "collision/bricks/brick_geometry.h"

namespace bw {
namespace {

Aabb box(const Vec3f& lo, const Vec3f& hi) { return Aabb{lo, hi}; }

TEST(BrickConnectivity, FacesJoinEdgesAndCornersDoNot) {
  const Aabb a = box({0, 0, 0}, {1, 1, 1});
  EXPECT_TRUE(BrickConnectivity::touches(a, box({1, 0, 0}, {2, 1, 1})));           // face
  EXPECT_TRUE(BrickConnectivity::touches(a, box({1.0005f, 0.5f, 0.2f}, {2, 3, 4})));  // face, gap within tolerance
  EXPECT_FALSE(BrickConnectivity::touches(a, box({1.01f, 0, 0}, {2, 1, 1})));       // gap
  EXPECT_FALSE(BrickConnectivity::touches(a, box({1, 1, 0}, {2, 2, 1})));           // edge
  EXPECT_FALSE(BrickConnectivity::touches(a, box({1, 1, 1}, {2, 2, 2})));           // corner
  EXPECT_TRUE(BrickConnectivity::touches(a, box({0.5f, 0.5f, 0.5f}, {2, 2, 2})));    // overlap
  EXPECT_TRUE(BrickConnectivity::touches(a, box({0.2f, 0.2f, 1}, {0.4f, 0.4f, 1.2f})));  // a rod standing on it
  // Far from the origin float steps are coarser: a face there still joins.
  const Vec3f far(3.0e4f, -2.0e4f, 500.f);
  EXPECT_TRUE(BrickConnectivity::touches(box(far, far + Vec3f(1, 1, 1)), box(far + Vec3f(1.003f, 0, 0), far + Vec3f(2, 1, 1))));
}

// A seeded, connected grid: a lattice of cubes with holes, plates and rods on top and between.
struct Built {
  std::unique_ptr<BrickGrid> grid;
};

std::unique_ptr<BrickGrid> seededGrid(uint32_t seed, int side, const Vec3f& origin) {
  auto grid = std::make_unique<BrickGrid>(BrickGrid::Config(1u << 15));
  std::mt19937 rng{seed};
  for (int x = 0; x < side; ++x)
    for (int y = 0; y < side; ++y)
      for (int z = 0; z < 2; ++z)
        if (rng() % 4 != 0) grid->placeBrick(Brick::box(origin + Vec3f(float(x), float(y), float(z)), Vec3f::Constant(0.5f)));
  for (int k = 0; k < side; ++k) {  // plates on top, some bridging gaps
    const Vec3f p = origin + Vec3f(float(rng() % side), float(rng() % side), 1.6f);
    grid->placeBrick(Brick::box(p, rng() % 2 ? Vec3f(1.5f, 0.5f, 0.1f) : Vec3f(0.5f, 1.5f, 0.1f)));
  }
  for (int k = 0; k < side / 2; ++k)  // thin rods standing on the top layer
    grid->placeBrick(Brick::box(origin + Vec3f(float(rng() % side), float(rng() % side), 2.f), Vec3f(0.1f, 0.1f, 0.5f)));
  return grid;
}

std::vector<uint32_t> liveIds(const BrickGrid& grid) {
  std::vector<uint32_t> ids;
  grid.forEachBrick([&](uint32_t id) { ids.push_back(id); });
  return ids;
}

// Brute-force components of the grid's bricks: label per brick id.
std::map<uint32_t, uint32_t> components(const BrickGrid& grid) {
  const std::vector<uint32_t> ids = liveIds(grid);
  std::map<uint32_t, uint32_t> label;
  uint32_t next = 0;
  for (uint32_t s : ids) {
    if (label.count(s)) continue;
    std::vector<uint32_t> stack = {s};
    label[s] = next;
    while (!stack.empty()) {
      const uint32_t u = stack.back();
      stack.pop_back();
      for (uint32_t v : ids)
        if (!label.count(v) && BrickConnectivity::touches(brickBounds(grid.brick(u)), brickBounds(grid.brick(v)))) {
          label[v] = next;
          stack.push_back(v);
        }
    }
    ++next;
  }
  return label;
}

// Keep only the largest component (the test's grids start in one piece).
void keepLargest(BrickGrid& grid) {
  const auto label = components(grid);
  std::map<uint32_t, uint32_t> size;
  for (const auto& [id, l] : label) ++size[l];
  uint32_t best = 0;
  for (const auto& [l, n] : size)
    if (n > size[best]) best = l;
  for (const auto& [id, l] : label)
    if (l != best) grid.removeBrick(id);
}

void expectAdjacencyIsBruteForce(const BrickGrid& grid, const BrickConnectivity& links) {
  const std::vector<uint32_t> ids = liveIds(grid);
  for (uint32_t a : ids) {
    std::set<uint32_t> want, got(links.neighbours(a).begin(), links.neighbours(a).end());
    for (uint32_t b : ids)
      if (a != b && BrickConnectivity::touches(brickBounds(grid.brick(a)), brickBounds(grid.brick(b)))) want.insert(b);
    ASSERT_EQ(got, want) << "neighbours of brick " << a;
    ASSERT_EQ(got.size(), links.neighbours(a).size()) << "a neighbour listed twice";
  }
}

TEST(BrickConnectivity, AdjacencyIsBruteForceAfterBuildingAndPlacing) {
  for (uint32_t seed : {1u, 2u}) {
    auto grid = seededGrid(seed, 10, seed == 1 ? Vec3f(0, 0, 0) : Vec3f(3.0e4f, -2.0e4f, 500.f));
    BrickConnectivity links(*grid);
    expectAdjacencyIsBruteForce(*grid, links);
    std::mt19937 rng{seed};
    for (int k = 0; k < 60; ++k) {
      const std::vector<uint32_t> ids = liveIds(*grid);
      Brick b = grid->brick(ids[rng() % ids.size()]);
      b.position.z() += brickBounds(b).extent().z();
      links.placed(*grid, grid->placeBrick(b));
    }
    expectAdjacencyIsBruteForce(*grid, links);
  }
}

// Removals (single bricks and holes), each followed by the detached pieces' removal, checked
// against the flood fill: every piece is a whole component, the rest is one.
TEST(BrickConnectivity, DetachedPiecesAreExactlyTheComponentsThatLeftTheRest) {
  uint32_t totalPieces = 0, steps = 0;
  for (uint32_t seed : {3u, 4u, 5u, 6u, 7u, 8u}) {
    auto grid = seededGrid(seed, 16, seed >= 7 ? Vec3f(3.0e4f, -2.0e4f, 500.f) : Vec3f(-40.f, 7.f, 2.f));
    keepLargest(*grid);
    BrickConnectivity links(*grid);
    std::mt19937 rng{seed * 7};
    std::vector<uint32_t> seeds;
    std::vector<std::vector<uint32_t>> pieces;
    int fullChecks = 0;
    while (grid->brickCount() > 10) {
      const std::vector<uint32_t> ids = liveIds(*grid);
      std::vector<uint32_t> cut = {ids[rng() % ids.size()]};
      if (rng() % 4 == 0)  // a hole: the bricks within 1.6 of a random one
        for (uint32_t id : ids)
          if (id != cut[0] && (grid->brick(id).position - grid->brick(cut[0]).position).norm() < 1.6f) cut.push_back(id);
      seeds.clear();
      for (uint32_t id : cut) links.removing(id, seeds);
      for (uint32_t id : cut) grid->removeBrick(id);
      pieces.clear();
      links.detached(seeds, pieces);
      const auto label = components(*grid);
      std::map<uint32_t, std::set<uint32_t>> byLabel;
      for (const auto& [id, l] : label) byLabel[l].insert(id);
      ASSERT_EQ(byLabel.size(), pieces.size() + (grid->brickCount() > 0 ? 1u : 0u))
          << "seed " << seed << " step " << steps << ": " << pieces.size() << " pieces reported";
      for (const std::vector<uint32_t>& piece : pieces) {
        const std::set<uint32_t> set(piece.begin(), piece.end());
        ASSERT_EQ(set.size(), piece.size()) << "a brick twice in one piece";
        ASSERT_EQ(byLabel.at(label.at(piece[0])), set) << "a piece is not a whole component";
      }
      // The pieces leave the grid (as the world moves them into bodies of their own), their
      // links taken over renumbered: the brute-force adjacency of their own grid, and what stays
      // behind that of the grid left.
      for (const std::vector<uint32_t>& piece : pieces) {
        BrickGrid part(BrickGrid::Config(uint32_t(piece.size() + 16)));
        const std::vector<uint32_t> ids = grid->moveBricks(piece, part);
        const BrickConnectivity partLinks(links, piece, ids);
        expectAdjacencyIsBruteForce(part, partLinks);
        part.index().validate();
      }
      if (!pieces.empty() && fullChecks < 4) {  // (quadratic: the first few splits of each grid)
        ++fullChecks;
        grid->index().validate();
        expectAdjacencyIsBruteForce(*grid, links);
      }
      totalPieces += uint32_t(pieces.size());
      ++steps;
    }
  }
  EXPECT_GT(totalPieces, 30u) << "the sequences must split the grids often";
  std::printf("[ connectivity ] %u removals and holes, %u pieces detached\n", steps, totalPieces);
  EXPECT_GT(steps, 200u);
}

TEST(BrickConnectivity, ARemovalThatSplitsNothingVisitsFewBricksAndACutWalksOnlyTheSmallerSide) {
  // A solid 40 x 40 x 2 slab of cubes: a brick out of its middle.
  auto slab = std::make_unique<BrickGrid>(BrickGrid::Config(1u << 14));
  for (int x = 0; x < 40; ++x)
    for (int y = 0; y < 40; ++y)
      for (int z = 0; z < 2; ++z) slab->placeBrick(Brick::box(Vec3f(float(x), float(y), float(z)), Vec3f::Constant(0.5f)));
  BrickConnectivity links(*slab);
  uint32_t middle = 0;
  slab->forEachBrick([&](uint32_t id) {
    if (slab->brick(id).position == Vec3f(20, 20, 1)) middle = id;
  });
  std::vector<uint32_t> seeds;
  links.removing(middle, seeds);
  slab->removeBrick(middle);
  std::vector<std::vector<uint32_t>> pieces;
  ConnectivityStats st;
  links.detached(seeds, pieces, &st);
  EXPECT_TRUE(pieces.empty());
  EXPECT_LT(st.visited, 100u) << "of 3199 bricks";
  // Two blocks joined by one bar of bricks: cutting the bar walks the small block, not the big one.
  auto two = std::make_unique<BrickGrid>(BrickGrid::Config(1u << 15));
  for (int x = 0; x < 60; ++x)
    for (int y = 0; y < 60; ++y) two->placeBrick(Brick::box(Vec3f(float(x), float(y), 0), Vec3f::Constant(0.5f)));  // big: 3600
  for (int x = 60; x < 64; ++x) two->placeBrick(Brick::box(Vec3f(float(x), 30, 0), Vec3f::Constant(0.5f)));        // the bar
  for (int x = 64; x < 74; ++x)
    for (int y = 25; y < 35; ++y) two->placeBrick(Brick::box(Vec3f(float(x), float(y), 0), Vec3f::Constant(0.5f)));  // small: 100
  BrickConnectivity joined(*two);
  uint32_t bar = 0;
  two->forEachBrick([&](uint32_t id) {
    if (two->brick(id).position == Vec3f(62, 30, 0)) bar = id;
  });
  seeds.clear();
  joined.removing(bar, seeds);
  two->removeBrick(bar);
  pieces.clear();
  joined.detached(seeds, pieces, &st);
  ASSERT_EQ(pieces.size(), 1u);
  EXPECT_EQ(pieces[0].size(), 101u) << "the small block and the bar's last brick";
  EXPECT_LT(st.visited, 2u * 101u + 64u + 10u) << "the big block is never walked (of its 3600, at most one turn's 64)";
}

}  // namespace
}  // namespace bw
