// The .vox reader's material mapping: the water range, solid rules, overrides, the mapping
// file, and what lands in the terrain.
#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <gtest/gtest.h>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "collision/content/vox_reader.h"
#include "collision/core/argument_checks.h"
#include "collision/terrain/terrain.h"
#include "collision/content/vox_test_files.h"

namespace bw {
namespace {

using namespace test::vox;

// ---- materials ----

TEST(VoxMaterials, WaterRangeSolidRulesAndOverrides) {
  VoxMaterialMap m;
  EXPECT_EQ(m.materialFor(1), 2);
  EXPECT_EQ(m.materialFor(30), 31);
  EXPECT_EQ(m.materialFor(254), 255);
  EXPECT_EQ(m.materialFor(255), 255);
  EXPECT_EQ(m.materialFor(0), kMaterialAir);
  m.waterFirst = 10;
  m.waterLast = 12;
  EXPECT_EQ(m.materialFor(9), 10);
  EXPECT_TRUE(m.isWater(10));
  EXPECT_TRUE(m.isWater(12));
  EXPECT_FALSE(m.isWater(13));
  m.solids = VoxMaterialMap::Solids::Single;
  m.solidMaterial = 7;
  EXPECT_EQ(m.materialFor(200), 7);
  EXPECT_EQ(m.materialFor(11), kMaterialWater);
  m.overrides[11] = 9;
  m.overrides[200] = 0;
  EXPECT_EQ(m.materialFor(11), 9);
  EXPECT_EQ(m.materialFor(200), kMaterialAir);
  EXPECT_TRUE(VoxMaterialMap::monu6().isWater(29));
  EXPECT_TRUE(VoxMaterialMap::monu6().isWater(31));
  EXPECT_FALSE(VoxMaterialMap::monu6().isWater(45));
}

TEST(VoxMaterials, TerrainGetsWaterSolidsAndSkipsAir) {
  const Blob file = voxFile({sizeChunk(4, 1, 1), xyziChunk({{0, 0, 0, 5}, {1, 0, 0, 6}, {2, 0, 0, 7}, {3, 0, 0, 8}})});
  const VoxModelSet s = parseExact(file, "water.vox");
  VoxMaterialMap m;
  m.waterFirst = 6;
  m.waterLast = 6;
  m.overrides[8] = 0;
  VoxTerrainOptions opt;
  opt.margin = 0;
  const VoxTerrain vt = buildVoxTerrain(s, m, opt);
  const VoxelTerrain& v = vt.terrain->voxels();
  EXPECT_EQ(v.get({0, 0, 0}), Voxel::make(6));
  EXPECT_TRUE(v.get({1, 0, 0}).isWater());
  EXPECT_EQ(v.get({2, 0, 0}), Voxel::make(8));
  EXPECT_TRUE(v.get({3, 0, 0}).isAir());
  EXPECT_EQ(vt.waterVoxels, 1u);
  EXPECT_EQ(vt.solidVoxels, 2u);
  EXPECT_EQ(vt.skippedVoxels, 1u);
  VoxMaterialMap bad;
  bad.solids = VoxMaterialMap::Solids::Single;
  bad.solidMaterial = 1;
  EXPECT_THROW(buildVoxTerrain(s, bad), InvalidInput);
  VoxTerrainOptions badMargin;
  badMargin.margin = -1;
  EXPECT_THROW(buildVoxTerrain(s, {}, badMargin), InvalidInput);
}

TEST(VoxMaterials, MappingFileParsesAndRejectsBadEntries) {
  const VoxMaterialMap m =
      parseVoxMaterialMap(R"({"water": [29, 31], "solids": "single", "solid_material": 4, "materials": {"45": 7, "11": 0}})",
                          "map.json");
  EXPECT_EQ(m.waterFirst, 29);
  EXPECT_EQ(m.waterLast, 31);
  EXPECT_EQ(m.materialFor(30), kMaterialWater);
  EXPECT_EQ(m.materialFor(45), 7);
  EXPECT_EQ(m.materialFor(11), kMaterialAir);
  EXPECT_EQ(m.materialFor(100), 4);
  EXPECT_EQ(parseVoxMaterialMap("{}", "empty.json").materialFor(3), 4);

  const std::vector<std::pair<std::string, std::string>> bad = {
      {"[1, 2]", "must be a JSON object"},
      {"{\"water\": [31, 29]}", "inverted"},
      {"{\"water\": [0, 3]}", "not an integer in [1, 255]"},
      {"{\"water\": 3}", "must be [first, last]"},
      {"{\"solids\": \"mixed\"}", "neither"},
      {"{\"solid_material\": 1}", "not an integer in [2, 255]"},
      {"{\"materials\": {\"x\": 3}}", "not a palette index"},
      {"{\"materials\": {\"256\": 3}}", "not a palette index"},
      {"{\"materials\": {\"3\": 300}}", "not an integer in [0, 255]"},
      {"{\"colour\": 1}", "unknown key"},
      {"{\"water\": [1, 2]", "not valid JSON"},
  };
  for (const auto& [text, fragment] : bad) {
    try {
      parseVoxMaterialMap(text, "bad.json");
      ADD_FAILURE() << text;
    } catch (const InvalidInput& e) {
      EXPECT_EQ(std::string(e.what()).rfind("bad.json: ", 0), 0u) << e.what();
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what() << " / " << fragment;
    }
  }
  EXPECT_THROW(loadVoxMaterialMap("/nonexistent/map.json"), InvalidInput);
}

}  // namespace
}  // namespace bw
