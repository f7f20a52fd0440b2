// The .vox reader against the real monu6 and nature models (counts, bounds and palette checked
// against a separate minimal chunk scan written here), against hand-built files (scene-graph
// placement, palettes, material mapping, terrain round trips) and against bad files: each must
// fail with InvalidInput naming the file, never crash or half-load.
// Real files, palette and scene graph here; materials in vox_materials_test.cpp, bad files in
// vox_bad_files_test.cpp.
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

// ---- real files ----

const VoxModelSet& monu6() {
  static const VoxModelSet s = loadVox(dataPath("monu6.vox").string());
  return s;
}

TEST(VoxRealFiles, Monu6MatchesAnIndependentScan) {
  ASSERT_TRUE(fs::exists(dataPath("monu6.vox"))) << "the shared data folder must sit next to the repository";
  const Blob bytes = readFile(dataPath("monu6.vox"));
  const ScanResult scan = scanVox(bytes);
  const VoxModelSet& s = monu6();
  ASSERT_EQ(scan.sizes.size(), 1u);
  EXPECT_EQ(scan.voxels, 365'232u);
  EXPECT_EQ((scan.sizes[0]), (std::array<int32_t, 3>{84, 84, 126}));
  EXPECT_FALSE(scan.sceneGraph);

  EXPECT_EQ(s.version, 150);
  ASSERT_EQ(s.models.size(), 1u);
  ASSERT_EQ(s.instances.size(), 1u);
  EXPECT_EQ(s.models[0].size, (Int3{84, 84, 126}));
  EXPECT_EQ(s.fileVoxels, scan.voxels);
  EXPECT_EQ(s.totalVoxels, scan.voxels);
  EXPECT_EQ(s.instances[0].offset, (Int3{0, 0, 0}));
  EXPECT_EQ(s.boundsMin, (Int3{0, 0, 0}));
  EXPECT_EQ(s.boundsMax, (Int3{83, 83, 125}));
  EXPECT_EQ(s.voxelBoundsMin, (Int3{scan.tightLo[0], scan.tightLo[1], scan.tightLo[2]}));
  EXPECT_EQ(s.voxelBoundsMax, (Int3{scan.tightHi[0], scan.tightHi[1], scan.tightHi[2]}));
  for (int i = 0; i < 256; ++i) EXPECT_EQ(s.paletteCounts[size_t(i)], scan.histogram[size_t(i)]) << "index " << i;

  // Palette: entry i of the RGBA chunk is palette index i + 1.
  EXPECT_FALSE(s.defaultPalette);
  ASSERT_EQ(scan.rgba.size(), 256u);
  for (int i = 1; i < 256; ++i) {
    const auto& raw = scan.rgba[size_t(i - 1)];
    EXPECT_EQ(s.palette[size_t(i)], (VoxRgba{raw[0], raw[1], raw[2], raw[3]})) << "index " << i;
  }
  // The water (see vox_reader.h): indices 29 and 31, cyan, 169,072 + 2,118 voxels.
  EXPECT_EQ(s.palette[29], (VoxRgba{144, 223, 227, 255}));
  EXPECT_EQ(s.palette[31], (VoxRgba{144, 223, 227, 255}));
  EXPECT_EQ(s.paletteCounts[30], 0u);
  EXPECT_EQ(s.countInRange(29, 31), scan.histogram[29] + scan.histogram[31]);
  EXPECT_EQ(s.countInRange(29, 31), 171'190u);
}

TEST(VoxRealFiles, NatureMatchesAnIndependentScan) {
  const Blob bytes = readFile(dataPath("nature.vox"));
  ASSERT_FALSE(bytes.empty());
  const ScanResult scan = scanVox(bytes);
  const VoxModelSet s = loadVox(dataPath("nature.vox").string());
  ASSERT_EQ(scan.sizes.size(), 1u);
  EXPECT_EQ(scan.voxels, 75'835u);
  EXPECT_EQ(s.totalVoxels, scan.voxels);
  ASSERT_EQ(s.models.size(), 1u);
  EXPECT_EQ(s.models[0].size, (Int3{120, 120, 60}));
  EXPECT_EQ(s.boundsMax, (Int3{119, 119, 59}));
  EXPECT_EQ(s.voxelBoundsMin, (Int3{scan.tightLo[0], scan.tightLo[1], scan.tightLo[2]}));
  EXPECT_EQ(s.voxelBoundsMax, (Int3{scan.tightHi[0], scan.tightHi[1], scan.tightHi[2]}));
  for (int i = 0; i < 256; ++i) EXPECT_EQ(s.paletteCounts[size_t(i)], scan.histogram[size_t(i)]) << "index " << i;
}

TEST(VoxRealFiles, Monu6RoundTripsThroughTheTerrain) {
  const VoxModelSet& s = monu6();
  VoxTerrainOptions opt;
  opt.voxelSize = 0.5f;
  opt.placement.translation = Vec3d(1e6, -2e6, 10.0);
  const auto t0 = std::chrono::steady_clock::now();
  const VoxTerrain vt = buildVoxTerrain(s, VoxMaterialMap::monu6(), opt);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::printf("monu6: buildVoxTerrain %.1f ms, %u chunks stored\n", ms, vt.terrain->voxels().storedChunkCount());

  const Terrain& t = *vt.terrain;
  EXPECT_EQ(t.voxels().size(), (Int3{84 + 4, 84 + 4, 126 + 4}));
  EXPECT_EQ(vt.voxToTerrain, (Int3{2, 2, 2}));
  EXPECT_EQ(vt.waterVoxels, 171'190u);
  EXPECT_EQ(vt.solidVoxels, 365'232u - 171'190u);
  EXPECT_EQ(vt.skippedVoxels, 0u);
  const VoxMaterialMap map = VoxMaterialMap::monu6();
  for (const VoxVoxel& v : s.models[0].voxels) {
    const Voxel got = t.voxels().get({v.x + 2, v.y + 2, v.z + 2});
    ASSERT_EQ(got, Voxel::make(map.materialFor(v.colorIndex))) << int(v.x) << " " << int(v.y) << " " << int(v.z);
  }
  uint64_t water = 0;
  EXPECT_EQ(countStoredVoxels(t, &water), 365'232u);  // no duplicates in the file, so writes == stored
  EXPECT_EQ(water, 171'190u);
  // The margin is air.
  EXPECT_TRUE(t.voxels().get({1, 40, 40}).isAir());
  EXPECT_TRUE(t.voxels().get({40, 40, 129}).isAir());
  EXPECT_GT(t.broadphase().entryCount(), 0u);
}

// ---- palette ----

TEST(VoxPalette, DefaultPaletteMatchesTheFormatText) {
  std::ifstream in(dataPath("MagicaVoxel-file-format-vox.txt"));
  ASSERT_TRUE(in) << dataPath("MagicaVoxel-file-format-vox.txt");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  size_t at = text.find("default_palette[256]");
  ASSERT_NE(at, std::string::npos);
  at = text.find('{', at);
  const size_t end = text.find('}', at);
  std::vector<uint32_t> table;
  for (size_t p = text.find("0x", at); p < end; p = text.find("0x", p + 2))
    table.push_back(uint32_t(std::stoul(text.substr(p + 2, 8), nullptr, 16)));
  ASSERT_EQ(table.size(), 256u);
  const auto& pal = voxDefaultPalette();
  for (size_t i = 0; i < 256; ++i) {
    const uint32_t v = table[i];  // 0xAABBGGRR: bytes R, G, B, A in memory
    EXPECT_EQ(pal[i], (VoxRgba{uint8_t(v), uint8_t(v >> 8), uint8_t(v >> 16), uint8_t(v >> 24)})) << "index " << i;
  }
}

TEST(VoxPalette, AbsentRgbaUsesTheDefaultAndRgbaShiftsByOne) {
  const Blob noPalette = voxFile({sizeChunk(2, 2, 2), xyziChunk({{0, 0, 0, 5}})});
  const VoxModelSet a = parseExact(noPalette, "default.vox");
  EXPECT_TRUE(a.defaultPalette);
  EXPECT_EQ(a.palette, voxDefaultPalette());

  std::array<VoxRgba, 256> custom{};
  for (int i = 1; i < 256; ++i) custom[size_t(i)] = VoxRgba{uint8_t(i), uint8_t(255 - i), uint8_t(i * 3), 200};
  const VoxModelSet b = parseExact(voxFile({sizeChunk(2, 2, 2), xyziChunk({{0, 0, 0, 5}}), rgbaChunk(custom)}),
                                   "custom.vox");
  EXPECT_FALSE(b.defaultPalette);
  EXPECT_EQ(b.palette[0], VoxRgba{});
  for (int i = 1; i < 256; ++i) EXPECT_EQ(b.palette[size_t(i)], custom[size_t(i)]) << i;
}

// ---- scene graph ----

TEST(VoxScene, TranslationsAccumulateAndCentreTheModels) {
  const VoxModelSet s = parseExact(twoModelScene(), "scene.vox");
  EXPECT_EQ(s.version, 200);
  EXPECT_TRUE(s.hasSceneGraph);
  ASSERT_EQ(s.instances.size(), 2u);
  // Model 0 (4x4x4): centre at (11, 1, 1), so voxel (0,0,0) at (11-2, 1-2, 1-2).
  EXPECT_EQ(s.instances[0].model, 0u);
  EXPECT_EQ(s.instances[0].translation, (Int3{11, 1, 1}));
  EXPECT_EQ(s.instances[0].offset, (Int3{9, -1, -1}));
  // Model 1 (3x5x1): centre at (-4, 4, 8), floor(size/2) = (1, 2, 0).
  EXPECT_EQ(s.instances[1].model, 1u);
  EXPECT_EQ(s.instances[1].translation, (Int3{-4, 4, 8}));
  EXPECT_EQ(s.instances[1].offset, (Int3{-5, 2, 8}));
  EXPECT_EQ(s.transformsApplied, 3u);  // root, then one per model path
  EXPECT_EQ(s.ignoredRotations, 0u);
  EXPECT_EQ(s.totalVoxels, 5u);
  // Model boxes: [9,12]x[-1,2]x[-1,2] and [-5,-3]x[2,6]x[8,8].
  EXPECT_EQ(s.boundsMin, (Int3{-5, -1, -1}));
  EXPECT_EQ(s.boundsMax, (Int3{12, 6, 8}));
  // Voxels: (9,-1,-1), (12,2,2), (-5,2,8), (-3,6,8), (-4,4,8).
  EXPECT_EQ(s.voxelBoundsMin, (Int3{-5, -1, -1}));
  EXPECT_EQ(s.voxelBoundsMax, (Int3{12, 6, 8}));
}

TEST(VoxScene, TwoModelsLandInTheTerrainWhereMagicaVoxelPlacesThem) {
  const VoxModelSet s = parseExact(twoModelScene(), "scene.vox");
  VoxTerrainOptions opt;
  opt.margin = 3;
  const VoxTerrain vt = buildVoxTerrain(s, {}, opt);
  const Terrain& t = *vt.terrain;
  EXPECT_EQ(t.voxels().size(), (Int3{18 + 6, 8 + 6, 10 + 6}));
  EXPECT_EQ(vt.voxToTerrain, (Int3{5 + 3, 1 + 3, 1 + 3}));
  const std::vector<std::pair<Int3, uint8_t>> expected = {
      {{9, -1, -1}, 10}, {{12, 2, 2}, 11}, {{-5, 2, 8}, 20}, {{-3, 6, 8}, 21}, {{-4, 4, 8}, 22}};
  for (const auto& [p, index] : expected) {
    const Int3 q{p.x + vt.voxToTerrain.x, p.y + vt.voxToTerrain.y, p.z + vt.voxToTerrain.z};
    EXPECT_EQ(t.voxels().get(q), Voxel::make(uint8_t(index + 1))) << p.x << " " << p.y << " " << p.z;
  }
  EXPECT_EQ(countStoredVoxels(t), 5u);
  EXPECT_EQ(vt.solidVoxels, 5u);
}

TEST(VoxScene, SharedSubtreesInstanceAndRotationsAreCounted) {
  // Two transforms share one shape; the second has a rotation (x <-> y swap: _r = 1).
  const Blob file = voxFile({sizeChunk(2, 2, 2), xyziChunk({{1, 1, 1, 3}}), ntrn(0, 1), ngrp(1, {2, 3}),
                             ntrn(2, 4, "0 0 0", "4"), ntrn(3, 4, "20 0 0", "1"), nshp(4, 0)});
  const VoxModelSet s = parseExact(file, "shared.vox");
  ASSERT_EQ(s.instances.size(), 2u);
  EXPECT_EQ(s.instances[0].offset, (Int3{-1, -1, -1}));
  EXPECT_FALSE(s.instances[0].rotationIgnored);
  EXPECT_EQ(s.instances[1].offset, (Int3{19, -1, -1}));
  EXPECT_TRUE(s.instances[1].rotationIgnored);
  EXPECT_EQ(s.ignoredRotations, 1u);
  EXPECT_EQ(s.totalVoxels, 2u);
  EXPECT_EQ(s.fileVoxels, 1u);
  EXPECT_EQ(s.paletteCounts[3], 2u);
}

TEST(VoxScene, WithoutASceneGraphSeveralModelsAreAnimationFramesOfWhichTheFirstIsPlaced) {
  // MagicaVoxel 0.98 and earlier store an animation as one model a frame (PACK counts them):
  // T-Rex.vox's 8 frames stacked in one place gave 10,219 voxels where 1,655 distinct exist.
  const Blob file = voxFile({chunk("PACK", Bytes().i32(2).b), sizeChunk(3, 3, 3), xyziChunk({{2, 2, 2, 1}, {0, 0, 0, 1}}),
                             sizeChunk(5, 1, 1), xyziChunk({{4, 0, 0, 2}})});
  const VoxModelSet s = parseExact(file, "pack.vox");
  EXPECT_EQ(s.animationFrames, 2u);
  ASSERT_EQ(s.instances.size(), 1u);
  EXPECT_EQ(s.instances[0].model, 0u);
  EXPECT_EQ(s.instances[0].offset, (Int3{0, 0, 0}));  // at the origin, as placed by MagicaVoxel
  EXPECT_EQ(s.totalVoxels, 2u);
  EXPECT_EQ(s.fileVoxels, 3u);
  EXPECT_EQ(s.boundsMin, (Int3{0, 0, 0}));
  EXPECT_EQ(s.boundsMax, (Int3{2, 2, 2}));
  EXPECT_EQ(s.transformsApplied, 0u);
  // One model: no animation.
  EXPECT_EQ(parseExact(voxFile({sizeChunk(3, 3, 3), xyziChunk({{2, 2, 2, 1}})}), "one.vox").animationFrames, 1u);
  // With a scene graph, a shape listing three models is a three-frame animation; frame 0 placed.
  const Blob shape = chunk("nSHP", Bytes().i32(1).dict({}).i32(3).i32(0).dict({}).i32(1).dict({}).i32(1).dict({}).b);
  const VoxModelSet g = parseExact(voxFile({sizeChunk(3, 3, 3), xyziChunk({{2, 2, 2, 1}}), sizeChunk(5, 1, 1), xyziChunk({{4, 0, 0, 2}}),
                                            ntrn(0, 1), shape},
                                           200),
                                   "frames.vox");
  EXPECT_EQ(g.animationFrames, 3u);
  ASSERT_EQ(g.instances.size(), 1u);
  EXPECT_EQ(g.instances[0].model, 0u);
  EXPECT_EQ(g.totalVoxels, 1u);
}

TEST(VoxScene, UnknownChunksAreSkippedBySize) {
  const Blob matl = chunk("MATL", Bytes().i32(29).dict({{"_type", "_glass"}, {"_alpha", "0.5"}}).b);
  const Blob layr = chunk("LAYR", Bytes().i32(0).dict({}).i32(-1).b, chunk("NOTE", Bytes().i32(0).b));
  const Blob file = voxFile({chunk("rOBJ", Bytes().dict({{"_type", "_bloom"}}).b), sizeChunk(1, 1, 1),
                             xyziChunk({{0, 0, 0, 7}}), matl, layr, chunk("IMAP", Blob(256, 0))});
  const VoxModelSet s = parseExact(file, "unknown.vox");
  EXPECT_EQ(s.totalVoxels, 1u);
  EXPECT_EQ(s.skippedChunks, 4u);
}

TEST(VoxScene, EmptyFileBuildsAnAirTerrain) {
  const VoxModelSet s = parseExact(voxFile({}), "empty.vox");
  EXPECT_TRUE(s.empty());
  const VoxTerrain vt = buildVoxTerrain(s);
  EXPECT_EQ(vt.terrain->voxels().size(), (Int3{4, 4, 4}));
  EXPECT_EQ(vt.terrain->voxels().storedChunkCount(), 0u);
  VoxTerrainOptions noMargin;
  noMargin.margin = 0;
  EXPECT_EQ(buildVoxTerrain(s, {}, noMargin).terrain->voxels().size(), (Int3{1, 1, 1}));
}

}  // namespace
}  // namespace bw
