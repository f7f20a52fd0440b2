// The .brs components section: Lighthouse_Island's two light components decoded to their last
// byte and turned into lights, hand-built components of every type the writer knows (unaligned
// strings included) in saves of versions 8 to 10, and corrupt component data, which must fail
// with InvalidInput naming the file, `components` and the component, never crash.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <gtest/gtest.h>
#include <limits>
#include <map>
#include <string>
#include <vector>
#include <zlib.h>

#include "collision/content/brs_components.h"
#include "collision/content/brs_reader.h"
#include "collision/content/brs_test_files.h"
#include "collision/core/argument_checks.h"

namespace bw {
namespace {

using namespace test::brsfile;

// Lighthouse_Island's components section, uncompressed, found by walking the section headers
// (magic, version, game version; header1, header2, the preview, bricks, components).
std::vector<uint8_t> lighthouseComponentsSection() {
  const std::vector<uint8_t> f = readFile(lighthousePath());
  size_t at = 9;
  auto section = [&]() {
    int32_t un = 0, cn = 0;
    if (at + 8 > f.size()) return std::vector<uint8_t>{};
    std::memcpy(&un, &f[at], 4);
    std::memcpy(&cn, &f[at + 4], 4);
    at += 8;
    if (un < 0 || cn < 0) return std::vector<uint8_t>{};
    const size_t stored = cn == 0 ? size_t(un) : size_t(cn);
    if (at + stored > f.size()) return std::vector<uint8_t>{};
    std::vector<uint8_t> raw(static_cast<size_t>(un));
    if (cn == 0) {
      std::memcpy(raw.data(), &f[at], raw.size());
    } else {
      uLongf n = uLongf(un);
      if (uncompress(raw.data(), &n, &f[at], uLong(cn)) != Z_OK) return std::vector<uint8_t>{};
    }
    at += stored;
    return raw;
  };
  section();
  section();
  if (at < f.size() && f[at++] != 0) {
    int32_t len = 0;
    std::memcpy(&len, &f[at], 4);
    at += 4 + size_t(len);
  }
  section();
  return section();
}

class BrsLighthouseComponents : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(std::filesystem::exists(lighthousePath()))
        << "missing " << lighthousePath() << ": the shared data folder must sit next to the repository";
  }
};

using Properties = std::vector<std::pair<std::string, std::string>>;

Properties propertiesOf(const brs::Component& c) {
  Properties out;
  for (const brs::ComponentProperty& p : c.properties) out.emplace_back(p.name, p.type);
  return out;
}

// The decoder reads every value by its type and must land within the last byte of each
// component (714 and 1017 bytes), so these names, types and counts are checked by the file.
TEST_F(BrsLighthouseComponents, BothLightComponentsDecodeToTheirLastByte) {
  const std::vector<uint8_t> section = lighthouseComponentsSection();
  ASSERT_EQ(section.size(), 1780u);
  const std::vector<brs::Component> cs = brs::readComponents(section, 25'427, "Lighthouse_Island.brs");
  ASSERT_EQ(cs.size(), 2u);
  EXPECT_EQ(cs[0].name, "BCD_PointLight");
  EXPECT_EQ(cs[1].name, "BCD_SpotLight");
  for (const brs::Component& c : cs) {
    EXPECT_EQ(c.version, 1) << c.name;
    EXPECT_EQ(c.radius.size(), c.bricks.size()) << c.name;
    EXPECT_TRUE(std::is_sorted(c.bricks.begin(), c.bricks.end())) << c.name;
  }
  EXPECT_EQ(cs[0].bricks.size(), 21u);
  EXPECT_EQ(cs[1].bricks.size(), 19u);
  EXPECT_EQ(propertiesOf(cs[0]), pointLightProperties());
  EXPECT_EQ(propertiesOf(cs[1]), spotLightProperties());
  // First and last brick of each, from an independent Python walk of the same layout.
  EXPECT_EQ(cs[0].bricks.front(), 4725u);
  EXPECT_EQ(cs[0].bricks.back(), 24637u);
  EXPECT_EQ(cs[1].bricks.front(), 3708u);
  EXPECT_EQ(cs[1].bricks.back(), 13457u);
  // Radii in Brickadia units: point lights 20 x 150 and 1 x 120; spot lights 6 x 120,
  // 8 x 50, 4 x 1000, 1 x 140.
  std::map<float, int> point, spot;
  for (float r : cs[0].radius) ++point[r];
  for (float r : cs[1].radius) ++spot[r];
  EXPECT_EQ(point, (std::map<float, int>{{120.f, 1}, {150.f, 20}}));
  EXPECT_EQ(spot, (std::map<float, int>{{50.f, 8}, {120.f, 6}, {140.f, 1}, {1000.f, 4}}));
}

TEST_F(BrsLighthouseComponents, EveryLightSitsOnItsBrickInsideTheSave) {
  const BrsLoadResult& r = lighthouse();
  EXPECT_EQ(r.componentCounts, (std::map<std::string, uint32_t>{{"BCD_PointLight", 21}, {"BCD_SpotLight", 19}}));
  ASSERT_EQ(r.lights.size(), 40u);
  ASSERT_EQ(r.lightRecords.size(), r.lights.size());
  EXPECT_EQ(r.lightComponentsFound, 40u);
  const Aabb grown = r.bounds.expanded(2.f);
  size_t points = 0;
  std::map<float, int> radii;
  for (size_t i = 0; i < r.lights.size(); ++i) {
    const BuildLight& l = r.lights[i];
    points += l.kind == BuildLightKind::Point ? 1 : 0;
    EXPECT_EQ(l.kind, i < 21 ? BuildLightKind::Point : BuildLightKind::Spot) << i;
    EXPECT_TRUE(std::isfinite(l.radius) && l.radius > 0.f) << i;
    ++radii[l.radius];
    EXPECT_TRUE(grown.contains(l.position)) << i << ": " << l.position.transpose();
    // At its brick's centre (every brick of this save has collision, so it is indexed too).
    const BrsBrickRecord& rec = r.records.at(r.lightRecords[i]);
    ASSERT_GE(rec.brick, 0);
    EXPECT_EQ(l.position, r.bricks[size_t(rec.brick)].position) << i;
  }
  EXPECT_EQ(points, 21u);
  // Radius x 0.04: 50 -> 2, 120 -> 4.8, 140 -> 5.6, 150 -> 6, 1000 -> 40.
  EXPECT_EQ(radii, (std::map<float, int>{{50.f * 0.04f, 8}, {120.f * 0.04f, 7}, {140.f * 0.04f, 1},
                                         {150.f * 0.04f, 20}, {1000.f * 0.04f, 4}}));
}

// Every single-byte corruption and every truncation of the real section either decodes (then
// its indices are in range) or fails with an error naming the file and the section.
TEST_F(BrsLighthouseComponents, FlippedAndCutSectionsFailCleanly) {
  const std::vector<uint8_t> section = lighthouseComponentsSection();
  ASSERT_FALSE(section.empty());
  auto check = [](const std::vector<uint8_t>& bytes, bool mustFail) {
    std::vector<uint8_t> exact(bytes);
    exact.shrink_to_fit();
    try {
      const std::vector<brs::Component> cs = brs::readComponents(exact, 25'427, "Lighthouse_bad.brs");
      EXPECT_FALSE(mustFail);
      for (const brs::Component& c : cs)
        for (uint32_t b : c.bricks) ASSERT_LT(b, 25'427u);
    } catch (const InvalidInput& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind("Lighthouse_bad.brs: components: ", 0), 0u) << msg;
    }
  };
  for (size_t i = 0; i < section.size(); ++i) {
    std::vector<uint8_t> flipped = section;
    flipped[i] ^= 0xFF;
    check(flipped, false);
  }
  for (size_t n = 0; n < section.size(); ++n) check(std::vector<uint8_t>(section.begin(), section.begin() + long(n)), true);
}

// ---- hand-built components ----

TEST(BrsComponents, LightsOfEveryVersionIncludingCollisionOffBricks) {
  for (int version : {8, 9, 10}) {
    SCOPED_TRACE("version " + std::to_string(version));
    const auto bytes = buildSave(version, kAssets, sampleBricks());
    const BrsLoadResult r = parseBrs(bytes.data(), bytes.size(), "lights.brs");
    EXPECT_EQ(r.componentCounts,
              (std::map<std::string, uint32_t>{{"BCD_Interact", 1}, {"BCD_PointLight", 2}, {"BCD_SpotLight", 1}}));
    ASSERT_EQ(r.lights.size(), 3u);
    EXPECT_EQ(r.lightComponentsFound, 3u);
    EXPECT_EQ(r.lightRecords, (std::vector<uint32_t>{2, 5, 0}));
    // Point lights on bricks 2 and 5 (radius 150 and 250), the spot light on brick 0 (1000).
    EXPECT_EQ(r.lights[0].kind, BuildLightKind::Point);
    EXPECT_EQ(r.lights[1].kind, BuildLightKind::Point);
    EXPECT_EQ(r.lights[2].kind, BuildLightKind::Spot);
    EXPECT_FLOAT_EQ(r.lights[0].radius, 6.f);
    EXPECT_FLOAT_EQ(r.lights[1].radius, 10.f);
    EXPECT_FLOAT_EQ(r.lights[2].radius, 40.f);
    EXPECT_TRUE(r.lights[0].position.isApprox(Vec3f(50, -50, 18) * 0.04f));
    // Brick 5 has collision off: not indexed, its light is still there, at its record's centre.
    EXPECT_EQ(r.records[5].brick, -1);
    EXPECT_TRUE(r.lights[1].position.isApprox(Vec3f(1000, 0, -12) * 0.04f));
    EXPECT_TRUE(r.lights[2].position.isApprox(Vec3f(0, 0, 6) * 0.04f));
  }
}

TEST(BrsComponents, RadiusDefaultsScaleAndUnknownLightComponents) {
  const auto bricks = sampleBricks();
  // No Radius property; Radius 0 and negative; an unknown "...Light" component.
  TestComponent noRadius{.name = "BCD_PointLight", .bricks = {1}, .properties = {{"Brightness", "Float"}}};
  TestComponent zero{.name = "BCD_SpotLight", .bricks = {3, 4}, .properties = spotLightProperties(), .radius = {0.f, -3.f}};
  TestComponent area{.name = "BCD_AreaLight", .bricks = {0, 6}, .properties = {{"Radius", "Float"}}, .radius = {80.f, 90.f}};
  const auto bytes = buildSave(9, kAssets, bricks, -1, componentsSection({noRadius, zero, area}, 7));
  for (float units : {0.04f, 0.1f}) {
    const BrsLoadResult r = parseBrs(bytes.data(), bytes.size(), "defaults.brs", units);
    ASSERT_EQ(r.lights.size(), 3u);
    EXPECT_EQ(r.lightComponentsFound, 5u);
    EXPECT_EQ(r.componentCounts.at("BCD_AreaLight"), 2u);
    for (const BuildLight& l : r.lights) EXPECT_FLOAT_EQ(l.radius, kBrsDefaultLightRadius * units);
    EXPECT_TRUE(r.lights[0].position.isApprox(Vec3f(-100, 40, 2) * units));
  }
}

TEST(BrsComponents, EmptySectionsAndComponentsLoad) {
  const auto none = buildSave(8, kAssets, sampleBricks(), -1, componentsSection({}, 7));
  const BrsLoadResult a = parseBrs(none.data(), none.size(), "none.brs");
  EXPECT_TRUE(a.componentCounts.empty());
  EXPECT_TRUE(a.lights.empty());
  // An empty save still lists its components, with no bricks.
  const auto empty = buildSave(10, {}, {});
  const BrsLoadResult b = parseBrs(empty.data(), empty.size(), "empty.brs");
  EXPECT_EQ(b.componentCounts.at("BCD_PointLight"), 0u);
  EXPECT_TRUE(b.lights.empty());
}

// Every kind of corrupt component data names the file, the section and the component.
TEST(BrsBadFiles, CorruptComponentsNameTheComponent) {
  const auto bricks = sampleBricks();
  auto point = [] {
    return TestComponent{.name = "BCD_PointLight", .bricks = {2, 5}, .properties = pointLightProperties(), .radius = {150.f, 250.f}};
  };
  auto save = [&](const std::vector<TestComponent>& cs) { return buildSave(8, kAssets, bricks, -1, componentsSection(cs, 7)); };
  const std::string where = "components: BCD_PointLight: ";

  TestComponent cut = point();
  cut.lengthDelta = -1;
  expectInvalid(save({cut}), "cut1.brs", where + "truncated");
  cut.lengthDelta = -20;
  expectInvalid(save({cut}), "cut20.brs", where + "truncated");
  TestComponent longer = point();
  longer.lengthDelta = 5;
  expectInvalid(save({longer}), "longer.brs", where + "truncated: length");

  TestComponent unknown = point();
  unknown.properties[2].second = "Vector9";
  expectInvalid(save({unknown}), "type.brs", where + "property Radius has type \"Vector9\"");

  TestComponent manyProperties = point();
  manyProperties.propertyCountOverride = 1'000'000;
  expectInvalid(save({manyProperties}), "properties.brs", where + "property count 1000000 exceeds the data");
  manyProperties.propertyCountOverride = -2;
  expectInvalid(save({manyProperties}), "properties_neg.brs", where + "property count is negative");

  TestComponent manyBricks = point();
  manyBricks.brickCountOverride = 2'000'000'000;
  expectInvalid(save({manyBricks}), "bricks.brs", where + "brick count 2000000000 exceeds the data");
  manyBricks.brickCountOverride = -1;
  expectInvalid(save({manyBricks}), "bricks_neg.brs", where + "brick count is negative");
  manyBricks.brickCountOverride = 3;  // one more entry than values: the values run out
  expectInvalid(save({manyBricks}), "bricks3.brs", where);

  TestComponent extra = point();
  extra.extraBits = 8;
  expectInvalid(save({extra}), "extra.brs", {where, "bits left after the last value"});

  TestComponent nan = point();
  nan.radius[1] = std::numeric_limits<float>::quiet_NaN();
  expectInvalid(save({nan}), "nan.brs", where + "brick 5: Radius nan is not finite");
  nan.radius[1] = std::numeric_limits<float>::infinity();
  expectInvalid(save({nan}), "inf.brs", where + "brick 5: Radius inf is not finite");

  // Brick indices take uint(max(brickCount, 2)) bits, so with one brick index 1 can be stored.
  TestComponent outOfRange{.name = "BCD_PointLight", .bricks = {1}, .properties = pointLightProperties(), .radius = {150.f}};
  expectInvalid(buildSave(10, {"PB_DefaultBrick"}, {bricks[0]}, -1, componentsSection({outOfRange}, 1)), "index.brs",
                where + "brick index 1 is out of range (1 bricks)");
  outOfRange.bricks = {0};
  expectInvalid(buildSave(10, {"PB_DefaultBrick"}, {}, -1, componentsSection({outOfRange}, 0)), "index0.brs",
                where + "brick index 0 is out of range (0 bricks)");

  // Framing: the component count, a negative length, bytes after the last component.
  Bytes count;
  count.i32(1'000'000);
  expectInvalid(buildSave(8, kAssets, bricks, -1, count.b), "count.brs", "components: components count 1000000 exceeds");
  Bytes negative;
  negative.i32(1);
  negative.str("BCD_PointLight");
  negative.i32(-4);
  expectInvalid(buildSave(8, kAssets, bricks, -1, negative.b), "negative.brs", where + "length is negative");
  std::vector<uint8_t> trailing = componentsSection({point()}, 7);
  trailing.insert(trailing.end(), 3, 0);
  expectInvalid(buildSave(8, kAssets, bricks, -1, trailing), "trailing.brs", "components: 3 bytes left after the last component");
}

// Every byte of a hand-built components section (all property types, unaligned strings) flipped:
// the save loads with valid lights or fails naming the file and the components section.
TEST(BrsBadFiles, FlippedComponentBytesFailCleanlyOrLoad) {
  const std::vector<uint8_t> section = componentsSection(sampleComponents(7), 7);
  for (size_t i = 0; i < section.size(); ++i) {
    std::vector<uint8_t> flipped = section;
    flipped[i] ^= 0xFF;
    std::vector<uint8_t> bytes = buildSave(9, kAssets, sampleBricks(), -1, flipped);
    bytes.shrink_to_fit();
    try {
      const BrsLoadResult r = parseBrs(bytes.data(), bytes.size(), "flip.brs");
      for (const BuildLight& l : r.lights) {
        EXPECT_TRUE(l.position.allFinite());
        EXPECT_TRUE(std::isfinite(l.radius) && l.radius > 0.f);
      }
    } catch (const InvalidInput& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind("flip.brs: components", 0), 0u) << "byte " << i << ": " << msg;
    }
  }
}

}  // namespace
}  // namespace bw
