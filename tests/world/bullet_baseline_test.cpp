// The Bullet baseline (world/bullet_baseline.h) and what it is judged with: the expert setup
// mirrors bricks of every shape into chunk objects, fires the same ray load as the World (hit
// for hit on box bricks), lands crates on a grid without letting any through, refuses a voxel
// terrain by name; World::setPoses moves the judge and rejects bad input whole.
#include <cmath>
#include <gtest/gtest.h>
#include <set>

#include "collision/core/errors.h"
#include "collision/core/seeded_random.h"
#include "world/bullet_baseline.h"
#include "world/containment.h"
#include "world/scene_file.h"
#include "world/world.h"

namespace bw {
namespace {

// A static floor of box bricks (a checkerboard of heights, so rays and crates meet steps) far
// from the origin, and `crates` boxes dropped onto it.
SceneDescription floorScene(uint32_t crates, uint32_t rays, const Vec3d& at) {
  SceneDescription s;
  s.name = "bullet_floor";
  s.source = "bullet_floor.json";
  GridDescription g;
  g.name = "floor";
  g.position = at;
  for (int x = 0; x < 24; ++x)
    for (int y = 0; y < 24; ++y) {
      const float h = (x + y) % 3 == 0 ? 0.4f : 0.2f;
      g.bricks.push_back(Brick::box(Vec3f(float(x) - 12.f + 0.5f, float(y) - 12.f + 0.5f, h), Vec3f(0.5f, 0.5f, h)));
    }
  s.grids.push_back(g);
  SpawnerDescription sp;
  sp.shape = SpawnerDescription::Shape::Box;
  sp.count = crates;
  sp.halfExtents = Vec3f::Constant(0.25f);
  sp.density = 500;
  sp.regionMin = at + Vec3d(-8, -8, 3);
  sp.regionMax = at + Vec3d(8, 8, 12);
  // Fast: without CCD (the naive setup) Bullet lets one through at 3 km from the origin.
  sp.velocity = Vec3d(0, 0, -20);
  s.spawners.push_back(sp);
  s.rays.count = rays;
  s.rays.seed = 5;
  return s;
}

TEST(BulletBaseline, ExpertLandsCratesWithoutLettingAnyThrough) {
  for (const Vec3d& at : {Vec3d(0, 0, 0), Vec3d(3000, -2000, 50)}) {
    const SceneDescription scene = floorScene(60, 0, at);
    World judge(scene, 1);
    BulletBaseline bullet(judge, BulletSetup::Expert);
    ContainmentTracker containment(judge);
    std::vector<Vec3d> positions;
    std::vector<Quatf> rotations;
    for (int f = 0; f < 180; ++f) {
      bullet.step();
      bullet.poses(positions, rotations);
      judge.setPoses(positions, rotations);
      containment.update();
    }
    EXPECT_EQ(containment.report().count(), 0u) << "at " << at.transpose();
    uint32_t resting, moving;
    double lowest;
    bullet.restingReport(resting, moving, lowest);
    // Every crate is on the floor (its top is at 0.4 or 0.8 m), none below it or still falling.
    EXPECT_GT(lowest, at.z() + 0.4 + 0.25 - 0.05) << "at " << at.transpose();
    EXPECT_EQ(resting + moving, 60u);
    EXPECT_GE(resting, 50u);
  }
}

TEST(BulletBaseline, ChunksEveryBrickOnceWithOneShapePerDistinctBrick) {
  // A grid of all four shapes, three sizes and random rotations: the chunk objects together
  // hold every brick; the shared shapes are one per (shape, size, sides).
  SceneDescription s;
  s.name = "shapes";
  s.source = "shapes.json";
  GridDescription g;
  g.name = "mixed";
  SeededRandom r(11);
  std::set<std::tuple<int, float, int>> distinct;
  for (int i = 0; i < 400; ++i) {
    Brick b = Brick::box(Vec3f(float(r.uniform(-40, 40)), float(r.uniform(-40, 40)), float(r.uniform(0, 30))), Vec3f::Zero());
    const float size = std::array<float, 3>{0.2f, 0.5f, 2.f}[size_t(r.uniform(0, 2.999))];
    b.halfSize = Vec3f::Constant(size);
    b.shape = BrickShape(int(r.uniform(0, 3.999)));
    b.sides = b.shape == BrickShape::Cylinder ? 16 : 12;
    b.rotation = AxisRotation::fromIndex(int(r.uniform(0, 23.999)));
    g.bricks.push_back(b);
    distinct.insert({int(b.shape), size, b.shape == BrickShape::Cylinder ? 16 : 0});
  }
  s.grids.push_back(g);
  World world(s, 1);
  BulletBaseline chunked(world, BulletSetup::Expert, 16.f);
  EXPECT_EQ(chunked.distinctBrickShapes(), distinct.size());
  // 80 x 80 x 30 m in 16 m cubes: at most 6 x 6 x 3 chunks, and at least as many as the
  // distinct cubes the brick centres fall in.
  std::set<std::tuple<int, int, int>> cubes;
  for (const Brick& b : g.bricks)
    cubes.insert({int(std::floor(b.position.x() / 16)), int(std::floor(b.position.y() / 16)), int(std::floor(b.position.z() / 16))});
  EXPECT_EQ(chunked.chunkObjects(), cubes.size());
  BulletBaseline naive(world, BulletSetup::Naive);
  EXPECT_EQ(naive.chunkObjects(), 0u);
  EXPECT_THROW(BulletBaseline(world, BulletSetup::Expert, 0.f), InvalidInput);
  EXPECT_THROW(BulletBaseline(world, BulletSetup::Expert, std::nanf("")), InvalidInput);
}

TEST(BulletBaseline, FiresTheSameRaysAsTheWorldAndHitsTheSame) {
  // Box bricks only: Bullet's ray against a box child is exact, so every ray that hits our grid
  // hits Bullet's chunks (a ray grazing an edge may go either way: allow 1 in 200).
  const SceneDescription scene = floorScene(0, 2000, Vec3d(100, 200, 0));
  World ours(scene, 1);
  World judge(scene, 1);
  BulletBaseline bullet(judge, BulletSetup::Expert);
  for (int f = 0; f < 3; ++f) {
    ours.step();
    bullet.step();
    uint32_t ourHits = 0;
    for (float t : ours.rayLoad().hitDistances()) ourHits += std::isfinite(t) ? 1u : 0u;
    const BulletFrame b = bullet.lastFrame();
    EXPECT_EQ(b.rays, 2000u);
    EXPECT_GT(ourHits, 200u) << "the rays must cross the floor for this test to mean anything";
    EXPECT_NEAR(double(b.rayHits), double(ourHits), 10.0) << "frame " << f;
  }
}

TEST(BulletBaseline, RefusesVoxelTerrainByName) {
  SceneDescription s = floorScene(1, 0, Vec3d::Zero());
  TerrainDescription t;
  t.name = "hills";
  t.file = "hills.vox";
  s.terrains.push_back(t);
  try {
    BulletBaseline::requireMirrorable(s);
    FAIL() << "a terrain scene was accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("hills"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("voxel terrain"), std::string::npos) << e.what();
  }
}

// One frame of the judge-follows-Bullet loop with edits (as `run --engine bullet` does it).
void editedFrame(World& judge, BulletBaseline& bullet, std::vector<Vec3d>& positions, std::vector<Quatf>& rotations) {
  judge.applyFrameEdits();
  bullet.applyEdits(judge);
  bullet.step();
  bullet.poses(positions, rotations);
  judge.setPoses(positions, rotations);
}

TEST(BulletBaseline, MirrorsEditsOnStaticKinematicAndDynamicGridsBrickForBrick) {
  // A static floor, a kinematic slab sailing over it and a dynamic block falling onto it, all
  // edited every frame (removals, placements, holes), far from the origin; crates on the
  // floor. Bullet's chunks hold every grid's bricks after every frame; the dynamic block's
  // body frame follows its new centre of mass exactly as the judge's does.
  SceneDescription s = floorScene(20, 0, Vec3d(5000, -3000, 40));
  GridDescription slab;
  slab.name = "slab";
  slab.motion = MotionType::Kinematic;
  slab.position = Vec3d(5000, -3000, 46);
  slab.kinematic.linearVelocity = Vec3d(1.5, 0, 0);
  GridDescription block;
  block.name = "block";
  block.motion = MotionType::Dynamic;
  block.position = Vec3d(4995, -2995, 44);
  for (int x = 0; x < 10; ++x)
    for (int y = 0; y < 10; ++y) {
      slab.bricks.push_back(Brick::box(Vec3f(float(x) * 2.f - 9.f, float(y) * 2.f - 9.f, 0.f), Vec3f(1.f, 1.f, 0.25f)));
      if (x < 4 && y < 4)
        for (int z = 0; z < 3; ++z)
          block.bricks.push_back(Brick::box(Vec3f(float(x) * 0.4f, float(y) * 0.4f, float(z) * 0.4f), Vec3f::Constant(0.2f)));
    }
  s.grids.push_back(slab);
  s.grids.push_back(block);
  auto stream = [](const char* grid, EditLoadDescription::Kind kind, uint32_t perFrame, uint64_t seed) {
    EditLoadDescription e;
    e.grid = grid;
    e.kind = kind;
    e.perFrame = perFrame;
    e.seed = seed;
    return e;
  };
  s.edits = {stream("floor", EditLoadDescription::Kind::Remove, 2, 1), stream("floor", EditLoadDescription::Kind::Place, 2, 2),
             stream("slab", EditLoadDescription::Kind::Remove, 1, 3), stream("slab", EditLoadDescription::Kind::Place, 1, 4),
             stream("block", EditLoadDescription::Kind::Remove, 1, 5)};
  s.edits.back().lastFrame = 20;
  for (KinematicGrids kinematic : {KinematicGrids::Compound, KinematicGrids::ChunkBodies}) {
    SCOPED_TRACE(kinematicGridsName(kinematic));
    World judge(s, 1);
    judge.recordEdits(true);
    BulletBaseline bullet(judge, BulletSetup::Expert, 4.f, kinematic);
    ASSERT_EQ(bullet.kinematicGrids(), kinematic);
    std::vector<Vec3d> positions;
    std::vector<Quatf> rotations;
    auto bodyOfGrid = [&](uint32_t grid) {
      for (uint32_t i = 0; i < judge.bodies().size(); ++i)
        if (judge.bodies().shape[i].isGrid() && judge.bodies().shape[i].grid == grid) return i;
      return ~0u;
    };
    const uint32_t slabBody = bodyOfGrid(1), blockBody = bodyOfGrid(2);
    ASSERT_EQ(judge.bodies().motion[slabBody], MotionType::Kinematic);
    ASSERT_EQ(judge.bodies().motion[blockBody], MotionType::Dynamic);
    const Vec3d slabStart = judge.bodies().position[slabBody];
    uint64_t edited = 0;
    for (int f = 0; f < 60; ++f) {
      judge.applyFrameEdits();
      edited += judge.lastStats().bricksRemoved + judge.lastStats().bricksPlaced;
      bullet.applyEdits(judge);
      for (uint32_t g = 0; g < judge.gridCount(); ++g)
        ASSERT_EQ(bullet.bricksMirrored(g), judge.grid(g).brickCount()) << "grid " << g << " after frame " << f << "'s edits";
      // Right after the edits the block's body sits where the judge moved it (its new centre;
      // Bullet holds it in floats, 6 km from the origin).
      bullet.poses(positions, rotations);
      EXPECT_LT((positions[blockBody] - judge.bodies().position[blockBody]).norm(), 2e-3) << "frame " << f;
      bullet.step();
      bullet.poses(positions, rotations);
      judge.setPoses(positions, rotations);
    }
    EXPECT_GT(edited, 250u) << "the edit load must edit for this test to mean anything";
    EXPECT_EQ(judge.grid(2).brickCount(), 48u - 21u) << "the block lost one brick a frame for 21 frames";
    // The kinematic slab's chunk bodies moved as one: its pose went 60 frames at 1.5 m/s (Bullet
    // adds each frame's step in floats 5 km out: ~0.5 mm of rounding a frame).
    EXPECT_NEAR(positions[slabBody].x() - slabStart.x(), 1.5 * 60 * s.settings.timestep, 0.02);
  }
}

TEST(BulletBaseline, MirrorsDemolitionSplitsPartForPart) {
  // The shipped demolition scene: the house loses bricks and parts break off; Bullet's chunks
  // keep the house's bricks equal to the judge's, and every part becomes a Bullet body.
  const SceneDescription scene = loadScene(std::string(BW_SCENES_DIR) + "/demolition.json");
  World judge(scene, 1);
  judge.recordEdits(true);
  BulletBaseline bullet(judge, BulletSetup::Expert);
  const uint32_t bodiesBefore = judge.bodies().size();
  std::vector<Vec3d> positions;
  std::vector<Quatf> rotations;
  for (int f = 0; f < 200; ++f) {
    editedFrame(judge, bullet, positions, rotations);
    ASSERT_EQ(positions.size(), judge.bodies().size());
    for (uint32_t g = 0; g < judge.gridCount(); ++g)
      ASSERT_EQ(bullet.bricksMirrored(g), judge.grid(g).brickCount()) << "grid " << g << " after frame " << f;
  }
  EXPECT_GT(bullet.partsMade(), 10u) << "the house must split for this test to mean anything";
  EXPECT_EQ(bullet.partsMade(), judge.bodies().size() - bodiesBefore);
  // The naive setup does not mirror edits: refused up front, naming the way out.
  try {
    BulletBaseline::requireMirrorable(scene, BulletSetup::Naive);
    FAIL() << "the naive setup accepted a scene with edits";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("--engine bullet"), std::string::npos) << e.what();
  }
}

TEST(WorldSetPoses, MovesEveryBodyAndRejectsBadInputWhole) {
  World world(floorScene(5, 0, Vec3d::Zero()), 1);
  std::vector<Vec3d> p = world.bodies().position;
  std::vector<Quatf> q = world.bodies().rotation;
  for (size_t i = 1; i < p.size(); ++i) p[i] += Vec3d(1, 2, 3);
  world.setPoses(p, q);
  for (size_t i = 0; i < p.size(); ++i) EXPECT_EQ(world.bodies().position[i], p[i]);
  const std::vector<Vec3d> before = world.bodies().position;
  std::vector<Vec3d> bad = p;
  bad.back().x() = std::nan("");
  bad.front() += Vec3d(5, 0, 0);
  EXPECT_THROW(world.setPoses(bad, q), InvalidInput);
  EXPECT_EQ(world.bodies().position, before) << "a rejected call moved a body";
  bad = p;
  bad.pop_back();
  EXPECT_THROW(world.setPoses(bad, q), InvalidInput);
  std::vector<Quatf> notUnit = q;
  notUnit[1] = Quatf(2, 0, 0, 0);
  EXPECT_THROW(world.setPoses(p, notUnit), InvalidInput);
  EXPECT_EQ(world.bodies().position, before);
}

}  // namespace
}  // namespace bw
