// The .vox reader against the real monu6 and nature models (counts, bounds and palette checked
// against a separate minimal chunk scan written here), against hand-built files (scene-graph
// placement, palettes, material mapping, terrain round trips) and against bad files: each must
// fail with InvalidInput naming the file, never crash or half-load.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "collision/content/vox_reader.h"
#include "collision/core/argument_checks.h"
#include "collision/terrain/terrain.h"

namespace bw {
namespace {

namespace fs = std::filesystem;

// The shared data folder is a sibling of the repository: <repo>/../shared/data.
fs::path dataPath(const std::string& name) {
  const fs::path repo = fs::path(__FILE__).parent_path().parent_path().parent_path();
  const fs::path candidate = repo / ".." / "shared" / "data" / name;
  if (fs::exists(candidate)) return candidate;
  for (fs::path dir = fs::current_path(); !dir.empty(); dir = dir.parent_path()) {
    const fs::path p = dir / ".." / "shared" / "data" / name;
    if (fs::exists(p)) return p;
    if (dir == dir.parent_path()) break;
  }
  return candidate;
}

std::vector<uint8_t> readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// ---- a minimal independent scan of a well-formed file (no checks beyond what it needs) ----

struct ScanResult {
  std::vector<std::array<int32_t, 3>> sizes;
  uint64_t voxels = 0;
  std::array<uint64_t, 256> histogram{};
  std::array<int, 3> tightLo{255, 255, 255}, tightHi{-1, -1, -1};
  std::vector<std::array<uint8_t, 4>> rgba;  // raw entries, file order
  bool sceneGraph = false;
};

int32_t le32(const std::vector<uint8_t>& b, size_t at) {
  int32_t v;
  std::memcpy(&v, b.data() + at, 4);  // little-endian host (x86-64, aarch64)
  return v;
}

ScanResult scanVox(const std::vector<uint8_t>& b) {
  ScanResult r;
  const size_t childrenAt = 20 + size_t(le32(b, 12));
  const size_t end = childrenAt + size_t(le32(b, 16));
  for (size_t at = childrenAt; at < end;) {
    const std::string id(reinterpret_cast<const char*>(b.data() + at), 4);
    const size_t n = size_t(le32(b, at + 4)), m = size_t(le32(b, at + 8));
    const size_t c = at + 12;
    if (id == "SIZE") r.sizes.push_back({le32(b, c), le32(b, c + 4), le32(b, c + 8)});
    if (id == "XYZI") {
      const size_t count = size_t(le32(b, c));
      r.voxels += count;
      for (size_t i = 0; i < count; ++i) {
        const uint8_t* v = b.data() + c + 4 + 4 * i;
        ++r.histogram[v[3]];
        for (int a = 0; a < 3; ++a) {
          r.tightLo[size_t(a)] = std::min<int>(r.tightLo[size_t(a)], v[a]);
          r.tightHi[size_t(a)] = std::max<int>(r.tightHi[size_t(a)], v[a]);
        }
      }
    }
    if (id == "RGBA")
      for (size_t i = 0; i < 256; ++i) r.rgba.push_back({b[c + 4 * i], b[c + 4 * i + 1], b[c + 4 * i + 2], b[c + 4 * i + 3]});
    if (id == "nTRN" || id == "nGRP" || id == "nSHP") r.sceneGraph = true;
    at = c + n + m;
  }
  return r;
}

// ---- a test-only writer ----

struct Bytes {
  std::vector<uint8_t> b;
  Bytes& i32(int32_t v) {
    for (int i = 0; i < 4; ++i) b.push_back(uint8_t(uint32_t(v) >> (8 * i)));
    return *this;
  }
  Bytes& str(const std::string& s) {
    i32(int32_t(s.size()));
    b.insert(b.end(), s.begin(), s.end());
    return *this;
  }
  Bytes& dict(const std::vector<std::pair<std::string, std::string>>& kv) {
    i32(int32_t(kv.size()));
    for (const auto& [k, v] : kv) str(k).str(v);
    return *this;
  }
  Bytes& raw(const std::vector<uint8_t>& more) {
    b.insert(b.end(), more.begin(), more.end());
    return *this;
  }
};

using Blob = std::vector<uint8_t>;

Blob chunk(const std::string& id, const Blob& content, const Blob& children = {}) {
  Bytes out;
  out.b.assign(id.begin(), id.end());
  out.i32(int32_t(content.size())).i32(int32_t(children.size())).raw(content).raw(children);
  return out.b;
}

Blob voxFile(const std::vector<Blob>& mainChildren, int version = 150) {
  Blob children;
  for (const Blob& c : mainChildren) children.insert(children.end(), c.begin(), c.end());
  Bytes out;
  out.b = {'V', 'O', 'X', ' '};
  out.i32(version).raw(chunk("MAIN", {}, children));
  return out.b;
}

Blob sizeChunk(int x, int y, int z) { return chunk("SIZE", Bytes().i32(x).i32(y).i32(z).b); }
Blob xyziChunk(const std::vector<VoxVoxel>& voxels) {
  Bytes c;
  c.i32(int32_t(voxels.size()));
  for (const VoxVoxel& v : voxels) c.b.insert(c.b.end(), {v.x, v.y, v.z, v.colorIndex});
  return chunk("XYZI", c.b);
}
Blob rgbaChunk(const std::array<VoxRgba, 256>& byIndex) {
  Bytes c;
  for (int i = 1; i <= 256; ++i) {
    const VoxRgba p = byIndex[size_t(i & 255)];  // entry i - 1 is palette index i; the last is unused
    c.b.insert(c.b.end(), {p.r, p.g, p.b, p.a});
  }
  return chunk("RGBA", c.b);
}
Blob ntrn(int id, int child, const std::string& t = "", const std::string& r = "") {
  std::vector<std::pair<std::string, std::string>> frame;
  if (!r.empty()) frame.emplace_back("_r", r);
  if (!t.empty()) frame.emplace_back("_t", t);
  return chunk("nTRN", Bytes().i32(id).dict({{"_name", "t"}}).i32(child).i32(-1).i32(0).i32(1).dict(frame).b);
}
Blob ngrp(int id, const std::vector<int>& children) {
  Bytes c;
  c.i32(id).dict({}).i32(int32_t(children.size()));
  for (int ch : children) c.i32(ch);
  return chunk("nGRP", c.b);
}
Blob nshp(int id, int model) { return chunk("nSHP", Bytes().i32(id).dict({}).i32(1).i32(model).dict({}).b); }

// Parses an exact-size copy so that ASan catches any over-read.
VoxModelSet parseExact(const Blob& bytes, const std::string& name) {
  const Blob exact(bytes);
  return parseVox(exact.empty() ? nullptr : exact.data(), exact.size(), name);
}

void expectInvalid(const Blob& bytes, const std::string& name, const std::string& fragment) {
  try {
    parseExact(bytes, name);
    ADD_FAILURE() << name << ": expected InvalidInput containing \"" << fragment << "\"";
  } catch (const InvalidInput& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(name + ": ", 0), 0u) << msg;
    EXPECT_NE(msg.find(fragment), std::string::npos) << "message: " << msg << "\nexpected: " << fragment;
  }
}

uint64_t countStoredVoxels(const Terrain& t, uint64_t* water = nullptr) {
  uint64_t n = 0, w = 0;
  t.voxels().forEachChunk([&](const Int3& c, const VoxelChunk& chunk) {
    for (int z = 0; z < kChunkSize; ++z)
      for (int y = 0; y < kChunkSize; ++y)
        for (int x = 0; x < kChunkSize; ++x) {
          const Voxel v = t.voxels().get({c.x * kChunkSize + x, c.y * kChunkSize + y, c.z * kChunkSize + z});
          if (!v.isAir()) ++n;
          if (v.isWater()) ++w;
        }
    (void)chunk;
  });
  if (water) *water = w;
  return n;
}

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

// root nTRN 0 (_t 1 1 1) -> nGRP 1 -> { nTRN 2 (_t 10 0 0) -> nSHP 3 (model 0),
//                                       nTRN 4 (_t -5 3 7) -> nSHP 5 (model 1) }
Blob twoModelScene() {
  return voxFile({sizeChunk(4, 4, 4), xyziChunk({{0, 0, 0, 10}, {3, 3, 3, 11}}),  //
                  sizeChunk(3, 5, 1), xyziChunk({{0, 0, 0, 20}, {2, 4, 0, 21}, {1, 2, 0, 22}}),
                  ntrn(0, 1, "1 1 1"), ngrp(1, {2, 4}), ntrn(2, 3, "10 0 0"), nshp(3, 0), ntrn(4, 5, "-5 3 7"),
                  nshp(5, 1)},
                 200);
}

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

TEST(VoxScene, WithoutASceneGraphModelsSitAtTheOrigin) {
  const Blob file = voxFile({chunk("PACK", Bytes().i32(2).b), sizeChunk(3, 3, 3), xyziChunk({{2, 2, 2, 1}}),
                             sizeChunk(5, 1, 1), xyziChunk({{4, 0, 0, 2}})});
  const VoxModelSet s = parseExact(file, "pack.vox");
  ASSERT_EQ(s.instances.size(), 2u);
  EXPECT_EQ(s.instances[0].offset, (Int3{0, 0, 0}));
  EXPECT_EQ(s.instances[1].offset, (Int3{0, 0, 0}));
  EXPECT_EQ(s.boundsMin, (Int3{0, 0, 0}));
  EXPECT_EQ(s.boundsMax, (Int3{4, 2, 2}));
  EXPECT_EQ(s.transformsApplied, 0u);
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

// ---- bad files ----

TEST(VoxBadFiles, HeaderAndChunkProblemsNameTheFileAndTheProblem) {
  const Blob good = voxFile({sizeChunk(2, 2, 2), xyziChunk({{0, 0, 0, 1}})});
  ASSERT_NO_THROW(parseExact(good, "good.vox"));

  Blob magic = good;
  magic[0] = 'W';
  expectInvalid(magic, "magic.vox", "not a MagicaVoxel file");
  expectInvalid(voxFile({}, 151), "v151.vox", "unsupported version 151");
  expectInvalid(Blob{'V', 'O', 'X'}, "short.vox", "truncated");
  expectInvalid(Blob{}, "zero.vox", "truncated");
  Blob notMain = good;
  notMain[8] = 'X';
  expectInvalid(notMain, "notmain.vox", "expected \"MAIN\"");

  // MAIN's children size larger than the data.
  Blob mainTooBig = good;
  mainTooBig[16] += 4;
  expectInvalid(mainTooBig, "mainbig.vox", "MAIN chunk: truncated");
  // A child whose content exceeds MAIN.
  Blob childTooBig = good;
  childTooBig[20 + 4] = 200;  // SIZE content size
  expectInvalid(childTooBig, "childbig.vox", "exceed MAIN");
  Blob negative = good;
  negative[20 + 8 + 3] = 0x80;  // SIZE children size negative
  expectInvalid(negative, "negative.vox", "negative sizes");
  // Content shorter than its fields.
  expectInvalid(voxFile({chunk("SIZE", Bytes().i32(2).i32(2).b), xyziChunk({})}), "shortsize.vox",
                "SIZE chunk 0: truncated: size z");

  // XYZI count beyond the chunk.
  Blob count = voxFile({sizeChunk(2, 2, 2), chunk("XYZI", Bytes().i32(3).i32(0).i32(0).b)});
  expectInvalid(count, "count.vox", "XYZI chunk 1: numVoxels 3 exceeds the chunk");
  expectInvalid(voxFile({sizeChunk(2, 2, 2), xyziChunk({{0, 2, 0, 1}})}), "outside.vox",
                "voxel 0 at (0, 2, 0) is outside SIZE (2, 2, 2)");
  expectInvalid(voxFile({sizeChunk(2, 2, 2), xyziChunk({{0, 0, 0, 0}})}), "index0.vox", "colour index 0");
  expectInvalid(voxFile({sizeChunk(0, 2, 2), xyziChunk({})}), "size0.vox", "is outside [1, 256]");
  expectInvalid(voxFile({sizeChunk(2, 257, 2), xyziChunk({})}), "size257.vox", "is outside [1, 256]");
  expectInvalid(voxFile({xyziChunk({})}), "nosize.vox", "XYZI chunk without a SIZE");
  expectInvalid(voxFile({sizeChunk(2, 2, 2)}), "noxyzi.vox", "last SIZE chunk has no XYZI");
  expectInvalid(voxFile({sizeChunk(2, 2, 2), sizeChunk(2, 2, 2), xyziChunk({})}), "twosize.vox",
                "not followed by its XYZI");
  expectInvalid(voxFile({chunk("PACK", Bytes().i32(2).b), sizeChunk(2, 2, 2), xyziChunk({})}), "pack.vox",
                "numModels 2 but the file has 1");
  expectInvalid(voxFile({sizeChunk(2, 2, 2), xyziChunk({}), chunk("RGBA", Blob(100, 0))}), "rgba.vox",
                "RGBA chunk 2: truncated: palette");
}

TEST(VoxBadFiles, SceneGraphProblems) {
  const Blob model = voxFile({sizeChunk(2, 2, 2), xyziChunk({{0, 0, 0, 1}})});
  auto withNodes = [](std::vector<Blob> nodes) {
    std::vector<Blob> all = {sizeChunk(2, 2, 2), xyziChunk({{0, 0, 0, 1}})};
    all.insert(all.end(), nodes.begin(), nodes.end());
    return voxFile(all);
  };
  ASSERT_NO_THROW(parseExact(withNodes({ntrn(0, 1), nshp(1, 0)}), "ok.vox"));
  expectInvalid(withNodes({ntrn(0, 7), nshp(1, 0)}), "missing.vox", "node 7 is referenced but missing");
  expectInvalid(withNodes({ntrn(1, 2), nshp(2, 0)}), "noroot.vox", "has no root node 0");
  expectInvalid(withNodes({ntrn(0, 1), ngrp(1, {2}), ntrn(2, 1)}), "cycle.vox", "cycle through node 1");
  expectInvalid(withNodes({ntrn(0, 0)}), "selfcycle.vox", "cycle through node 0");
  expectInvalid(withNodes({ntrn(0, 1), nshp(1, 3)}), "model.vox", "names model 3 of 1");
  expectInvalid(withNodes({ntrn(0, 1), nshp(1, 0), nshp(1, 0)}), "dup.vox", "node id 1 is used by an earlier nSHP");
  expectInvalid(withNodes({ntrn(0, 1, "1 2"), nshp(1, 0)}), "t2.vox", "_t \"1 2\" is not three integers");
  expectInvalid(withNodes({ntrn(0, 1, "1 2 x"), nshp(1, 0)}), "tx.vox", "is not three integers");
  expectInvalid(withNodes({ntrn(0, 1, "99999999 0 0"), nshp(1, 0)}), "tbig.vox", "is beyond");
  expectInvalid(withNodes({ntrn(0, 1, "", "3"), nshp(1, 0)}), "r3.vox", "is not a rotation");
  expectInvalid(withNodes({ntrn(0, 1, "", "200"), nshp(1, 0)}), "r200.vox", "not a rotation byte");
  // A DICT whose count exceeds the chunk.
  expectInvalid(withNodes({chunk("nGRP", Bytes().i32(0).i32(1000).b)}), "dict.vox", "exceeds the chunk");
  // Deep chains are refused before the stack suffers.
  std::vector<Blob> chain;
  for (int i = 0; i < 400; ++i) chain.push_back(ngrp(i, {i + 1}));
  chain.push_back(nshp(400, 0));
  expectInvalid(withNodes(chain), "deep.vox", "deeper than 256");
  // Exponential instancing is capped: 20 levels of groups with two edges to the same child.
  std::vector<Blob> fan;
  for (int i = 0; i < 20; ++i) fan.push_back(ngrp(i, {i + 1, i + 1}));
  fan.push_back(nshp(20, 0));
  expectInvalid(withNodes(fan), "fan.vox", "more than 65536 instances");
  // 65536 instances of a 16,385-voxel model place more than 2^30 voxels.
  std::vector<Blob> many = {sizeChunk(32, 32, 32), xyziChunk(std::vector<VoxVoxel>(16385, VoxVoxel{1, 2, 3, 4}))};
  for (int i = 0; i < 16; ++i) many.push_back(ngrp(i, {i + 1, i + 1}));
  many.push_back(nshp(16, 0));
  expectInvalid(voxFile(many), "many.vox", "places more than 1073741824 voxels");
  (void)model;
}

TEST(VoxBadFiles, TruncatedRealFilesAlwaysThrow) {
  for (const char* name : {"monu6.vox", "nature.vox"}) {
    const Blob full = readFile(dataPath(name));
    ASSERT_GT(full.size(), 1000u) << name;
    std::vector<size_t> cuts;
    for (size_t i = 0; i < 64; ++i) cuts.push_back(i);
    std::mt19937_64 rng(20261121);
    std::uniform_int_distribution<size_t> pick(0, full.size() - 1);
    for (int i = 0; i < 60; ++i) cuts.push_back(pick(rng));
    cuts.push_back(full.size() - 1);
    for (size_t cut : cuts)
      expectInvalid(Blob(full.begin(), full.begin() + long(cut)), std::string("cut_") + name, "truncated");
    // The same cuts with MAIN's children size patched to what is left, so that parsing reaches
    // the cut chunk. A cut exactly at a chunk boundary leaves a valid (smaller) file.
    int rejected = 0;
    for (size_t cut : cuts) {
      if (cut < 20) continue;
      Blob b(full.begin(), full.begin() + long(cut));
      const uint32_t children = uint32_t(cut - 20);
      for (int i = 0; i < 4; ++i) b[16 + size_t(i)] = uint8_t(children >> (8 * i));
      try {
        parseExact(b, std::string("patched_") + name);
      } catch (const InvalidInput& e) {
        EXPECT_EQ(std::string(e.what()).rfind(std::string("patched_") + name + ": ", 0), 0u) << e.what();
        ++rejected;
      }
    }
    EXPECT_GE(rejected, int(cuts.size()) - 20 - 3) << name;
  }
}

TEST(VoxBadFiles, CorruptedSceneFilesThrowOrParseNeverCrash) {
  // Every truncation of a scene-graph file, and random byte corruptions inside it: each parse
  // must either succeed or throw InvalidInput (ASan checks the reads).
  const Blob base = twoModelScene();
  for (size_t cut = 0; cut < base.size(); ++cut)
    expectInvalid(Blob(base.begin(), base.begin() + long(cut)), "cut_scene.vox", "");
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<size_t> pos(0, base.size() - 1);
  std::uniform_int_distribution<int> byte(0, 255);
  int parsed = 0, rejected = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    Blob b = base;
    const int flips = 1 + trial % 3;
    for (int f = 0; f < flips; ++f) b[pos(rng)] = uint8_t(byte(rng));
    try {
      const VoxModelSet s = parseExact(b, "flip.vox");
      ++parsed;
      if (!s.empty() && s.boundsMax.x - s.boundsMin.x < 4096 && s.boundsMax.y - s.boundsMin.y < 4096 &&
          s.boundsMax.z - s.boundsMin.z < 4096) (void)buildVoxTerrain(s);
    } catch (const InvalidInput&) {
      ++rejected;
    }
  }
  EXPECT_GT(rejected, 0);
  EXPECT_GT(parsed, 0);
}

TEST(VoxBadFiles, MissingFileNamesThePath) {
  try {
    loadVox("/nonexistent/dir/model.vox");
    ADD_FAILURE();
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/model.vox: file: cannot be opened"), std::string::npos);
  }
}

}  // namespace
}  // namespace bw
