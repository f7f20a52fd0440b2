// The .brs reader against the real Lighthouse_Island save (counts and extents computed
// independently of the reader) and against hand-built saves of versions 8, 9 and 10, plus bad
// files: each must fail with InvalidInput naming the file, never crash or half-load.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <map>
#include <string>
#include <vector>
#include <zlib.h>

#include "collision/bricks/brick.h"
#include "collision/bricks/brick_geometry.h"
#include "collision/bricks/brick_grid.h"
#include "collision/content/brs_reader.h"
#include "collision/content/brs_test_files.h"
#include "collision/core/argument_checks.h"

namespace bw {
namespace {

using namespace test::brsfile;

class BrsLighthouse : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(std::filesystem::exists(lighthousePath()))
        << "missing " << lighthousePath() << ": the shared data folder must sit next to the repository";
  }
};

TEST_F(BrsLighthouse, HeaderAndAssetHistogram) {
  const BrsLoadResult& r = lighthouse();
  EXPECT_EQ(r.version, 8);
  EXPECT_EQ(r.mapName, "Plate");
  EXPECT_EQ(r.author, "Rothary");
  EXPECT_EQ(r.totalBricks, 25'427u);
  EXPECT_EQ(r.records.size(), 25'427u);
  EXPECT_EQ(r.collisionOff, 0u);
  EXPECT_EQ(r.bricks.size(), 25'427u);
  // Figures from the issue and from an independent Python walk of the same bit layout.
  EXPECT_EQ(r.assetCounts.at("PB_DefaultSideWedgeTile"), 7'443u);
  EXPECT_EQ(r.assetCounts.at("PB_DefaultTile"), 7'342u);
  EXPECT_EQ(r.assetCounts.at("PB_DefaultBrick"), 2'543u);
  EXPECT_EQ(r.assetCounts.at("PB_DefaultWedge"), 1'960u);
  EXPECT_EQ(r.assetCounts.at("B_Small_Flower"), 1'641u);
  EXPECT_EQ(r.assetCounts.at("B_Fern"), 1'200u);
  EXPECT_EQ(r.assetCounts.at("PB_DefaultSideWedge"), 1'148u);
  EXPECT_EQ(r.assetCounts.at("B_Flame"), 958u);
  EXPECT_EQ(r.assetCounts.at("PB_DefaultMicroBrick"), 227u);
  EXPECT_EQ(r.assetCounts.at("PB_DefaultRampCorner"), 63u);
  EXPECT_EQ(r.assetCounts.at("B_Bone"), 1u);
  EXPECT_EQ(r.assetCounts.size(), 36u);
  uint32_t sum = 0;
  for (const auto& [name, n] : r.assetCounts) sum += n;
  EXPECT_EQ(sum, r.totalBricks);
  uint32_t shapes = 0;
  for (const auto& [name, n] : r.shapeCounts) shapes += n;
  EXPECT_EQ(shapes, r.totalBricks);
  // Every asset of this save has a documented mapping.
  EXPECT_EQ(r.unknownAssets, 0u);
  // Side wedges (tile and full) and wedges, ramps: 7443 + 1148 + 1960 + 26.
  EXPECT_EQ(r.shapeCounts.at("wedge"), 10'577u);
  EXPECT_EQ(r.shapeCounts.at("corner_wedge"), 63u);
}

TEST_F(BrsLighthouse, EveryBrickValidAndProceduralSizesKept) {
  const BrsLoadResult& r = lighthouse();
  for (size_t i = 0; i < r.bricks.size(); ++i) EXPECT_NO_THROW(validateBrick(r.bricks[i], "lighthouse brick"));
  for (const BrsBrickRecord& rec : r.records) {
    ASSERT_GE(rec.brick, 0);
    const Brick& b = r.bricks[size_t(rec.brick)];
    const std::string& asset = r.assetNames[rec.asset];
    EXPECT_EQ(rec.hasSize, asset.rfind("PB_", 0) == 0) << asset;
    // Canonical half extents are Brickadia's size (permuted for folded shapes) times 0.04.
    std::vector<float> a{b.halfSize.x(), b.halfSize.y(), b.halfSize.z()};
    std::vector<float> e{rec.halfSizeUsed[0] * 0.04f, rec.halfSizeUsed[1] * 0.04f, rec.halfSizeUsed[2] * 0.04f};
    std::sort(a.begin(), a.end());
    std::sort(e.begin(), e.end());
    for (int k = 0; k < 3; ++k) EXPECT_FLOAT_EQ(a[size_t(k)], e[size_t(k)]) << asset;
  }
}

// World half extent along `axis` of a Brickadia brick, by the axis-permutation rule of the
// public brs-js bounds helper (X directions swap x and z, Y directions cycle, odd rotations swap
// x and y) — a second path, independent of our rotation tables.
uint32_t worldHalfExtent(const BrsBrickRecord& rec, int axis) {
  int a = axis;
  if (rec.direction <= 1) {
    a = a == 0 ? 2 : a == 2 ? 0 : a;
  } else if (rec.direction <= 3) {
    a = a == 0 ? 1 : a == 1 ? 2 : 0;
  }
  if (rec.rotation & 1) a = a == 0 ? 1 : a == 1 ? 0 : a;
  return rec.halfSizeUsed[a];
}

TEST_F(BrsLighthouse, BoundsMatchAnIndependentComputation) {
  const BrsLoadResult& r = lighthouse();
  int64_t lo[3] = {INT64_MAX, INT64_MAX, INT64_MAX}, hi[3] = {INT64_MIN, INT64_MIN, INT64_MIN};
  for (const BrsBrickRecord& rec : r.records)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min<int64_t>(lo[k], int64_t(rec.position[k]) - worldHalfExtent(rec, k));
      hi[k] = std::max<int64_t>(hi[k], int64_t(rec.position[k]) + worldHalfExtent(rec, k));
    }
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(r.bounds.min[k], lo[k] * 0.04, 1e-3) << "axis " << k;
    EXPECT_NEAR(r.bounds.max[k], hi[k] * 0.04, 1e-3) << "axis " << k;
  }
  // Each brick's own bounds agree with the permutation rule, so the rotation mapping moves
  // every axis where Brickadia does.
  for (const BrsBrickRecord& rec : r.records) {
    const Aabb box = brickBounds(r.bricks[size_t(rec.brick)]);
    for (int k = 0; k < 3; ++k) {
      ASSERT_NEAR(box.max[k] - box.min[k], 2 * 0.04 * worldHalfExtent(rec, k), 1e-3) << "axis " << k;
      ASSERT_TRUE(r.bounds.contains(box));
    }
  }
  // Tight: some brick touches each face of the bounds.
  for (int k = 0; k < 3; ++k) {
    bool touchMin = false, touchMax = false;
    for (const Brick& b : r.bricks) {
      const Aabb box = brickBounds(b);
      touchMin |= box.min[k] == r.bounds.min[k];
      touchMax |= box.max[k] == r.bounds.max[k];
    }
    EXPECT_TRUE(touchMin && touchMax) << "axis " << k;
  }
}

// The slope of every wedge-like brick points where the build leaves room: a point inside our
// shape (in the half the slope keeps) is never inside a neighbour, while the cut-off half is
// often filled by one (side wedges pair up into rectangles). A wrong rotation, fold or mirror
// would put our solid half where the neighbours are.
TEST_F(BrsLighthouse, SlopesFaceWhereNeighboursLeaveRoom) {
  const BrsLoadResult& r = lighthouse();
  BrickGrid grid(BrickGrid::Config(uint32_t(r.bricks.size()) + 1024));
  std::vector<uint32_t> brickOfId;
  for (uint32_t i = 0; i < r.bricks.size(); ++i) {
    const uint32_t id = grid.placeBrick(r.bricks[i]);
    if (id >= brickOfId.size()) brickOfId.resize(id + 1, ~0u);
    brickOfId[id] = i;
  }
  std::vector<uint32_t> hits;
  auto occupiedByOthers = [&](uint32_t self, const Vec3f& local) {
    const Brick& b = r.bricks[self];
    const Vec3f p = b.position + b.rotation.apply(local.cwiseProduct(b.halfSize));
    hits.clear();
    grid.overlapBricks(Aabb::fromCenterHalf(p, Vec3f::Constant(1e-4f)), ~0u, hits);
    for (uint32_t id : hits)
      if (brickOfId[id] != self && brickContains(grid.brick(id), p, -1e-4f)) return true;
    return false;
  };
  std::map<std::string, std::pair<uint32_t, uint32_t>> solidCutCounts;  // per asset: solid half hit, cut half hit
  uint32_t sideWedges = 0;
  for (const BrsBrickRecord& rec : r.records) {
    const uint32_t i = uint32_t(rec.brick);
    const Brick& b = r.bricks[i];
    if (b.shape != BrickShape::Wedge && b.shape != BrickShape::CornerWedge) continue;
    const bool wedge = b.shape == BrickShape::Wedge;
    auto& c = solidCutCounts[r.assetNames[rec.asset]];
    c.first += occupiedByOthers(i, wedge ? Vec3f(-0.5f, 0.f, -0.5f) : Vec3f(-0.6f, -0.6f, -0.5f));
    c.second += occupiedByOthers(i, wedge ? Vec3f(0.5f, 0.f, 0.5f) : Vec3f(0.6f, 0.6f, 0.5f));
    sideWedges += r.assetNames[rec.asset].find("SideWedge") != std::string::npos;
  }
  for (const auto& [asset, c] : solidCutCounts) EXPECT_EQ(c.first, 0u) << asset << ": solid half overlaps neighbours";
  const uint32_t cutFilled = solidCutCounts["PB_DefaultSideWedge"].second + solidCutCounts["PB_DefaultSideWedgeTile"].second;
  EXPECT_GT(cutFilled, sideWedges / 4) << "side wedges should often pair up with a neighbour in their cut-off half";
}

TEST(BrsOrientation, DefaultIsIdentityAndAllTwentyFourAreDistinct) {
  EXPECT_EQ(brsOrientation(4, 0), AxisRotation::identity());
  std::vector<int> seen;
  for (int d = 0; d < 6; ++d)
    for (int r = 0; r < 4; ++r) {
      const AxisRotation rot = brsOrientation(d, r);
      seen.push_back(rot.index());
      // Local +Z lands on Brickadia's direction, as it does on ours.
      EXPECT_EQ(rot.direction(), d);
    }
  std::sort(seen.begin(), seen.end());
  EXPECT_EQ(std::unique(seen.begin(), seen.end()), seen.end());
  // +Z rotations turn counter-clockwise about +Z: local +X goes to +Y after one quarter turn.
  EXPECT_TRUE(brsOrientation(4, 1).apply(Vec3f(1, 0, 0)).isApprox(Vec3f(0, 1, 0)));
  // Brickadia's X+ (rotation 0) sends local x to world z and local y to world -y.
  EXPECT_TRUE(brsOrientation(0, 0).apply(Vec3f(1, 0, 0)).isApprox(Vec3f(0, 0, 1)));
  EXPECT_TRUE(brsOrientation(0, 0).apply(Vec3f(0, 1, 0)).isApprox(Vec3f(0, -1, 0)));
  EXPECT_THROW(brsOrientation(6, 0), InvalidInput);
}

// ---- hand-built saves (brs_test_files.h) ----

TEST(BrsSynthetic, VersionsEightToTenReadTheSameBricks) {
  for (int version : {8, 9, 10}) {
    SCOPED_TRACE("version " + std::to_string(version));
    const auto bytes = buildSave(version, kAssets, sampleBricks());
    const BrsLoadResult r = parseBrs(bytes.data(), bytes.size(), "synthetic.brs");
    EXPECT_EQ(r.version, version);
    EXPECT_EQ(r.gameVersion, 1234);
    EXPECT_EQ(r.mapName, "TestMap");
    EXPECT_EQ(r.author, "Tester");
    EXPECT_EQ(r.totalBricks, 7u);
    EXPECT_EQ(r.collisionOff, 1u);
    ASSERT_EQ(r.bricks.size(), 6u);
    EXPECT_EQ(r.unknownAssets, 2u);
    EXPECT_EQ(r.assetCounts.at("PB_DefaultBrick"), 2u);
    EXPECT_EQ(r.assetCounts.at("PB_DefaultWedge"), 1u);
    EXPECT_EQ(r.shapeCounts.at("box"), 4u);
    EXPECT_EQ(r.shapeCounts.at("wedge"), 2u);
    EXPECT_EQ(r.shapeCounts.at("cylinder"), 1u);
    const auto bricks = sampleBricks();
    for (size_t i = 0; i < bricks.size(); ++i) {
      const BrsBrickRecord& rec = r.records[i];
      EXPECT_EQ(rec.asset, bricks[i].asset);
      EXPECT_EQ(rec.direction, bricks[i].direction);
      EXPECT_EQ(rec.rotation, bricks[i].rotation);
      EXPECT_EQ(rec.collision, bricks[i].collision);
      for (int k = 0; k < 3; ++k) EXPECT_EQ(rec.position[k], bricks[i].pos[k]);
      if (bricks[i].hasSize) {
        for (int k = 0; k < 3; ++k) EXPECT_EQ(rec.size[k], bricks[i].size[k]);
      }
    }
    EXPECT_EQ(r.records[5].brick, -1);
    // The default-oriented brick is an unrotated box at position * 0.04.
    const Brick& b0 = r.bricks[0];
    EXPECT_EQ(b0.shape, BrickShape::Box);
    EXPECT_EQ(b0.rotation, AxisRotation::identity());
    EXPECT_TRUE(b0.halfSize.isApprox(Vec3f(0.4f, 0.8f, 0.24f)));
    EXPECT_TRUE(b0.position.isApprox(Vec3f(0, 0, 0.24f)));
    // The side wedge tile keeps Brickadia's footprint (30 x 10 units turned a quarter: 10 x 30).
    const Aabb w = brickBounds(r.bricks[1]);
    EXPECT_TRUE(w.extent().isApprox(Vec3f(0.4f, 1.2f, 0.16f))) << w.extent().transpose();
    EXPECT_EQ(r.bricks[1].shape, BrickShape::Wedge);
    // The 1x1 round lies along +X: its 12-unit height is now along x.
    const Aabb round = brickBounds(r.bricks[2]);
    EXPECT_TRUE(round.extent().isApprox(Vec3f(0.48f, 0.4f, 0.4f))) << round.extent().transpose();
    // Unknown fixed asset: a 1x1 brick; unknown procedural asset: a box of its size.
    EXPECT_TRUE(r.bricks[3].halfSize.isApprox(Vec3f(0.2f, 0.2f, 0.24f)));
    // PB_DefaultArch (30 units along local y) facing +Y: local y becomes world x.
    EXPECT_TRUE(brickBounds(r.bricks[4]).extent().isApprox(Vec3f(2.4f, 0.96f, 0.4f)))
        << brickBounds(r.bricks[4]).extent().transpose();
    EXPECT_TRUE(r.bounds.contains(brickBounds(r.bricks[5])));
  }
}

TEST(BrsSynthetic, EmptySaveLoads) {
  const auto bytes = buildSave(10, {}, {});
  const BrsLoadResult r = parseBrs(bytes.data(), bytes.size(), "empty_save.brs");
  EXPECT_EQ(r.totalBricks, 0u);
  EXPECT_TRUE(r.bricks.empty());
  EXPECT_TRUE(r.bounds.isEmpty());
}

TEST(BrsBadFiles, EmptyWrongMagicAndVersion) {
  expectInvalid({}, "empty.brs", "empty");
  expectInvalid({'B', 'R'}, "short.brs", "truncated");
  auto bytes = buildSave(8, kAssets, sampleBricks());
  auto magic = bytes;
  magic[0] = 'X';
  expectInvalid(magic, "magic.brs", "wrong magic");
  for (uint16_t v : {7, 11, 0xFFFF}) {
    auto ver = bytes;
    ver[3] = uint8_t(v & 0xFF);
    ver[4] = uint8_t(v >> 8);
    expectInvalid(ver, "version.brs", "unsupported version " + std::to_string(v));
  }
  EXPECT_THROW(loadBrs("/nonexistent/dir/missing.brs"), InvalidInput);
}

TEST(BrsBadFiles, CountsAndSizesThatExceedTheData) {
  // More bricks claimed than the bit stream holds.
  expectInvalid(buildSave(9, kAssets, sampleBricks(), 1'000'000), "count.brs", "exceeds the data");
  expectInvalid(buildSave(9, kAssets, sampleBricks(), 8), "count8.brs", "truncated record");
  // A zero size and an asset index beyond the table.
  auto zero = sampleBricks();
  zero[0].size[1] = 0;
  expectInvalid(buildSave(8, kAssets, zero), "zero.brs", "size 0 is out of range");
  auto huge = sampleBricks();
  huge[1].size[0] = 5'000'000;
  expectInvalid(buildSave(8, kAssets, huge), "huge.brs", "out of range");
  // With one asset the index still takes one bit (max(count, 2)), so index 1 can be stored.
  std::vector<TestBrick> one{{1, true, {5, 5, 6}, {0, 0, 0}, 4, 0, true}};
  expectInvalid(buildSave(10, {"PB_DefaultBrick"}, one), "asset.brs", "asset index 1 is out of range");
}

TEST_F(BrsLighthouse, TruncatedAndPatchedCopiesFailCleanly) {
  const std::vector<uint8_t> full = readFile(lighthousePath());
  ASSERT_GT(full.size(), 1'000'000u);
  // Every 1/16 of the file, plus the edges of the last section.
  std::vector<size_t> cuts;
  for (int k = 0; k < 16; ++k) cuts.push_back(full.size() * size_t(k) / 16);
  cuts.push_back(full.size() - 1);
  cuts.push_back(full.size() - 100);
  for (size_t cut : cuts) {
    SCOPED_TRACE("cut at " + std::to_string(cut));
    expectInvalid(std::vector<uint8_t>(full.begin(), full.begin() + long(cut)), "Lighthouse_cut.brs",
                  cut == 0 ? "empty" : "truncated");
  }
  // header1's compressed size (at byte 13, after magic, version, game version and the
  // uncompressed size) made larger than the rest of the file.
  auto big = full;
  const int32_t bigSizes[2] = {200'000'000, 100'000'000};
  std::memcpy(&big[9], bigSizes, 8);
  expectInvalid(big, "Lighthouse_big.brs", "header1 section: truncated: needs 100000000 bytes");
  // Corrupt zlib data in header1.
  auto corrupt = full;
  for (size_t i = 20; i < 40; ++i) corrupt[i] ^= 0x5A;
  expectInvalid(corrupt, "Lighthouse_zlib.brs", "header1 section: zlib data is corrupt");
  // Version patched in the copy.
  auto v = full;
  v[3] = 11;
  expectInvalid(v, "Lighthouse_v11.brs", "unsupported version 11");
  // Brick count in header1 raised far beyond the brick data: header1 is compressed, so
  // rebuild it with the count patched.
  const uint8_t* p = full.data() + 9;
  int32_t un = 0, cn = 0;
  std::memcpy(&un, p, 4);
  std::memcpy(&cn, p + 4, 4);
  std::vector<uint8_t> h1(size_t(un), 0);
  uLongf hn = uLongf(un);
  ASSERT_EQ(uncompress(h1.data(), &hn, p + 8, uLong(cn)), Z_OK);
  const int32_t tooMany = 10'000'000;
  std::memcpy(&h1[h1.size() - 4], &tooMany, 4);
  Bytes patched;
  patched.b.assign(full.begin(), full.begin() + 9);
  patched.i32(un);
  patched.i32(0);
  patched.append(h1);
  patched.b.insert(patched.b.end(), full.begin() + 9 + 8 + cn, full.end());
  expectInvalid(patched.b, "Lighthouse_count.brs", "brick count 10000000 exceeds the data");
  // A few bytes of the brick stream flipped: reading either fails cleanly or yields valid bricks.
  for (size_t at : {full.size() / 2, full.size() * 3 / 4}) {
    auto flipped = full;
    flipped[at] ^= 0xFF;
    try {
      const BrsLoadResult r = parseBrs(flipped.data(), flipped.size(), "flipped.brs");
      for (const Brick& b : r.bricks) validateBrick(b, "flipped");
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find("flipped.brs"), std::string::npos);
    }
  }
}

}  // namespace
}  // namespace bw
