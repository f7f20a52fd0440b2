// Bodies that start inside solid (world/depenetration.h): a spawner box overlapping a real
// voxel monument's tower, and one inside a solid block of bricks. Every body ends outside solid,
// none falls through the model; a scene that asks to refuse them stops with the spawner's name.
#include <algorithm>
#include <cstdio>
#include <gtest/gtest.h>

#include "collision/content/vox_test_files.h"
#include "world/containment.h"
#include "world/scene_file.h"
#include "world/world.h"

namespace bw {
namespace {

struct SolidStart {
  uint32_t startedInSolid = 0;
  uint32_t stillPushedOut = 0;
  uint32_t insideAtTheEnd = 0;
  uint32_t worstFrame = 0;  // most bodies inside solid at any frame after the first
  double lowest = 1e300;    // lowest dynamic centre over the run
};

SolidStart run(const SceneDescription& scene, int frames) {
  World world(scene, 2);
  ContainmentTracker tracker(world);
  SolidStart r;
  r.startedInSolid = world.startedInSolid();
  for (int f = 0; f < frames; ++f) {
    world.step();
    r.worstFrame = std::max(r.worstFrame, tracker.update().count());
    for (uint32_t b = 0; b < world.bodies().size(); ++b)
      if (!world.bodies().shape[b].isGrid() && !world.bodies().shape[b].isTerrain()) r.lowest = std::min(r.lowest, world.bodies().position[b].z());
  }
  r.stillPushedOut = world.depenetratingCount();
  r.insideAtTheEnd = tracker.report().count();
  for (uint32_t k = 0; k < r.insideAtTheEnd; ++k)
    ADD_FAILURE() << scene.name << ": body " << tracker.report().bodies[k] << " " << insideSolidName(tracker.report().reasons[k]);
  std::printf("[ start in solid ] %s: %u started inside solid, %u still pushed out, %u inside at the end (at most %u in a frame), lowest centre z %.2f\n",
              scene.name.c_str(), r.startedInSolid, r.stillPushedOut, r.insideAtTheEnd, r.worstFrame, r.lowest);
  return r;
}

SpawnerDescription spawnerAround(SpawnerDescription::Shape shape, const Vec3d& centre, double half, uint32_t count, uint64_t seed) {
  SpawnerDescription s;
  s.shape = shape;
  s.count = count;
  s.seed = seed;
  s.halfExtents = Vec3f::Constant(0.3f);
  s.radius = 0.25f;
  s.halfHeight = 0.3f;
  s.density = 500;  // wood (the monument's water voxels float it; the default 1 kg/m^3 would fly)
  s.regionMin = centre - Vec3d::Constant(half);
  s.regionMax = centre + Vec3d::Constant(half);
  return s;
}

// monu6.vox (shared data: 42 x 42 x 63 m of 0.5 m voxels, a lake up to 22.5 m around a tower).
SceneDescription monument() {
  SceneDescription s;
  s.name = "monument_spawner_in_tower";
  s.source = "monument_spawner_in_tower.json";
  TerrainDescription t;
  t.name = "monument";
  t.file = test::vox::dataPath("monu6.vox").string();
  t.voxelSize = 0.5f;
  t.waterFirst = 29;
  t.waterLast = 31;
  s.terrains.push_back(t);
  return s;
}

// The centre of the tower at height z: the solid point nearest the model's middle (found by
// probing, so the test does not depend on where the model's author put it).
Vec3d solidPointNearTheMiddle(const SceneDescription& terrainOnly, double z) {
  World probe(terrainOnly, 1);
  Vec3d best(0, 0, 0);
  double bestDistance = 1e300;
  for (double x = 0.25; x < 42; x += 0.5)
    for (double y = 0.25; y < 42; y += 0.5) {
      const Vec3d p(x, y, z);
      const double d = std::hypot(x - 21, y - 21);
      if (d < bestDistance && probe.pointInsideSolid(p, kInvalidIndex) == InsideSolid::InVoxel) {
        bestDistance = d;
        best = p;
      }
    }
  EXPECT_LT(bestDistance, 1e300) << "no solid voxel at z " << z;
  return best;
}

TEST(StartInSolid, BodiesSpawnedInsideAVoxelTowerArePushedOutAndNoneFallsThrough) {
  SceneDescription s = monument();
  const Vec3d tower = solidPointNearTheMiddle(s, 35);
  s.spawners.push_back(spawnerAround(SpawnerDescription::Shape::Box, tower, 1.0, 20, 3));
  s.spawners.push_back(spawnerAround(SpawnerDescription::Shape::Capsule, tower + Vec3d(0, 0, 3), 1.0, 20, 4));
  const SolidStart r = run(s, 300);
  EXPECT_GE(r.startedInSolid, 20u) << "the spawner boxes lie in the tower: most bodies start in it";
  EXPECT_EQ(r.stillPushedOut, 0u);
  EXPECT_EQ(r.insideAtTheEnd, 0u);
  // Before depenetration they fell through the whole model to -80 m. The model's base is solid
  // from z = 0: a body pushed out of the tower lands on it or floats in the lake.
  EXPECT_GT(r.lowest, 0.0);
}

// A static 6 x 6 x 6 m block of 1 m box bricks (216 bricks: every inner face is shared, so
// contacts alone would push a body inside it every which way) on a floor, and 40 boxes and
// spheres spawned in its middle.
TEST(StartInSolid, BodiesSpawnedInsideABlockOfBricksArePushedOutOnToIt) {
  SceneDescription s;
  s.name = "block_spawner_inside";
  s.source = "block_spawner_inside.json";
  GridDescription block;
  block.name = "block";
  for (int x = 0; x < 6; ++x)
    for (int y = 0; y < 6; ++y)
      for (int z = 0; z < 6; ++z) block.bricks.push_back(Brick::box(Vec3f(float(x) + 0.5f, float(y) + 0.5f, float(z) + 0.5f), Vec3f::Constant(0.5f)));
  block.bricks.push_back(Brick::box(Vec3f(3, 3, -0.5f), Vec3f(20, 20, 0.5f)));  // the floor
  s.grids.push_back(block);
  s.spawners.push_back(spawnerAround(SpawnerDescription::Shape::Box, Vec3d(3, 3, 3), 1.5, 20, 5));
  s.spawners.push_back(spawnerAround(SpawnerDescription::Shape::Sphere, Vec3d(3, 3, 3.5), 1.5, 20, 6));
  const SolidStart r = run(s, 240);
  EXPECT_EQ(r.startedInSolid, 40u);
  EXPECT_EQ(r.stillPushedOut, 0u);
  EXPECT_EQ(r.insideAtTheEnd, 0u);
  EXPECT_GT(r.lowest, 0.2) << "pushed out sideways or up, never through the floor";
}

TEST(StartInSolid, SceneThatRefusesBodiesInSolidNamesTheSpawner) {
  SceneDescription s = monument();
  const Vec3d tower = solidPointNearTheMiddle(s, 35);
  s.spawners.push_back(spawnerAround(SpawnerDescription::Shape::Sphere, tower + Vec3d(0, 0, 60), 1.0, 5, 1));  // in the air
  s.spawners.push_back(spawnerAround(SpawnerDescription::Shape::Box, tower, 0.2, 3, 2));
  s.settings.startInSolid = StartInSolid::Refuse;
  try {
    World world(s, 1);
    ADD_FAILURE() << "built a world with bodies inside solid";
  } catch (const SceneError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("monument_spawner_in_tower.json"), std::string::npos) << m;
    EXPECT_NE(m.find("spawners[1] body 0 of 3"), std::string::npos) << m;
    EXPECT_NE(m.find("inside a solid voxel"), std::string::npos) << m;
    EXPECT_NE(m.find("start_in_solid"), std::string::npos) << m;
  }
  // Parsed from JSON too, and a misspelt policy is refused by name.
  const std::string spawner = R"("spawners": [{"shape": "sphere", "count": 1, "region": {"min": [0, 0, 0], "max": [0, 0, 0]}}])";
  EXPECT_EQ(parseScene(R"({"name": "x", "settings": {"start_in_solid": "refuse"}, )" + spawner + "}", "x.json").settings.startInSolid,
            StartInSolid::Refuse);
  try {
    parseScene(R"({"name": "x", "settings": {"start_in_solid": "teleport"}, )" + spawner + "}", "x.json");
    ADD_FAILURE() << "accepted an unknown policy";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("settings.start_in_solid"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace bw
