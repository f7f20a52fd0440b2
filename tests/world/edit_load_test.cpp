// The scene's edit load (world/edit_load.h): removals, placements, carved holes and wall
// courses checked against brute force on seeded grids; in a world: static, kinematic and
// dynamic grids edited every frame keep the state hash identical for any thread count, wake
// what rests on them, keep a dynamic grid's exact mass and its bricks' velocities, and a full
// brick pool stops the run with an error naming the grid.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <set>

#include "collision/bricks/brick_geometry.h"
#include "collision/core/errors.h"
#include "world/edit_load.h"
#include "world/scene_file.h"
#include "world/world.h"
#include "world/world_tuning.h"

namespace bw {
namespace {

// A seeded grid: a slab of unit cubes (touching face to face) with a few flat plates and
// thin bricks on top, far from the grid origin so positions carry large float values.
std::unique_ptr<BrickGrid> seededGrid(uint64_t seed, int side = 24) {
  auto grid = std::make_unique<BrickGrid>(BrickGrid::Config(1u << 16));
  std::mt19937 rng{uint32_t(seed)};
  const Vec3f origin(5000.f, -3000.f, 200.f);
  for (int x = 0; x < side; ++x)
    for (int y = 0; y < side; ++y)
      for (int z = 0; z < 3; ++z)
        if (rng() % 7 != 0) grid->placeBrick(Brick::box(origin + Vec3f(float(x), float(y), float(z)), Vec3f::Constant(0.5f)));
  for (int k = 0; k < 8; ++k)
    grid->placeBrick(Brick::box(origin + Vec3f(float(rng() % side), float(rng() % side), 3.1f), Vec3f(2.f, 0.5f, 0.1f)));
  return grid;
}

std::map<uint32_t, Brick> liveBricks(const BrickGrid& grid) {
  std::map<uint32_t, Brick> out;
  grid.forEachBrick([&](uint32_t id) { out[id] = grid.brick(id); });
  return out;
}

// Overlap of two bricks' bounds beyond a small inset (touching faces do not count).
bool overlaps(const Brick& a, const Brick& b) {
  const Aabb x = brickBounds(a), y = brickBounds(b);
  const Vec3f lo = x.min.cwiseMax(y.min), hi = x.max.cwiseMin(y.max);
  const Vec3f tol = x.halfExtent().cwiseMin(y.halfExtent()) * 0.04f;
  return ((hi - lo).array() > tol.array()).all();
}

EditLoadDescription stream(EditLoadDescription::Kind kind, uint32_t perFrame, uint64_t seed) {
  EditLoadDescription d;
  d.grid = "g";
  d.kind = kind;
  d.perFrame = perFrame;
  d.seed = seed;
  return d;
}

TEST(EditLoad, RemovalsTakeExactlyTheirCountAndRepeatForTheSameSeed) {
  std::vector<std::unique_ptr<BrickGrid>> a, b;
  a.push_back(seededGrid(3));
  b.push_back(seededGrid(3));
  const uint32_t start = a[0]->brickCount();
  EditLoad la({stream(EditLoadDescription::Kind::Remove, 37, 9)}, {0}), lb({stream(EditLoadDescription::Kind::Remove, 37, 9)}, {0});
  std::vector<uint32_t> edited;
  for (uint64_t f = 0; f < 20; ++f) {
    const auto before = liveBricks(*a[0]);
    const EditLoadStats s = la.apply(f, a, edited);
    lb.apply(f, b, edited);
    EXPECT_EQ(s.removed, 37u);
    EXPECT_EQ(s.placed, 0u);
    const auto after = liveBricks(*a[0]);
    EXPECT_EQ(before.size() - after.size(), 37u);
    for (const auto& [id, brick] : after) EXPECT_TRUE(before.count(id)) << "a removal stream placed brick " << id;
  }
  EXPECT_EQ(a[0]->brickCount(), start - 20 * 37);
  EXPECT_EQ(a[0]->index().structureHash(), b[0]->index().structureHash());
  EXPECT_EQ(liveBricks(*a[0]).size(), liveBricks(*b[0]).size());
  // A different seed removes other bricks.
  std::vector<std::unique_ptr<BrickGrid>> c;
  c.push_back(seededGrid(3));
  EditLoad lc({stream(EditLoadDescription::Kind::Remove, 37, 10)}, {0});
  for (uint64_t f = 0; f < 20; ++f) lc.apply(f, c, edited);
  EXPECT_NE(a[0]->index().structureHash(), c[0]->index().structureHash());
}

TEST(EditLoad, PlacementsLandBesideTheirSourceAndNeverOverlapABrick) {
  std::vector<std::unique_ptr<BrickGrid>> grids;
  grids.push_back(seededGrid(5, 12));
  EditLoad load({stream(EditLoadDescription::Kind::Place, 50, 4)}, {0});
  std::vector<uint32_t> edited;
  uint32_t placed = 0;
  for (uint64_t f = 0; f < 12; ++f) {
    const auto before = liveBricks(*grids[0]);
    const EditLoadStats s = load.apply(f, grids, edited);
    EXPECT_EQ(s.placed + s.skipped, 50u);
    placed += s.placed;
    const auto after = liveBricks(*grids[0]);
    ASSERT_EQ(after.size(), before.size() + s.placed);
    // Brute force: every new brick against every brick (old and new).
    for (const auto& [id, brick] : after) {
      if (before.count(id)) continue;
      bool touchesOne = false;
      for (const auto& [other, o] : after) {
        if (other == id) continue;
        ASSERT_FALSE(overlaps(brick, o)) << "placed brick " << id << " overlaps brick " << other << " at frame " << f;
        touchesOne |= (brickBounds(brick).expanded(1e-3f).overlaps(brickBounds(o)));
      }
      EXPECT_TRUE(touchesOne) << "placed brick " << id << " touches nothing";
    }
  }
  EXPECT_GT(placed, 400u);
}

// Spots are chosen a group at a time and placed together: a spot chosen earlier in the group
// is taken. Around one brick alone there are five spots (on top, four sides), so a group of 32
// fills exactly those five, and the next groups build from the bricks placed before them.
TEST(EditLoad, PlacementsChosenTogetherNeverTakeTheSameSpot) {
  std::vector<std::unique_ptr<BrickGrid>> grids;
  grids.push_back(std::make_unique<BrickGrid>(BrickGrid::Config(1024)));
  grids[0]->placeBrick(Brick::box(Vec3f(-700.f, 30.f, 2.f), Vec3f(0.5f, 0.25f, 0.2f)));
  EditLoad load({stream(EditLoadDescription::Kind::Place, uint32_t(BrickGrid::kPrefetchGroup), 8)}, {0});
  std::vector<uint32_t> edited;
  EditLoadStats s = load.apply(0, grids, edited);
  EXPECT_EQ(s.placed, 5u);
  EXPECT_EQ(s.skipped, BrickGrid::kPrefetchGroup - 5);
  for (uint64_t f = 1; f < 4; ++f) {
    s = load.apply(f, grids, edited);
    EXPECT_GT(s.placed, 5u) << "frame " << f;
  }
  const auto all = liveBricks(*grids[0]);
  for (const auto& [id, brick] : all)
    for (const auto& [other, o] : all)
      if (other > id) {
        ASSERT_FALSE(overlaps(brick, o)) << "bricks " << id << " and " << other;
      }
}

TEST(EditLoad, CarvedHolesAreExactlyTheBricksWithinTheRadiusOfOneBrick) {
  std::vector<std::unique_ptr<BrickGrid>> grids;
  grids.push_back(seededGrid(8));
  EditLoadDescription d = stream(EditLoadDescription::Kind::Carve, 1, 2);
  d.radius = 2.3f;
  EditLoad load({d}, {0});
  std::vector<uint32_t> edited;
  for (uint64_t f = 0; f < 15; ++f) {
    const auto before = liveBricks(*grids[0]);
    const EditLoadStats s = load.apply(f, grids, edited);
    const auto after = liveBricks(*grids[0]);
    std::set<uint32_t> gone;
    for (const auto& [id, brick] : before)
      if (!after.count(id)) gone.insert(id);
    ASSERT_EQ(gone.size(), s.removed);
    ASSERT_GT(gone.size(), 5u) << "a 2.3 radius hole in a slab of unit cubes";
    // Some removed brick is the centre: the removed set is every brick within the radius of it.
    bool explained = false;
    for (uint32_t c : gone) {
      const Vec3f centre = before.at(c).position;
      std::set<uint32_t> within;
      for (const auto& [id, brick] : before)
        if ((brick.position - centre).squaredNorm() <= d.radius * d.radius) within.insert(id);
      explained |= within == gone;
    }
    EXPECT_TRUE(explained) << "frame " << f;
  }
}

TEST(EditLoad, WallsRiseCourseByCourseOnTopOfTheGrid) {
  std::vector<std::unique_ptr<BrickGrid>> grids;
  grids.push_back(seededGrid(1, 16));
  const float top = grids[0]->bounds().max.z();
  EditLoadDescription d = stream(EditLoadDescription::Kind::Wall, 7, 3);
  d.wallLength = 10;
  d.brickHalfSize = Vec3f(0.4f, 0.2f, 0.25f);
  EditLoad load({d}, {0});
  std::vector<uint32_t> edited;
  const auto before = liveBricks(*grids[0]);
  for (uint64_t f = 0; f < 10; ++f) EXPECT_EQ(load.apply(f, grids, edited).placed, 7u);
  std::map<int, int> perCourse;
  for (const auto& [id, brick] : liveBricks(*grids[0])) {
    if (before.count(id)) continue;
    const float course = (brick.position.z() - top - 0.25f) / 0.5f;
    ASSERT_NEAR(course, std::round(course), 1e-3f);
    ++perCourse[int(std::round(course))];
  }
  ASSERT_EQ(perCourse.size(), 7u);  // 70 bricks, 10 per course
  for (const auto& [course, n] : perCourse) EXPECT_EQ(n, 10) << "course " << course;
}

TEST(EditLoad, NoticesEditsMadeOutsideItAndRefusesMismatchedStreams) {
  std::vector<std::unique_ptr<BrickGrid>> grids;
  grids.push_back(seededGrid(2, 8));
  EditLoad load({stream(EditLoadDescription::Kind::Remove, 5, 1)}, {0});
  std::vector<uint32_t> edited;
  load.apply(0, grids, edited);
  // Remove bricks behind the load's back: its next picks must still be live bricks.
  std::vector<uint32_t> ids;
  grids[0]->forEachBrick([&](uint32_t id) { ids.push_back(id); });
  for (size_t k = 0; k < ids.size(); k += 2) grids[0]->removeBrick(ids[k]);
  const uint32_t left = grids[0]->brickCount();
  for (uint64_t f = 1; f < 40; ++f) load.apply(f, grids, edited);
  EXPECT_EQ(grids[0]->brickCount(), left > 39 * 5 ? left - 39 * 5 : 0u);
  EXPECT_THROW(EditLoad({stream(EditLoadDescription::Kind::Remove, 5, 1)}, {}), InvalidInput);
}

// A floor of cubes with a crate resting on it, and a dynamic grid flying free (no gravity on it
// would be simpler, but the scene's gravity makes everything rest first).
SceneDescription editedScene() {
  return parseScene(R"({
    "name": "edited", "settings": {"timestep": 0.016666667, "substeps": 1, "frames": 90},
    "grids": [{"name": "floor", "generator": "city_block", "scale": 0.004, "seed": 3},
              {"name": "lift", "bricks": [{"position": [0, 0, 0], "half_size": [2, 2, 0.2]}, {"position": [0, 0, 1], "half_size": [0.5, 0.5, 0.5]}],
               "position": [30, 30, 12], "motion": "kinematic", "linear_velocity": [0, 0, 0.5]},
              {"name": "ship", "bricks": [{"position": [0, 0, 0], "half_size": [1, 0.5, 0.5]}, {"position": [2, 0, 0], "half_size": [1, 0.5, 0.5]},
                                          {"position": [4, 0, 0], "half_size": [1, 0.5, 0.5]}, {"position": [2, 1, 0], "half_size": [1, 0.5, 0.5]}],
               "position": [10, 10, 40], "motion": "dynamic"}],
    "spawners": [{"shape": "box", "count": 150, "half_extents": [0.3, 0.3, 0.3], "region": {"min": [2, 2, 25], "max": [60, 60, 35]}, "seed": 4}],
    "edits": [{"grid": "floor", "kind": "remove", "per_frame": 40, "seed": 1, "first_frame": 30},
              {"grid": "floor", "kind": "carve", "radius": 1.5, "every": 15, "seed": 2},
              {"grid": "lift", "kind": "wall", "per_frame": 3, "wall_length": 6, "brick_half_size": [0.3, 0.1, 0.1], "seed": 3},
              {"grid": "ship", "kind": "place", "per_frame": 1, "every": 10, "seed": 4}]})",
                    "edited.json");
}

TEST(EditLoadWorld, StateIsIdenticalForAnyThreadCountAndNothingEndsInsideSolid) {
  const SceneDescription scene = editedScene();
  uint64_t first = 0;
  for (int threads : {1, 2, 4}) {
    World world(scene, threads);
    uint32_t removed = 0, placed = 0;
    for (uint32_t f = 0; f < scene.settings.frames; ++f) {
      world.step();
      removed += world.lastStats().bricksRemoved;
      placed += world.lastStats().bricksPlaced;
    }
    EXPECT_GT(removed, 60u * 40u) << threads;
    EXPECT_GT(placed, 200u) << threads;
    if (threads == 1) {
      first = world.stateHash();
      ContainmentTracker inside(world);
      inside.update();
      EXPECT_EQ(inside.report().count(), 0u);
    } else {
      EXPECT_EQ(world.stateHash(), first) << threads << " threads";
    }
  }
}

TEST(EditLoadWorld, ASleepingBoxFallsWhenTheBricksUnderItAreRemoved) {
  const SceneDescription scene = parseScene(R"({
    "name": "pull", "settings": {"timestep": 0.016666667, "frames": 400},
    "grids": [{"name": "floor", "bricks": [{"position": [0, 0, -0.5], "half_size": [3, 3, 0.5]}]}],
    "spawners": [{"shape": "box", "count": 1, "half_extents": [0.25, 0.25, 0.25], "region": {"min": [0, 0, 0.3], "max": [0, 0, 0.3]}}],
    "edits": [{"grid": "floor", "kind": "remove", "per_frame": 1, "first_frame": 300, "last_frame": 300}]})",
                                            "pull.json");
  World world(scene, 2);
  for (int f = 0; f < 300; ++f) world.step();
  ASSERT_EQ(world.sleepingCount(), 1u) << "the box should be asleep on the floor before the edit";
  const double restingZ = world.bodies().position[1].z();
  for (int f = 0; f < 60; ++f) world.step();
  EXPECT_EQ(world.grid(0).brickCount(), 0u);
  EXPECT_EQ(world.sleepingCount(), 0u);
  EXPECT_LT(world.bodies().position[1].z(), restingZ - 3.0) << "one second of free fall";
}

TEST(EditLoadWorld, ADynamicGridKeepsItsExactMassAndItsBricksTheirVelocity) {
  const SceneDescription scene = parseScene(R"({
    "name": "refit", "settings": {"gravity": [0, 0, 0], "frames": 30},
    "grids": [{"name": "ship", "generator": "house", "scale": 1, "seed": 2, "position": [1.0e6, -2.0e6, 300],
               "motion": "dynamic", "linear_velocity": [3, -1, 0.5], "angular_velocity": [0.2, 0.1, -0.3]}],
    "edits": [{"grid": "ship", "kind": "remove", "per_frame": 20, "seed": 5}, {"grid": "ship", "kind": "place", "per_frame": 10, "seed": 6}]})",
                                            "refit.json");
  World world(scene, 2);
  for (int f = 0; f < 30; ++f) {
    const BodyStore& b = world.bodies();
    const Vec3d c0 = b.position[0];
    const Vec3f v0 = b.linearVelocity[0], w0 = b.angularVelocity[0];
    const RigidTransform gridPose0 = b.shapePose(0);
    world.step();
    ASSERT_GT(world.lastStats().bricksRemoved, 0u);
    // Mass: the body's equals the edited grid's, computed from its bricks.
    const MassProperties m = world.grid(0).massProperties();
    EXPECT_NEAR(1.0 / b.inverseMass[0], m.mass, m.mass * 1e-5) << f;
    // The edit (before the step's motion) moved the centre of mass inside the grid; the body
    // then moves at the velocity that point of the body had (v + w x r) and keeps its spin.
    const Vec3d c1 = gridPose0.pointToWorld(m.centerOfMass.cast<float>());
    const Vec3f v1 = v0 + w0.cross((c1 - c0).cast<float>());
    EXPECT_LT((b.linearVelocity[0] - v1).norm(), 1e-4f * v1.norm()) << "frame " << f;
    EXPECT_LT((b.angularVelocity[0] - w0).norm(), 1e-5f) << "frame " << f;
    const Vec3d expected = c1 + v1.cast<double>() * scene.settings.timestep;
    EXPECT_LT((b.position[0] - expected).norm(), 1e-4) << "frame " << f;
  }
}

TEST(EditLoadWorld, AFullBrickPoolStopsTheRunWithAnErrorNamingTheGrid) {
  const SceneDescription scene = parseScene(R"({
    "name": "full", "settings": {"gravity": [0, 0, 0], "frames": 1},
    "grids": [{"name": "yard", "bricks": [{"position": [0, 0, 0], "half_size": [0.5, 0.5, 0.5]}]}],
    "edits": [{"grid": "yard", "kind": "wall", "per_frame": 1000, "wall_length": 100}]})",
                                            "full.json");
  World world(scene, 1);  // room for the bricks 4 x 1 frame of edits place, and 1024 more
  uint32_t frames = 0;
  try {
    for (; frames < 10; ++frames) world.step();
    FAIL() << "the pool never filled";
  } catch (const CapacityExceeded& e) {
    EXPECT_NE(std::string(e.what()).find("grid 'yard'"), std::string::npos) << e.what();
  }
  EXPECT_GE(frames, 4u);
  // Every brick placed before the pool filled is whole and indexed.
  const BrickGrid& grid = world.grid(0);
  uint32_t counted = 0;
  grid.forEachBrick([&](uint32_t) { ++counted; });
  EXPECT_EQ(counted, grid.brickCount());
  EXPECT_EQ(grid.index().size(), grid.brickCount());
}

TEST(EditLoadScene, BadEditsAreRefusedNamingTheField) {
  const std::string base = R"({"name": "x", "grids": [{"name": "g", "bricks": [{"position": [0, 0, 0], "half_size": [1, 1, 1]}]}], "edits": [)";
  const std::pair<const char*, const char*> cases[] = {
      {R"({"grid": "nope", "kind": "remove"})", "scene.edits[0].grid"},
      {R"({"grid": "g", "kind": "explode"})", "scene.edits[0].kind"},
      {R"({"grid": "g", "kind": "remove", "per_frame": 0})", "scene.edits[0].per_frame"},
      {R"({"grid": "g", "kind": "remove", "first_frame": 10, "last_frame": 5})", "scene.edits[0].last_frame"},
      {R"({"grid": "g", "kind": "carve", "radius": -1})", "scene.edits[0].radius"},
      {R"({"grid": "g", "kind": "wall", "brick_half_size": [1, 0, 1]})", "scene.edits[0].brick_half_size"},
      {R"({"grid": "g", "kind": "remove", "colour": 3})", "scene.edits[0].colour: unknown field"},
  };
  for (const auto& [edit, field] : cases) {
    try {
      parseScene(base + edit + "]}", "bad.json");
      ADD_FAILURE() << "accepted " << edit;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  }
}

// A dynamic bar of nine cubes far from the origin, spinning in zero gravity; one random brick
// removed: an inner one splits the bar in two bodies. Mass is conserved but for the removed
// brick, and so is momentum: the parts carry their bricks' velocities (v + w x r).
TEST(EditLoadSplit, APartSplitOffCarriesItsMassAndItsBricksMomentum) {
  uint32_t splits = 0;
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    SceneDescription scene = parseScene(R"({
      "name": "bar", "settings": {"gravity": [0, 0, 0], "frames": 3},
      "grids": [{"name": "bar", "bricks": [
        {"position": [0, 0, 0], "half_size": [0.5, 0.5, 0.5]}, {"position": [1, 0, 0], "half_size": [0.5, 0.5, 0.5]},
        {"position": [2, 0, 0], "half_size": [0.5, 0.5, 0.5]}, {"position": [3, 0, 0], "half_size": [0.5, 0.5, 0.5]},
        {"position": [4, 0, 0], "half_size": [0.5, 0.5, 0.5]}, {"position": [5, 0, 0], "half_size": [0.5, 0.5, 0.5]},
        {"position": [6, 0, 0], "half_size": [0.5, 0.5, 0.5]}, {"position": [7, 0, 0], "half_size": [0.5, 0.5, 0.5]},
        {"position": [8, 0, 0], "half_size": [0.5, 0.5, 0.5]}],
        "position": [2.0e6, -1.0e6, 500], "motion": "dynamic", "linear_velocity": [1, 2, -0.5], "angular_velocity": [0.1, -0.2, 0.7],
        "split": true}],
      "edits": [{"grid": "bar", "kind": "remove", "per_frame": 1, "first_frame": 1, "last_frame": 1}]})",
                                        "bar.json");
    scene.edits[0].seed = seed;
    World world(scene, 2);
    world.step();
    const BodyStore& b = world.bodies();
    const double mass0 = 1.0 / b.inverseMass[0];
    const RigidTransform pose = b.shapePose(0);
    const Vec3f v0 = b.linearVelocity[0], w0 = b.angularVelocity[0];
    const Vec3d c0 = b.position[0];
    // Which brick goes: the stream's pick, seen as the brick missing after the step.
    std::vector<Vec3f> before;
    world.grid(0).forEachBrick([&](uint32_t id) { before.push_back(world.grid(0).brick(id).position); });
    world.step();
    ASSERT_EQ(world.lastStats().bricksRemoved, 1u);
    std::vector<Vec3f> after;
    for (uint32_t g = 0; g < world.gridCount(); ++g)
      world.grid(g).forEachBrick([&](uint32_t id) { after.push_back(world.grid(g).brick(id).position); });
    ASSERT_EQ(after.size(), 8u);
    Vec3f gone = Vec3f::Zero();
    for (const Vec3f& p : before)
      if (std::find(after.begin(), after.end(), p) == after.end()) gone = p;
    const bool inner = gone.x() > 0.5f && gone.x() < 7.5f;
    ASSERT_EQ(b.size(), inner ? 2u : 1u) << "brick at x = " << gone.x();
    splits += world.lastStats().splits;
    // Mass: every body's, summed, is the bar's less one cube (a ninth).
    double mass = 0;
    Vec3d momentum = Vec3d::Zero();
    for (uint32_t i = 0; i < b.size(); ++i) {
      mass += 1.0 / b.inverseMass[i];
      momentum += b.linearVelocity[i].cast<double>() / double(b.inverseMass[i]);
    }
    EXPECT_NEAR(mass, mass0 * 8.0 / 9.0, mass0 * 1e-5) << "seed " << seed;
    // Momentum: the bar's less the removed cube's (its mass at its point's velocity).
    const Vec3d at = pose.pointToWorld(gone);
    const Vec3d cubeMomentum = (mass0 / 9.0) * (v0 + w0.cross((at - c0).cast<float>())).cast<double>();
    const Vec3d expected = mass0 * v0.cast<double>() - cubeMomentum;
    EXPECT_LT((momentum - expected).norm(), 1e-4 * mass0 * v0.norm()) << "seed " << seed;
    for (uint32_t i = 0; i < b.size(); ++i) EXPECT_LT((b.angularVelocity[i] - w0).norm(), 1e-5f) << "seed " << seed;
  }
  EXPECT_GE(splits, 3u) << "most single removals from a bar split it";
}

// Splitting on a static house: parts fall as bodies; the same state for 1, 2 and 4 threads.
TEST(EditLoadSplit, ADemolishedHouseSplitsTheSameForAnyThreadCount) {
  const SceneDescription scene = parseScene(R"({
    "name": "demo", "settings": {"timestep": 0.016666667, "substeps": 2, "frames": 90},
    "grids": [{"name": "yard", "bricks": [{"position": [20, 20, -0.5], "half_size": [40, 40, 0.5]}]},
              {"name": "house", "generator": "house", "scale": 1, "seed": 3, "position": [15, 15, 0.16], "split": true, "debris_bricks": 3}],
    "edits": [{"grid": "house", "kind": "remove", "per_frame": 10, "seed": 5, "first_frame": 5},
              {"grid": "house", "kind": "carve", "radius": 1.0, "every": 4, "seed": 6, "first_frame": 5}]})",
                                          "demo.json");
  uint64_t first = 0;
  for (int threads : {1, 2, 4}) {
    World world(scene, threads);
    uint32_t splits = 0, debris = 0;
    for (uint32_t f = 0; f < scene.settings.frames; ++f) {
      world.step();
      splits += world.lastStats().splits;
      debris += world.lastStats().debrisBricks;
    }
    EXPECT_GT(splits, 5u);
    EXPECT_EQ(world.bodies().size(), 2u + splits);
    if (threads == 1) {
      first = world.stateHash();
      // The parts of a static house start at rest and fall: some are below where they began.
      uint32_t fell = 0;
      for (uint32_t i = 2; i < world.bodies().size(); ++i) fell += world.bodies().motion[i] == MotionType::Dynamic;
      EXPECT_EQ(fell, splits);
      ContainmentTracker inside(world);
      inside.update();
      EXPECT_EQ(inside.report().count(), 0u);
      std::printf("[ demolition ] %u parts split off, %u debris bricks\n", splits, debris);
    } else {
      EXPECT_EQ(world.stateHash(), first) << threads << " threads";
    }
  }
}

// A cut into two big halves: from kParallelPartBricks bricks on, the part's index is built, its
// bricks and mass added, the old grid lets go and the links move, as four jobs (the first two on
// one grid: TSan checks they share nothing). Any thread count gives the same grids (ids,
// index structure, mass) and the same state after the parts fall; mass is conserved.
TEST(EditLoadSplit, ABigCutIsTheSameOnAnyThreadCountAndConservesMass) {
  SceneDescription scene;
  scene.name = "cut";
  GridDescription slab;
  slab.name = "slab";
  slab.split = true;
  const int side = 50;  // two halves of 2,500 bricks: above kParallelPartBricks
  static_assert(50 * 50 >= tuning::kParallelPartBricks);
  const Vec3f far(3000.f, -2000.f, 10.f);
  for (int half = 0; half < 2; ++half)
    for (int x = 0; x < side; ++x)
      for (int y = 0; y < side; ++y)
        slab.bricks.push_back(Brick::box(far + Vec3f(float(x + half * (side + 1)), float(y), float((x * 7 + y) % 3) * 0.25f),
                                         Vec3f(0.5f, 0.5f, 0.5f + 0.125f * float((x + y) % 2))));
  slab.bricks.push_back(Brick::box(far + Vec3f(float(side), float(side / 2), 0), Vec3f::Constant(0.5f)));  // the joint, last
  scene.grids = {slab};
  uint64_t firstHash = 0, firstTree[2] = {0, 0};
  for (int threads : {1, 2, 4}) {
    World world(scene, threads);
    const MassProperties before = world.grid(0).massProperties();
    const uint32_t joint = uint32_t(slab.bricks.size() - 1);
    const MassProperties jointMass = [&] {
      BrickGrid g;
      g.placeBrick(world.grid(0).brick(joint));
      return g.massProperties();
    }();
    const World::RemovalResult r = world.removeBricks(0, std::span<const uint32_t>(&joint, 1));
    ASSERT_EQ(r.parts, 1u);
    EXPECT_GT(r.partBodiesMs, 0.0) << "the part's grid and body were timed";
    EXPECT_LE(r.partBodiesMs, r.ms) << "the part's time is part of the whole";
    ASSERT_EQ(world.gridCount(), 2u);
    EXPECT_EQ(world.grid(0).brickCount(), uint32_t(side * side));
    EXPECT_EQ(world.grid(1).brickCount(), uint32_t(side * side));
    world.grid(0).index().validate();
    world.grid(1).index().validate();
    const double mass = world.grid(0).massProperties().mass + world.grid(1).massProperties().mass;
    EXPECT_NEAR(mass, before.mass - jointMass.mass, 1e-9 * before.mass);
    for (int f = 0; f < 5; ++f) world.step();
    if (threads == 1) {
      firstHash = world.stateHash();
      firstTree[0] = world.grid(0).index().structureHash();
      firstTree[1] = world.grid(1).index().structureHash();
    } else {
      EXPECT_EQ(world.stateHash(), firstHash) << threads << " threads";
      EXPECT_EQ(world.grid(0).index().structureHash(), firstTree[0]) << threads << " threads";
      EXPECT_EQ(world.grid(1).index().structureHash(), firstTree[1]) << threads << " threads";
    }
  }
}

TEST(EditLoadSplit, SplitGridsAreRefusedWhereASplitIsUndefined) {
  // Checked when the world is built (validateScene), naming the field.
  const auto refused = [](const char* json, const char* what) {
    try {
      World world(parseScene(json, "x.json"), 1);
      ADD_FAILURE() << "accepted " << json;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  refused(R"({"name": "x", "grids": [{"name": "g", "bricks": [{"position": [0, 0, 0], "half_size": [1, 1, 1]}], "split": true}],
              "spawners": [{"shape": "grid", "grid": "g", "count": 2, "region": {"min": [0, 0, 5], "max": [9, 9, 9]}}]})",
          "grids[0].split: a grid that spawners copy cannot split");
  EXPECT_THROW(parseScene(R"({"name": "x", "grids": [{"name": "g", "bricks": [{"position": [0, 0, 0], "half_size": [1, 1, 1]}], "debris_bricks": 3}]})",
                           "x.json"),
               SceneError);
}

TEST(EditLoadSplit, RemoveBricksSplitsAtOnceAndRefusesBadIdsWhole) {
  const SceneDescription scene = parseScene(R"({
    "name": "bar", "settings": {"frames": 10},
    "grids": [{"name": "bar", "bricks": [
      {"position": [0, 0, 5], "half_size": [0.5, 0.5, 0.5]}, {"position": [1, 0, 5], "half_size": [0.5, 0.5, 0.5]},
      {"position": [2, 0, 5], "half_size": [0.5, 0.5, 0.5]}, {"position": [3, 0, 5], "half_size": [0.5, 0.5, 0.5]},
      {"position": [4, 0, 5], "half_size": [0.5, 0.5, 0.5]}], "split": true}]})",
                                          "bar.json");
  World world(scene, 1);
  const uint32_t bad[] = {1, 77};
  EXPECT_THROW(world.removeBricks(0, bad), InvalidInput);
  EXPECT_EQ(world.grid(0).brickCount(), 5u) << "nothing removed";
  EXPECT_THROW(world.removeBricks(3, bad), InvalidInput);
  const uint32_t end[] = {4};  // splits nothing: no part's time
  const World::RemovalResult none = world.removeBricks(0, end);
  EXPECT_EQ(none.parts, 0u);
  EXPECT_EQ(none.partBodiesMs, 0.0);
  world.editGrid(0).placeBrick(Brick::box(Vec3f(4, 0, 5), Vec3f::Constant(0.5f)));  // back as it was
  const uint32_t middle[] = {1};  // x = 1: the brick at x = 0 falls off
  const World::RemovalResult r = world.removeBricks(0, middle);
  EXPECT_EQ(r.parts, 1u);
  ASSERT_EQ(world.bodies().size(), 2u);
  EXPECT_EQ(world.grid(0).brickCount() + world.grid(1).brickCount(), 4u);
  EXPECT_EQ(world.grid(1).brickCount(), 1u) << "the smaller side is the part";
  EXPECT_EQ(world.bodies().motion[1], MotionType::Dynamic);
  EXPECT_LT(world.bodies().position[1].x(), 0.01);
  for (int f = 0; f < 30; ++f) world.step();
  EXPECT_LT(world.bodies().position[1].z(), 5.0 - 1.0) << "a static grid's part falls";
  EXPECT_DOUBLE_EQ(world.bodies().position[0].z(), 0.0) << "the grid stays";
  // After an edit through editGrid() (which the links do not see), removals still split.
  world.editGrid(0).placeBrick(Brick::box(Vec3f(5, 0, 5), Vec3f::Constant(0.5f)));  // x = 2, 3, 4, 5
  const uint32_t second[] = {3};  // x = 3 goes: x = 2 falls off (the smaller side)
  EXPECT_EQ(world.removeBricks(0, second).parts, 1u);
  EXPECT_EQ(world.bodies().size(), 3u);
}

}  // namespace
}  // namespace bw
