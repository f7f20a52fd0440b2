// BulletChunkedGrid (collision/bricks/bullet_chunked_grid.h) against brute force: after seeded
// random placements and removals (ids freed and used again, bricks from 0.2 to 8 m, far from
// the origin), every chunk holds exactly the bricks whose centre lies in its cube, each as a
// child at the brick's place with its shared shape, and each chunk's box equals the one Bullet
// recalculates from its children (never smaller: a child outside it would be missed; never
// larger after finishEdits: the recalculation was not skipped where it mattered).
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "collision/bricks/bullet_chunked_grid.h"
#include "collision/core/errors.h"
#include "collision/core/seeded_random.h"

namespace bw {
namespace {

Brick randomBrick(SeededRandom& r, const Vec3f& centre) {
  const float size = float(r.logUniform(0.1, 4.0));
  Brick b = Brick::box(centre + Vec3f(float(r.uniform(-40, 40)), float(r.uniform(-40, 40)), float(r.uniform(-20, 20))),
                       Vec3f(size, float(r.logUniform(0.1, 4.0)), float(r.logUniform(0.1, 1.0))));
  b.shape = BrickShape(r.below(4));
  b.rotation = AxisRotation::fromIndex(int(r.below(24)));
  return b;
}

// Every chunk against the bricks live in its cube, and its box against a fresh recalculation.
void expectMatches(const BulletChunkedGrid& chunks, const std::map<uint32_t, Brick>& live, float chunkSize) {
  std::map<BulletChunkCell, std::multiset<std::tuple<float, float, float>>> want;
  for (const auto& [id, b] : live) want[bulletChunkCell(b.position, chunkSize)].insert({b.position.x(), b.position.y(), b.position.z()});
  uint64_t held = 0;
  for (const BulletBrickChunk& c : chunks.chunks()) {
    ASSERT_EQ(uint32_t(c.shape->getNumChildShapes()), c.bricks);
    held += c.bricks;
    if (c.bricks == 0) continue;
    const BulletChunkCell cell = bulletChunkCell(c.origin, chunkSize);
    std::multiset<std::tuple<float, float, float>> got;
    for (int k = 0; k < c.shape->getNumChildShapes(); ++k) {
      const btVector3 p = c.shape->getChildTransform(k).getOrigin();
      got.insert({p.x() + c.origin.x(), p.y() + c.origin.y(), p.z() + c.origin.z()});
    }
    // Child positions are relative to the chunk origin: compare within float rounding.
    const auto& expected = want[cell];
    ASSERT_EQ(got.size(), expected.size());
    auto g = got.begin();
    for (auto e = expected.begin(); e != expected.end(); ++e, ++g) {
      EXPECT_NEAR(std::get<0>(*g), std::get<0>(*e), 1e-3f);
      EXPECT_NEAR(std::get<1>(*g), std::get<1>(*e), 1e-3f);
      EXPECT_NEAR(std::get<2>(*g), std::get<2>(*e), 1e-3f);
    }
    btVector3 lo, hi, freshLo, freshHi;
    c.shape->getAabb(btTransform::getIdentity(), lo, hi);
    btCompoundShape fresh(false);
    for (int k = 0; k < c.shape->getNumChildShapes(); ++k) fresh.addChildShape(c.shape->getChildTransform(k), c.shape->getChildShape(k));
    fresh.getAabb(btTransform::getIdentity(), freshLo, freshHi);
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(lo[a], freshLo[a], 1e-3f) << "chunk box side " << a;
      EXPECT_NEAR(hi[a], freshHi[a], 1e-3f) << "chunk box side " << a;
    }
  }
  EXPECT_EQ(held, live.size());
  EXPECT_EQ(chunks.brickCount(), live.size());
}

TEST(BulletChunkedGrid, RandomEditsKeepEveryChunkEqualToBruteForce) {
  for (const Vec3f& centre : {Vec3f(0, 0, 0), Vec3f(20000, -15000, 300)}) {
    SeededRandom r(centre.x() == 0 ? 5 : 6);
    BrickGrid grid(BrickGrid::Config(4096));
    std::map<uint32_t, Brick> live;
    for (int i = 0; i < 600; ++i) {
      const Brick b = randomBrick(r, centre);
      live[grid.placeBrick(b)] = b;
    }
    BulletBrickShapes shapes;
    const float chunkSize = 16.f;
    BulletChunkedGrid chunks(grid, chunkSize, shapes);
    expectMatches(chunks, live, chunkSize);
    for (int frame = 0; frame < 30; ++frame) {
      // Removals first and then placements, so a freed id is taken again in the same frame.
      for (int k = 0; k < 25 && !live.empty(); ++k) {
        auto it = live.begin();
        std::advance(it, r.below(uint32_t(live.size())));
        chunks.remove(it->first);
        grid.removeBrick(it->first);
        live.erase(it);
      }
      for (int k = 0; k < int(r.below(40)); ++k) {
        const Brick b = randomBrick(r, centre);
        const uint32_t id = grid.placeBrick(b);
        chunks.place(id, b);
        live[id] = b;
      }
      chunks.finishEdits();
      expectMatches(chunks, live, chunkSize);
    }
    // Empty it: every chunk ends empty and nothing is held.
    for (const auto& [id, b] : live) chunks.remove(id);
    live.clear();
    chunks.finishEdits();
    expectMatches(chunks, live, chunkSize);
  }
}

TEST(BulletChunkedGrid, RefusesUnknownAndDuplicateIds) {
  BrickGrid grid(BrickGrid::Config(16));
  const Brick b = Brick::box(Vec3f(1, 2, 3), Vec3f(0.5f, 0.5f, 0.5f));
  const uint32_t id = grid.placeBrick(b);
  BulletBrickShapes shapes;
  BulletChunkedGrid chunks(grid, 8.f, shapes);
  EXPECT_THROW(chunks.place(id, b), InvalidInput);
  EXPECT_THROW(chunks.remove(id + 1), InvalidInput);
  EXPECT_THROW(chunks.remove(1000000), InvalidInput);
  chunks.remove(id);
  EXPECT_THROW(chunks.remove(id), InvalidInput);
  EXPECT_EQ(chunks.brickCount(), 0u);
  EXPECT_THROW(BulletChunkedGrid(grid, -1.f, shapes), InvalidInput);
}

}  // namespace
}  // namespace bw
