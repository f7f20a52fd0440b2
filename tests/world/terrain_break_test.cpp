// Terrain regions that break free (world/terrain_breaks.cpp): a generated quarry carved every
// frame loses exactly the voxels carved, the debris and the regions made bodies, each body
// weighs its voxels, nothing ends inside solid, and bad terrain edits are refused naming the
// field.
#include <gtest/gtest.h>

#include "collision/core/errors.h"
#include "world/containment.h"
#include "world/scene_file.h"
#include "world/world.h"

namespace bw {
namespace {

uint64_t solidVoxels(const Terrain& t) {
  const VoxelTerrain& v = t.voxels();
  uint64_t n = 0;
  for (int32_t z = 0; z < v.size().z; ++z)
    for (int32_t y = 0; y < v.size().y; ++y)
      for (int32_t x = 0; x < v.size().x; ++x) n += v.get({x, y, z}).isSolid() ? 1u : 0u;
  return n;
}

// A small quarry (48 x 32 x 24 voxels of 0.5 m) 3 km from the origin, carved every frame
// around its fin and pillars, with crates on its floor.
std::string quarryScene(int debris) {
  return R"({"name": "small_quarry", "settings": {"substeps": 2},
    "terrains": [{"name": "q", "generator": "quarry", "size": [48, 32, 24], "seed": 2, "voxel_size": 0.5,
                  "position": [3000, -2000, 40], "break_free": true, "anchor_below": 4, "debris_voxels": )" +
         std::to_string(debris) + R"(}],
    "spawners": [{"shape": "box", "count": 20, "half_extents": [0.25, 0.25, 0.25], "density": 300,
                  "region": {"min": [3005, -1999, 43], "max": [3018, -1996, 46]}, "seed": 4}],
    "edits": [{"terrain": "q", "kind": "carve", "radius": 1.0, "first_frame": 5, "seed": 9,
               "region": {"min": [3000, -1996, 42.5], "max": [3024, -1988, 50]}}]})";
}

TEST(TerrainBreak, CarvedQuarryLosesExactlyWhatBrokeFreeAndEachPartWeighsItsVoxels) {
  for (int debris : {0, 6}) {
    SCOPED_TRACE("debris_voxels " + std::to_string(debris));
    World world(parseScene(quarryScene(debris), "small_quarry.json"), 2);
    ContainmentTracker inside(world);
    const uint64_t before = solidVoxels(world.terrain(0));
    const uint32_t bodiesBefore = world.bodies().size();
    uint64_t carved = 0, debrisVoxels = 0, parts = 0;
    for (int f = 0; f < 150; ++f) {
      world.step();
      inside.update();
      carved += world.lastStats().voxelsCarved;
      debrisVoxels += world.lastStats().debrisVoxels;
      parts += world.lastStats().terrainParts;
    }
    ASSERT_GT(parts, 2u) << "the carves must cut regions free for this test to mean anything";
    EXPECT_EQ(world.bodies().size(), bodiesBefore + parts);
    if (debris == 0) {
      EXPECT_EQ(debrisVoxels, 0u);
    }
    // Each part's grid weighs its voxels (density 1, 0.125 m^3 a voxel); all together they,
    // the carved voxels and the debris are what the terrain lost.
    uint64_t partVoxels = 0;
    for (uint32_t i = bodiesBefore; i < world.bodies().size(); ++i) {
      const double voxels = world.grid(world.bodies().shape[i].grid).massProperties().mass / 0.125;
      EXPECT_NEAR(voxels, std::round(voxels), 1e-3);
      EXPECT_GE(std::lround(voxels), debris);
      partVoxels += uint64_t(std::lround(voxels));
    }
    EXPECT_EQ(before - solidVoxels(world.terrain(0)), carved + debrisVoxels + partVoxels);
    EXPECT_EQ(inside.report().count(), 0u);
  }
}

TEST(TerrainBreak, BadTerrainEditsAreRefusedNamingTheField) {
  const std::string terrain = R"({"name": "q", "generator": "quarry", "size": [32, 32, 16]})";
  const std::pair<std::string, const char*> cases[] = {
      {R"({"name": "x", "terrains": [)" + terrain + R"(], "edits": [{"terrain": "q", "kind": "remove"}]})", "scene.edits[0].kind"},
      {R"({"name": "x", "terrains": [)" + terrain + R"(], "edits": [{"terrain": "nope", "kind": "carve"}]})", "scene.edits[0].terrain"},
      {R"({"name": "x", "terrains": [)" + terrain + R"(], "grids": [{"name": "g", "bricks": [{"position": [0, 0, 0], "half_size": [1, 1, 1]}]}],
          "edits": [{"terrain": "q", "grid": "g", "kind": "carve"}]})", "exactly one of"},
      {R"({"name": "x", "terrains": [{"name": "q", "generator": "mountain"}]})", "scene.terrains[0].generator"},
      {R"({"name": "x", "terrains": [{"name": "q", "generator": "quarry", "size": [8, 32, 16]}]})", "scene.terrains[0].size"},
      {R"({"name": "x", "terrains": [{"name": "q", "generator": "quarry", "file": "a.vox"}]})", "exactly one of"},
      {R"({"name": "x", "terrains": [)" + terrain + R"(], "edits": [{"terrain": "q", "kind": "carve", "region": {"min": [5, 0, 0], "max": [1, 1, 1]}}]})",
       "min.x is greater than max.x"},
  };
  for (const auto& [text, field] : cases) {
    try {
      World world(parseScene(text, "bad.json"), 1);
      ADD_FAILURE() << "accepted " << text;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace bw
