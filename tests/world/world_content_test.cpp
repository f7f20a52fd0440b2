// The world on real content and its tools: a Brickadia save as a static grid (and tiled), a
// MagicaVoxel model as terrain with water, bad content files named in a scene, contact probes
// that leave the state alone, grid edits between steps, and the ten-box stack's drift goal.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <iterator>

#include "collision/bricks/brick_narrowphase.h"
#include "world/scene_file.h"
#include "world/world.h"

namespace bw {
namespace {

namespace fs = std::filesystem;

// Shipped scenes name the shared data folder relative to profiles/scenes.
SceneDescription shipped(const char* name) { return loadScene(std::string(BW_SCENES_DIR) + "/" + name + ".json"); }

TEST(WorldContent, LighthouseIsTheSaveAsOneStaticGridWithARayLoad) {
  SceneDescription scene = shipped("lighthouse");
  for (SpawnerDescription& s : scene.spawners) s.count = 20;
  World world(scene, 2);
  EXPECT_EQ(world.brickCount(), 25427u);
  uint32_t hits = 0;
  for (int f = 0; f < 30; ++f) {
    world.step();
    EXPECT_EQ(world.lastStats().rays, scene.rays.count);
    hits += world.lastStats().rayHits;
  }
  // Rays between random points of the island's bounds: some cross bricks, some only air.
  EXPECT_GT(hits, 30u * scene.rays.count / 10);
  EXPECT_LT(hits, 30u * scene.rays.count);

  scene.grids[0].tilesX = 2;
  scene.grids[0].tilesY = 3;
  EXPECT_EQ(World(scene, 1).brickCount(), 6u * 25427u);
}

TEST(WorldContent, BadContentFilesNamedInASceneFailNamingSceneGridAndProblem) {
  const fs::path dir = fs::temp_directory_path() / "bw_world_content_test";
  fs::create_directories(dir);
  const SceneDescription good = shipped("lighthouse");
  std::ifstream in(good.grids[0].file, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 1000u);
  std::ofstream(dir / "cut.brs", std::ios::binary).write(bytes.data(), std::streamsize(bytes.size() / 2));
  std::ofstream(dir / "cut.vox", std::ios::binary) << "VOX ";
  std::ofstream(dir / "cut.json") << R"({"name": "cut", "grids": [{"name": "island", "file": "cut.brs"}]})";
  std::ofstream(dir / "cutvox.json") << R"({"name": "cutvox", "terrains": [{"name": "lake", "file": "cut.vox"}]})";
  for (const auto& [scene, expected] : {std::pair{"cut.json", "grid 'island': "}, std::pair{"cutvox.json", "terrain 'lake': "}}) {
    try {
      World world(loadScene((dir / scene).string()), 1);
      ADD_FAILURE() << scene << " was accepted";
    } catch (const SceneError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(scene), std::string::npos) << m;
      EXPECT_NE(m.find(expected), std::string::npos) << m;
      EXPECT_NE(m.find(std::string(scene).find("vox") != std::string::npos ? "cut.vox" : "cut.brs"), std::string::npos)
          << "names the content file too: " << m;
    }
  }
  fs::remove_all(dir);
}

// monu6: a lake fills the model from z = 3 m (the floor) to 23 m (voxels of 0.5 m).
SceneDescription lakeWith(float density, const Vec3d& at) {
  SceneDescription scene = shipped("monument");
  SpawnerDescription crate = scene.spawners[0];
  crate.count = 1;
  crate.density = density;
  crate.regionMin = crate.regionMax = at;
  scene.spawners = {crate};
  scene.settings.sleeping = false;
  return scene;
}

TEST(WorldContent, CratesFloatAtTheLakeSurfaceAndDenseOnesSink) {
  {
    World world(lakeWith(500, {6, 20, 26}), 1);
    for (int f = 0; f < 720; ++f) world.step();
    const uint32_t crate = world.bodies().size() - 1;
    // Half the density of water: half under water, its centre at the surface (0.4 m half size).
    EXPECT_NEAR(world.bodies().position[crate].z(), 23.0, 0.15);
    EXPECT_LT(world.bodies().linearVelocity[crate].norm(), 0.2f);
  }
  {
    World world(lakeWith(8000, {9, 20, 10}), 1);
    for (int f = 0; f < 720; ++f) world.step();
    const uint32_t crate = world.bodies().size() - 1;
    EXPECT_NEAR(world.bodies().position[crate].z(), 3.0 + 0.4, 0.1) << "a dense crate rests on the lake floor";
    EXPECT_GT(world.lastStats().terrainContacts, 0u);
  }
}

// The step's terrain counters are summed per job of the parallel finish for pairs whose chunks
// were cached, and on one thread for the rest (a first frame meshes every chunk it touches):
// either way they equal a recount of the terrain pairs' contact lists (one substep a frame, so
// the last substep's lists are the step's), and crates in the lake count as floating.
TEST(WorldContent, TerrainCountersEqualARecountOfTheTerrainPairsContacts) {
  SceneDescription scene = shipped("monument");
  scene.settings.substeps = 1;
  scene.settings.sleeping = false;
  World world(scene, 2);
  uint32_t mostFloating = 0, framesWithContacts = 0;
  for (int f = 0; f < 90; ++f) {
    world.step();
    uint32_t recount = 0;
    for (uint32_t k = 0; k < world.pairs().size(); ++k) {
      const BodyPair& p = world.pairs()[k];
      if (world.bodies().shape[p.a].isTerrain() || world.bodies().shape[p.b].isTerrain())
        recount += uint32_t(world.pairContacts(k).size());
    }
    ASSERT_EQ(world.lastStats().terrainContacts, recount) << "frame " << f;
    framesWithContacts += recount > 0 ? 1 : 0;
    EXPECT_LE(world.lastStats().floating, world.bodies().size());
    mostFloating = std::max(mostFloating, world.lastStats().floating);
  }
  EXPECT_GT(framesWithContacts, 45u);
  EXPECT_GT(mostFloating, 0u);
}

TEST(WorldContent, ContactProbesLeaveTheStateUnchanged) {
  SceneDescription scene = shipped("crates_on_grid");
  scene.spawners[0].count = 150;
  World probed(scene, 2), plain(scene, 2);
  size_t probedContacts = 0;
  for (int f = 0; f < 150; ++f) {
    probed.step();
    plain.step();
    const auto& lists = probed.probeContacts(0.5f, 2, 2);
    for (size_t k = 0; k < probed.pairs().size(); ++k) {
      EXPECT_LE(lists[k].size(), 2u * kManifoldNormalGroups) << "the probe's manifold size (per normal direction)";
      probedContacts += lists[k].size();
    }
  }
  EXPECT_GT(probedContacts, 100u);
  EXPECT_EQ(probed.stateHash(), plain.stateHash());
  EXPECT_THROW(probed.probeContacts(2.f, 3, 4), SceneError) << "an out-of-range LOD fraction is refused";
}

TEST(WorldContent, GridEditsBetweenStepsAreSeenByTheBodies) {
  const SceneDescription scene = parseScene(R"({"name": "edit",
      "grids": [{"name": "floor", "bricks": [{"position": [0, 0, -0.5], "half_size": [1, 1, 0.5]},
                                             {"position": [0, 0, -5.5], "half_size": [1, 1, 0.5]}]}],
      "spawners": [{"shape": "box", "count": 1, "region": {"min": [0, 0, 1], "max": [0, 0, 1]}}]})",
                                            "edit.json");
  World world(scene, 1);
  for (int f = 0; f < 120; ++f) world.step();
  EXPECT_NEAR(world.bodies().position[1].z(), 0.25, 0.02) << "resting on the top brick";
  world.editGrid(0).removeBrick(0);
  for (int f = 0; f < 120; ++f) world.step();
  EXPECT_NEAR(world.bodies().position[1].z(), -5.0 + 0.25, 0.02) << "fell onto the lower brick once the top one was removed";
}

TEST(WorldContent, TenBoxStackDriftsLessThanAMillimetreOverTenSecondsWithoutSleeping) {
  SceneDescription scene = shipped("stack10");
  scene.settings.sleeping = false;
  World world(scene, 1);
  for (int f = 0; f < 60; ++f) world.step();  // 1 s to settle
  const std::vector<Vec3d> settled = world.bodies().position;
  double excursion = 0;
  for (int f = 0; f < 600; ++f) {
    world.step();
    for (uint32_t i = 1; i < settled.size(); ++i) excursion = std::max(excursion, (world.bodies().position[i] - settled[i]).norm());
  }
  double drift = 0;
  for (uint32_t i = 1; i < settled.size(); ++i) drift = std::max(drift, (world.bodies().position[i] - settled[i]).norm());
  // The issue's goal is on the drift (where the boxes end up); on the way the stack sways in a
  // slowly decaying rocking mode (measured 2.4 mm at most), bounded here.
  EXPECT_LT(drift, 1e-3) << "largest displacement of a box after 10 s";
  EXPECT_LT(excursion, 3e-3) << "largest displacement of a box at any time";
}

}  // namespace
}  // namespace bw
