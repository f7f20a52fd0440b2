// Render chunks that follow edits and splits (world/render_chunks.h): after any sequence of
// brick placements and removals, every body holding a grid carries exactly one visible
// primitive per non-empty cell, whose box is the union of that cell's bricks, against a brute
// force that recomputes every cell from scratch; hidden primitives are reused, so the store never
// holds more primitives than were ever visible at once. Then at the world level: scenes that
// split grids into bodies, break slabs off terrain and edit a moving grid every frame keep a
// render scene equal to the world (every proxy where its body and chunk say, emptied chunks
// hidden), identical for any thread count.
// Labelled `concurrency`: the world runs its render thread beside its workers (TSan in CI).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "collision/bricks/brick_geometry.h"
#include "collision/core/argument_checks.h"
#include "transforms/attachment_math.h"
#include "world/render_chunks.h"
#include "world/scene_file.h"
#include "world/world.h"

namespace bw {
namespace {

// One chunk as an attachment carries it: the box centre and the box around it.
struct Chunk {
  Vec3f centre;
  Aabb local;
  bool operator<(const Chunk& o) const {
    const auto key = [](const Chunk& c) {
      return std::make_tuple(c.centre.x(), c.centre.y(), c.centre.z(), c.local.min.x(), c.local.min.y(), c.local.min.z(),
                             c.local.max.x(), c.local.max.y(), c.local.max.z());
    };
    return key(*this) < key(o);
  }
  bool operator==(const Chunk& o) const { return !(*this < o) && !(o < *this); }
};

// Brute force: every brick's box into the cell of its centre, from scratch.
std::vector<Chunk> bruteChunks(const BrickGrid& grid, float chunk) {
  std::map<std::tuple<int64_t, int64_t, int64_t>, Aabb> cells;
  grid.forEachBrick([&](uint32_t id) {
    const Aabb box = brickBounds(grid.brick(id));
    const Vec3f c = box.center();
    const auto key = std::make_tuple(int64_t(std::floor(double(c.x()) / chunk)), int64_t(std::floor(double(c.y()) / chunk)),
                                     int64_t(std::floor(double(c.z()) / chunk)));
    auto [it, fresh] = cells.try_emplace(key, box);
    if (!fresh) it->second.merge(box);
  });
  std::vector<Chunk> out;
  for (const auto& [key, box] : cells) {
    const Vec3f c = box.center();
    out.push_back({c, Aabb{box.min - c, box.max - c}});
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The visible primitives riding on body.
std::vector<Chunk> visibleChunks(const AttachmentStore& store, uint32_t body) {
  std::vector<Chunk> out;
  for (uint32_t id = 0; id < store.size(); ++id)
    if (store.kind(id) == AttachmentKind::Primitive && store.body(id) == body && !store.localBounds(id).isEmpty())
      out.push_back({store.localTranslation(id), store.localBounds(id)});
  std::sort(out.begin(), out.end());
  return out;
}

uint32_t visiblePrimitives(const AttachmentStore& store) {
  uint32_t n = 0;
  for (uint32_t id = 0; id < store.size(); ++id) n += store.kind(id) == AttachmentKind::Primitive && !store.localBounds(id).isEmpty();
  return n;
}

// A seeded brick: sizes 0.2 to 40, a few giants, some with no filter bits (drawn, never found
// by the index), some on exact cell edges.
Brick randomBrick(std::mt19937& rng, const Vec3f& origin, float spread) {
  std::uniform_real_distribution<float> u(-spread, spread);
  std::uniform_int_distribution<int> kind(0, 19);
  const int k = kind(rng);
  Vec3f half = Vec3f::Constant(0.1f + std::uniform_real_distribution<float>(0, 1.5f)(rng));
  if (k == 0) half = Vec3f(20.f, 0.1f, 3.f);  // a thin giant plate
  if (k == 1) half = Vec3f(0.1f, 0.1f, 0.1f);
  Vec3f p = origin + Vec3f(u(rng), u(rng), u(rng));
  if (k == 2) p = origin + Vec3f(std::round(p.x() - origin.x()), std::round(p.y() - origin.y()), 0.f);  // centres on cell edges
  Brick b = Brick::box(p, half);
  if (k == 3) b.filter = 0;
  if (k == 4) b.rotation = AxisRotation::fromIndex(5);
  return b;
}

TEST(RenderChunks, FollowRandomEditsExactlyAndReuseHiddenChunks) {
  for (const Vec3f& origin : {Vec3f(0, 0, 0), Vec3f(3e4f, -2e4f, 500.f)}) {
    for (uint32_t seed : {1u, 2u, 3u}) {
      std::mt19937 rng(seed);
      const float chunk = seed == 3 ? 0.5f : 4.f;
      std::vector<std::unique_ptr<BrickGrid>> grids;
      grids.push_back(std::make_unique<BrickGrid>());
      BrickGrid& grid = *grids[0];
      std::vector<uint32_t> live;
      for (int i = 0; i < 400; ++i) live.push_back(grid.placeBrick(randomBrick(rng, origin, 12.f)));
      AttachmentStore store;
      RenderChunks chunks(chunk);
      store.addPrimitive(0, kInvalidIndex, Vec3f::Zero(), Quatf::Identity(), Aabb{Vec3f::Zero(), Vec3f::Zero()});  // another body's
      chunks.addHolder(0, grid, 1, store);
      chunks.addHolder(0, grid, 2, store);  // a copy holds the same grid
      ASSERT_EQ(visibleChunks(store, 1), bruteChunks(grid, chunk));
      uint32_t peak = visiblePrimitives(store);
      uint32_t recomputed = 0;
      for (int round = 0; round < 60; ++round) {
        // Mostly removals early (cells empty), then mostly placements (hidden chunks come back).
        const int removals = round < 30 ? 25 : 5, placements = round < 30 ? 5 : 25;
        for (int r = 0; r < removals && !live.empty(); ++r) {
          const size_t k = std::uniform_int_distribution<size_t>(0, live.size() - 1)(rng);
          chunks.removing(0, grid.brick(live[k]));
          grid.removeBrick(live[k]);
          live[k] = live.back();
          live.pop_back();
        }
        for (int p = 0; p < placements; ++p) {
          live.push_back(grid.placeBrick(randomBrick(rng, origin, 12.f)));
          chunks.placed(0, grid.brick(live.back()));
        }
        if (round == 45) {  // an edit not reported brick by brick
          for (int r = 0; r < 10 && !live.empty(); ++r) {
            grid.removeBrick(live.back());
            live.pop_back();
          }
          chunks.gridChanged(0);
        }
        const RenderChunkStats stats = chunks.refresh(grids, store);
        recomputed += stats.cellsRecomputed;
        const std::vector<Chunk> expected = bruteChunks(grid, chunk);
        ASSERT_EQ(visibleChunks(store, 1), expected) << "seed " << seed << " round " << round;
        ASSERT_EQ(visibleChunks(store, 2), expected) << "seed " << seed << " round " << round;
        peak = std::max(peak, visiblePrimitives(store));
        ASSERT_EQ(store.primitiveCount(), peak) << "a hidden chunk was not reused";
      }
      EXPECT_GT(recomputed, 0u) << "no removal ever took a face's last brick";
      EXPECT_GT(chunks.hiddenCount() + visiblePrimitives(store), 0u);
    }
  }
}

// A frame that fills a new cell before it empties another (touch order) reuses the emptied
// cell's primitive: hiding runs before any cell takes one, across grids too.
TEST(RenderChunks, AFrameThatFillsOneCellAndEmptiesAnotherDoesNotGrowTheStore) {
  std::vector<std::unique_ptr<BrickGrid>> grids;
  for (int i = 0; i < 2; ++i) grids.push_back(std::make_unique<BrickGrid>());
  const uint32_t a = grids[0]->placeBrick(Brick::box(Vec3f(0.5f, 0.5f, 0.5f), Vec3f::Constant(0.25f)));
  grids[1]->placeBrick(Brick::box(Vec3f(0.5f, 0.5f, 0.5f), Vec3f::Constant(0.25f)));
  const uint32_t b = grids[1]->placeBrick(Brick::box(Vec3f(5.5f, 0.5f, 0.5f), Vec3f::Constant(0.25f)));
  AttachmentStore store;
  RenderChunks chunks(1.f);
  chunks.addHolder(0, *grids[0], 0, store);
  chunks.addHolder(1, *grids[1], 1, store);
  ASSERT_EQ(store.primitiveCount(), 3u);
  // Grid 0 (refreshed first) gains a cell; grid 1 loses one; then grid 1 itself both gains and
  // loses one, gaining first.
  chunks.placed(0, grids[0]->brick(grids[0]->placeBrick(Brick::box(Vec3f(3.5f, 0.5f, 0.5f), Vec3f::Constant(0.25f)))));
  chunks.removing(1, grids[1]->brick(b));
  grids[1]->removeBrick(b);
  chunks.refresh(grids, store);
  EXPECT_EQ(store.primitiveCount(), 3u);
  EXPECT_EQ(visibleChunks(store, 0), bruteChunks(*grids[0], 1.f));
  EXPECT_EQ(visibleChunks(store, 1), bruteChunks(*grids[1], 1.f));
  chunks.placed(1, grids[1]->brick(grids[1]->placeBrick(Brick::box(Vec3f(8.5f, 0.5f, 0.5f), Vec3f::Constant(0.25f)))));
  chunks.removing(0, grids[0]->brick(a));
  grids[0]->removeBrick(a);
  chunks.refresh(grids, store);
  EXPECT_EQ(store.primitiveCount(), 3u);
  EXPECT_EQ(visibleChunks(store, 0), bruteChunks(*grids[0], 1.f));
  EXPECT_EQ(visibleChunks(store, 1), bruteChunks(*grids[1], 1.f));
}

TEST(RenderChunks, BadInputIsRefused) {
  EXPECT_THROW(RenderChunks(0.f), InvalidInput);
  EXPECT_THROW(RenderChunks(std::nanf("")), InvalidInput);
  AttachmentStore store;
  const uint32_t lamp = store.addLight(0, kInvalidIndex, Vec3f::Zero(), Quatf::Identity(), 3.f);
  const uint32_t hull = store.addPrimitive(0, kInvalidIndex, Vec3f::Zero(), Quatf::Identity(), Aabb{-Vec3f::Ones(), Vec3f::Ones()});
  store.addPrimitive(0, hull, Vec3f::Zero(), Quatf::Identity(), Aabb{-Vec3f::Ones(), Vec3f::Ones()});
  EXPECT_THROW(store.setPrimitiveBounds(lamp, Aabb::empty()), InvalidInput);
  EXPECT_THROW(store.setPrimitiveBounds(99, Aabb::empty()), InvalidInput);
  EXPECT_THROW(store.setPrimitiveBounds(hull, Aabb{Vec3f::Constant(std::nanf("")), Vec3f::Ones()}), InvalidInput);
  EXPECT_THROW(store.rebindPrimitive(hull, 1, Vec3f::Zero(), Quatf::Identity(), Aabb::empty()), InvalidInput) << "it carries a child";
  EXPECT_THROW(store.rebindPrimitive(2, 1, Vec3f::Zero(), Quatf::Identity(), Aabb::empty()), InvalidInput) << "it rides on a parent";
  store.setPrimitiveBounds(hull, Aabb::empty());
  EXPECT_TRUE(store.localBounds(hull).isEmpty());
  // A hidden primitive's record: zero extent at its origin, never the infinities of its corners.
  EXPECT_TRUE(store.localBounds(hull).min.allFinite() && store.localBounds(hull).max.allFinite());
  const WorldBounds b = makeWorldBounds(store.localBounds(hull), makeWorldMatrix(Vec3d(1, 2, 3), Quatf(Eigen::AngleAxisf(0.7f, Vec3f::UnitZ()))));
  EXPECT_EQ(b.origin, Vec3d(1, 2, 3));
  EXPECT_EQ(b.extent, Vec3f::Zero());
  EXPECT_EQ(b.radius, 0.f);
}

// The render scene equals the world: every attachment at its body's shape pose composed with
// its offset, hidden ones invisible; the world's grid bodies carry exactly their grids' chunks.
void expectRenderFollowsWorld(World& world) {
  const RenderScene& scene = world.renderScene();
  const AttachmentStore& store = world.render()->store();
  const BodyStore& bodies = world.bodies();
  ASSERT_EQ(scene.primitiveCount(), store.primitiveCount());
  for (uint32_t id = 0; id < store.size(); ++id) {
    if (store.kind(id) != AttachmentKind::Primitive) continue;
    ASSERT_LT(store.body(id), bodies.size());
    const RigidTransform body = bodies.shapePose(store.body(id));
    Vec3d t;
    Quatf r;
    composeAttachmentPose(body.translation, body.rotation, store.localTranslation(id), store.localRotation(id), t, r);
    const WorldMatrix m = makeWorldMatrix(t, r);
    const uint32_t rid = store.renderId(id);
    ASSERT_EQ(scene.visible(rid), !store.localBounds(id).isEmpty()) << "proxy " << rid;
    if (!scene.visible(rid)) continue;  // a hidden proxy is not sent again while it stays hidden
    ASSERT_EQ(std::memcmp(&scene.localToWorldTranslation(rid), &m.translation, sizeof(Vec3d)), 0) << "proxy " << rid;
    const WorldBounds b = makeWorldBounds(store.localBounds(id), m);
    ASSERT_EQ(std::memcmp(&scene.boundsOrigin(rid), &b.origin, sizeof(Vec3d)), 0) << "proxy " << rid;
    ASSERT_EQ(std::memcmp(&scene.boundsExtent(rid), &b.extent, sizeof(Vec3f)), 0) << "proxy " << rid;
  }
  const float chunk = world.scene().attachments.renderChunk;
  for (uint32_t body = 0; body < bodies.size(); ++body) {
    if (!bodies.shape[body].isGrid()) {
      EXPECT_EQ(visibleChunks(store, body).size(), 1u) << "body " << body;
      continue;
    }
    ASSERT_EQ(visibleChunks(store, body), bruteChunks(world.grid(bodies.shape[body].grid), chunk))
        << "body " << body << " (" << world.gridName(bodies.shape[body].grid) << ")";
  }
}

struct RunResult {
  uint64_t stateHash = 0, renderHash = 0;
  uint32_t bodies = 0, splits = 0, primitives = 0, hidden = 0, recomputed = 0;
};

RunResult runAndCheck(const SceneDescription& scene, int threads, SubmissionMode mode, int checkEvery) {
  World world(scene, threads, mode);
  RunResult r;
  for (uint32_t f = 0; f < scene.settings.frames; ++f) {
    world.step();
    r.splits += world.lastStats().splits + world.lastStats().terrainParts;
    r.hidden += world.lastStats().renderChunks.chunksHidden;
    r.recomputed += world.lastStats().renderChunks.cellsRecomputed;
    if ((f + 1) % checkEvery == 0) expectRenderFollowsWorld(world);
    if (::testing::Test::HasFatalFailure()) return r;
  }
  expectRenderFollowsWorld(world);
  r.stateHash = world.stateHash();
  r.renderHash = world.renderScene().stateHash();
  r.bodies = world.bodies().size();
  r.primitives = world.render()->store().primitiveCount();
  return r;
}

// Demolition with attachments: a house losing bricks and holes until parts break off.
SceneDescription demolitionWithAttachments(uint32_t frames) {
  return parseScene(R"({
    "name": "demolition_rendered", "settings": {"frames": )" + std::to_string(frames) + R"(},
    "grids": [
      {"name": "yard", "bricks": [{"position": [0, 0, -0.25], "half_size": [40, 40, 0.25]}]},
      {"name": "house", "generator": "house", "scale": 0.6, "seed": 3, "position": [0, 0, 0.01], "split": true, "debris_bricks": 3}
    ],
    "edits": [{"grid": "house", "kind": "remove", "per_frame": 6, "seed": 5},
              {"grid": "house", "kind": "carve", "radius": 0.8, "every": 4, "seed": 6}],
    "spawners": [{"shape": "box", "count": 10, "half_extents": [0.2, 0.2, 0.2], "region": {"min": [-3, -3, 6], "max": [3, 3, 9]}, "seed": 2}],
    "attachments": {"render_chunk": 1.5}
  })",
                    "demolition_rendered.json");
}

TEST(RenderChunksWorld, PartsSplitOffGetChunksAndTheRenderFollowsForAnyThreadCount) {
  const SceneDescription scene = demolitionWithAttachments(70);
  const RunResult one = runAndCheck(scene, 1, SubmissionMode::Batched, 7);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  EXPECT_GT(one.splits, 0u) << "nothing split off: the scene does not test parts";
  EXPECT_GT(one.hidden, 0u) << "no chunk was ever emptied";
  EXPECT_GT(one.bodies, 12u);
  std::printf("[ demolition_rendered ] %u parts, %u bodies, %u primitives, %u chunks hidden, %u cells recomputed\n", one.splits,
              one.bodies, one.primitives, one.hidden, one.recomputed);
  for (int threads : {2, 4}) {
    const RunResult r = runAndCheck(scene, threads, SubmissionMode::Batched, 35);
    ASSERT_FALSE(::testing::Test::HasFatalFailure());
    EXPECT_EQ(r.stateHash, one.stateHash) << threads << " threads";
    EXPECT_EQ(r.renderHash, one.renderHash) << threads << " threads";
  }
  // Per-object submission, both queues: the same render scene, byte for byte.
  for (SubmissionMode mode : {SubmissionMode::PerObjectMutex, SubmissionMode::PerObjectConcurrent}) {
    const RunResult r = runAndCheck(scene, 2, mode, 70);
    ASSERT_FALSE(::testing::Test::HasFatalFailure());
    EXPECT_EQ(r.renderHash, one.renderHash) << submissionModeName(mode);
  }
}

TEST(RenderChunksWorld, AMovingGridEditedEveryFrameKeepsExactChunks) {
  // A kinematic ship placing and removing bricks every frame, crates riding it; small chunks so
  // most edits reach a face of their cell's box.
  const SceneDescription scene = parseScene(R"({
    "name": "refit_rendered", "settings": {"frames": 30},
    "grids": [{"name": "ship", "generator": "truck", "scale": 0.8, "seed": 4, "position": [1000, -2000, 40],
               "motion": "kinematic", "linear_velocity": [4, 0, 0], "angular_velocity": [0, 0, 0.05]}],
    "edits": [{"grid": "ship", "kind": "remove", "per_frame": 20, "seed": 11},
              {"grid": "ship", "kind": "place", "per_frame": 20, "seed": 12}],
    "attachments": {"render_chunk": 0.75}
  })",
                                            "refit_rendered.json");
  const RunResult one = runAndCheck(scene, 1, SubmissionMode::Batched, 3);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  EXPECT_GT(one.recomputed, 0u);
  const RunResult two = runAndCheck(scene, 2, SubmissionMode::Batched, 30);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  EXPECT_EQ(two.renderHash, one.renderHash);
}

TEST(RenderChunksWorld, RemoveBricksAndEditGridBetweenStepsReachTheRender) {
  World world(demolitionWithAttachments(10), 1);
  world.step();
  const uint32_t house = world.gridBody("house");
  const uint32_t g = world.bodies().shape[house].grid;
  std::vector<uint32_t> some;
  world.grid(g).forEachBrick([&](uint32_t id) {
    if (some.size() < 40) some.push_back(id);
  });
  world.removeBricks(g, some);
  world.step();
  expectRenderFollowsWorld(world);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  BrickGrid& edited = world.editGrid(g);
  edited.placeBrick(Brick::box(Vec3f(0, 0, 30), Vec3f(0.5f, 0.5f, 0.5f)));
  world.step();
  expectRenderFollowsWorld(world);
}

// A lamp goes with the brick nearest to it: cut a small block out around one lamp (its bricks
// kept, a 1.5 m shell around them removed) and the lamp rides on the part that falls off, while
// lamps elsewhere stay on the house.
TEST(RenderChunksWorld, ALampGoesWithThePartItsNearestBrickSplitsOffIn) {
  World world(demolitionWithAttachments(10), 1);
  const uint32_t house = world.gridBody("house");
  const uint32_t g = world.bodies().shape[house].grid;
  const BrickGrid& grid = world.grid(g);
  const AttachmentStore& store = world.render()->store();
  const auto farthest = [](const Vec3f& p, const Aabb& b) { return (p - b.min).cwiseAbs().cwiseMax((p - b.max).cwiseAbs()).norm(); };
  const auto nearest = [](const Vec3f& p, const Aabb& b) { return (p.cwiseMax(b.min).cwiseMin(b.max) - p).norm(); };
  uint32_t lamp = kInvalidIndex;
  std::vector<uint32_t> shell;
  for (uint32_t id = 0; id < store.size() && lamp == kInvalidIndex; ++id) {
    if (store.kind(id) != AttachmentKind::Light || store.body(id) != house) continue;
    const Vec3f p = store.localTranslation(id);
    std::vector<uint32_t> inner, cut;
    grid.forEachBrick([&](uint32_t b) {
      const Aabb box = brickBounds(grid.brick(b));
      if (farthest(p, box) <= 1.5f) inner.push_back(b);
      else if (nearest(p, box) <= 3.f) cut.push_back(b);
    });
    // Nearest brick left after the cut, within the lamp's 2 m reach: it must be an inner one.
    float best = 2.f;
    bool innerNearest = false;
    grid.forEachBrick([&](uint32_t b) {
      if (std::find(cut.begin(), cut.end(), b) != cut.end()) return;
      const float d = nearest(p, brickBounds(grid.brick(b)));
      if (d < best) {
        best = d;
        innerNearest = std::find(inner.begin(), inner.end(), b) != inner.end();
      }
    });
    if (inner.size() >= 4 && innerNearest) {
      lamp = id;
      shell = cut;
    }
  }
  ASSERT_NE(lamp, kInvalidIndex) << "no lamp of the house sits on a block that can be cut out";
  std::vector<uint32_t> others;
  for (uint32_t id = 0; id < store.size(); ++id)
    if (id != lamp && store.kind(id) == AttachmentKind::Light && store.body(id) == house) others.push_back(id);
  const Vec3f offset = store.localTranslation(lamp);
  const World::RemovalResult cut = world.removeBricks(g, shell);
  ASSERT_GT(cut.parts, 0u);
  world.step();
  const uint32_t body = store.body(lamp);
  EXPECT_NE(body, house) << "the lamp stayed on the house";
  ASSERT_TRUE(world.bodies().shape[body].isGrid());
  EXPECT_NE(world.bodies().shape[body].grid, g);
  EXPECT_EQ(store.localTranslation(lamp), offset) << "the part keeps the grid's coordinates";
  uint32_t stayed = 0;
  for (uint32_t id : others) stayed += store.body(id) == house;
  EXPECT_GT(stayed, 0u) << "every other lamp left the house too";
  expectRenderFollowsWorld(world);
  // The lamp is drawn where the part holds it.
  const RenderScene& scene = world.renderScene();
  Vec3d t;
  Quatf r;
  const RigidTransform pose = world.bodies().shapePose(body);
  composeAttachmentPose(pose.translation, pose.rotation, store.localTranslation(lamp), store.localRotation(lamp), t, r);
  EXPECT_EQ(scene.lightPosition(store.renderId(lamp)), t);
  // The part's chunks, drawn for the first time (new or reused proxies): no motion from where
  // a reused proxy was, nor from the origin.
  uint32_t partChunks = 0;
  for (uint32_t id = 0; id < store.size(); ++id) {
    if (store.kind(id) != AttachmentKind::Primitive || store.body(id) != body) continue;
    ++partChunks;
    const uint32_t rid = store.renderId(id);
    EXPECT_EQ(scene.previousTranslation(rid), scene.localToWorldTranslation(rid)) << "proxy " << rid;
  }
  EXPECT_GT(partChunks, 0u);
}

TEST(RenderChunksWorld, SlabsBrokenOffTerrainGetProxies) {
  const SceneDescription scene = parseScene(R"({
    "name": "quarry_rendered", "settings": {"frames": 40},
    "terrains": [{"name": "cliff", "generator": "quarry", "size": [40, 40, 24], "seed": 3, "break_free": true, "anchor_below": 2}],
    "edits": [{"terrain": "cliff", "kind": "carve", "radius": 1.5, "every": 1, "seed": 9, "region": {"min": [2, 2, 2], "max": [18, 18, 11]}}],
    "attachments": {}
  })",
                                            "quarry_rendered.json");
  const RunResult one = runAndCheck(scene, 1, SubmissionMode::Batched, 10);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  EXPECT_GT(one.splits, 0u) << "no slab broke free";
  const RunResult two = runAndCheck(scene, 2, SubmissionMode::Batched, 40);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  EXPECT_EQ(two.renderHash, one.renderHash);
  EXPECT_EQ(two.stateHash, one.stateHash);
}

}  // namespace
}  // namespace bw
