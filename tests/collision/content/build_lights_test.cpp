// The generators' lights (build_generators.h): where each build promises lights it has them, in
// numbers that grow sensibly with scale, inside the build's bounds, never inside a brick's box,
// the same for the same seed; and tileLights() moves lights by exactly tileBuild()'s offsets.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <gtest/gtest.h>
#include <string>
#include <vector>

#include "collision/bricks/brick_geometry.h"
#include "collision/content/build_generators.h"
#include "collision/content/build_tiling.h"
#include "collision/core/argument_checks.h"

namespace bw {
namespace {

bool sameLights(const std::vector<BuildLight>& a, const std::vector<BuildLight>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (std::memcmp(a[i].position.data(), b[i].position.data(), sizeof(float) * 3) != 0 || a[i].radius != b[i].radius ||
        a[i].kind != b[i].kind)
      return false;
  return true;
}

struct LightCase {
  const char* name;
  float small;
  float large;
};
// Two scales per build, the second 16 times the first (4 times for the city block).
constexpr LightCase kCases[] = {
    {"house", 0.25f, 4.f},       {"truck", 0.25f, 4.f},  {"carrier", 0.04f, 0.64f},
    {"ring_station", 0.04f, 0.64f}, {"plate_stack", 0.1f, 1.f}, {"city_block", 0.01f, 0.04f},
    {"chain_link", 0.25f, 4.f},  {"hangar", 0.25f, 4.f},
};

// Every light finite with a radius of 4 to 15, inside the bounds grown by 0.5, and outside every
// brick's box grown by 0.05 (so outside its exact shape too), checked against every brick.
TEST(BuildLights, InsideTheBoundsAndNeverInsideABrick) {
  for (const LightCase& c : kCases) {
    for (float scale : {c.small, c.large}) {
      SCOPED_TRACE(std::string(c.name) + " scale " + std::to_string(scale));
      const GeneratedBuild g = generateBuild(c.name, 7, scale);
      const Aabb grown = g.bounds.expanded(0.5f);
      std::vector<Aabb> boxes;
      boxes.reserve(g.bricks.size());
      for (const Brick& b : g.bricks) boxes.push_back(brickBounds(b).expanded(0.05f));
      size_t outside = 0, inBrick = 0;
      for (size_t i = 0; i < g.lights.size(); ++i) {
        const BuildLight& l = g.lights[i];
        ASSERT_TRUE(l.position.allFinite()) << i;
        ASSERT_TRUE(l.radius >= 4.f && l.radius <= 15.f) << i << ": radius " << l.radius;
        ASSERT_LE(uint8_t(l.kind), uint8_t(BuildLightKind::Spot));
        outside += grown.contains(l.position) ? 0 : 1;
        for (size_t k = 0; k < g.bricks.size(); ++k) {
          if (!boxes[k].contains(l.position)) continue;
          ++inBrick;
          EXPECT_FALSE(brickContains(g.bricks[k], l.position)) << "light " << i << " inside brick " << k;
          ADD_FAILURE() << "light " << i << " at " << l.position.transpose() << " in the box of brick " << k;
        }
      }
      EXPECT_EQ(outside, 0u);
      EXPECT_EQ(inBrick, 0u);
    }
  }
}

// Lights where promised (none for the plate stack and the chain link), and more of them for larger builds: fixed
// for the truck, more for the others over a 16x (city: 4x) scale step, never more than the
// scale step itself (the brick count's growth).
TEST(BuildLights, CountsScaleSensibly) {
  for (const LightCase& c : kCases) {
    const size_t small = generateBuild(c.name, 3, c.small).lights.size();
    const size_t large = generateBuild(c.name, 3, c.large).lights.size();
    if (std::string(c.name) == "plate_stack" || std::string(c.name) == "chain_link") {
      EXPECT_EQ(small, 0u);
      EXPECT_EQ(large, 0u);
      continue;
    }
    EXPECT_GT(small, 0u) << c.name;
    if (std::string(c.name) == "truck") {
      EXPECT_EQ(small, 4u);
      EXPECT_EQ(large, 4u);
      continue;
    }
    const double step = double(c.large) / double(c.small);
    EXPECT_GT(double(large), 1.5 * double(small)) << c.name << ": " << small << " -> " << large;
    EXPECT_LE(double(large), step * double(small)) << c.name << ": " << small << " -> " << large;
  }
  // The documented counts at scale 1 (city block: 0.05).
  EXPECT_EQ(generateHouse(3, 1.f).lights.size(), 5u);
  EXPECT_EQ(generateTruck(3, 1.f).lights.size(), 4u);
  EXPECT_EQ(generateCarrierShip(3, 1.f).lights.size(), 56u);
  EXPECT_EQ(generateRingStation(3, 1.f).lights.size(), 44u);
  EXPECT_EQ(generatePlateStackBricks(3, 1.f).lights.size(), 0u);
  EXPECT_EQ(generateCityBlock(3, 0.05f).lights.size(), 61u);
  EXPECT_EQ(generateHangar(3, 1.f).lights.size(), 12u);
}

TEST(BuildLights, KindsWherePromised) {
  const GeneratedBuild truck = generateTruck(5, 1.f);
  const auto spots = std::count_if(truck.lights.begin(), truck.lights.end(),
                                   [](const BuildLight& l) { return l.kind == BuildLightKind::Spot; });
  EXPECT_EQ(spots, 2);  // the head lights, in front of the cab (+X)
  for (const BuildLight& l : truck.lights)
    EXPECT_EQ(l.kind == BuildLightKind::Spot, l.position.x() > truck.bounds.center().x());
  // The carrier's hangar lights are inside the hangar.
  const GeneratedBuild carrier = generateCarrierShip(5, 0.16f);
  ASSERT_EQ(carrier.interiors.size(), 1u);
  EXPECT_GE(std::count_if(carrier.lights.begin(), carrier.lights.end(),
                          [&](const BuildLight& l) { return carrier.interiors[0].contains(l.position); }),
            1);
  // The ring's lights lie in the habitable band, between the ceiling and the floor.
  const GeneratedBuild ring = generateRingStation(5, 0.16f);
  for (const BuildLight& l : ring.lights) {
    const float r = std::sqrt(l.position.x() * l.position.x() + l.position.y() * l.position.y());
    EXPECT_GT(r, ring.ring.innerRadius);
    EXPECT_LT(r, ring.ring.floorRadius);
    EXPECT_LT(std::abs(l.position.z()), ring.ring.width * 0.5f);
  }
}

TEST(BuildLights, SameSeedSameLights) {
  for (const LightCase& c : kCases) {
    const GeneratedBuild a = generateBuild(c.name, 11, c.small), b = generateBuild(c.name, 11, c.small);
    EXPECT_TRUE(sameLights(a.lights, b.lights)) << c.name;
    EXPECT_EQ(a.lights.capacity(), a.lights.size()) << c.name << ": sized exactly, once";
  }
  // The city block's lobby lamps follow its seeded buildings.
  EXPECT_FALSE(sameLights(generateCityBlock(1, 0.01f).lights, generateCityBlock(2, 0.01f).lights));
}

// Lights placed exactly on bricks stay exactly on the tiled copies of those bricks: the same
// offsets, the same double sum rounded once, the same order.
TEST(BuildLights, TileLightsUsesTileBuildsOffsets) {
  const GeneratedBuild g = generateTruck(4, 1.f);
  std::vector<BuildLight> onBricks;
  for (size_t k = 0; k < g.bricks.size(); k += 97) onBricks.push_back(BuildLight{g.bricks[k].position, 5.f, BuildLightKind::Point});
  const float gap = 3.7f;
  const std::vector<Brick> bricks = tileBuild(g.bricks, g.bounds, 3, 2, gap);
  const std::vector<BuildLight> lights = tileLights(onBricks, g.bounds, 3, 2, gap);
  ASSERT_EQ(lights.size(), onBricks.size() * 6);
  for (size_t t = 0; t < 6; ++t)
    for (size_t k = 0; k < onBricks.size(); ++k) {
      const BuildLight& l = lights[t * onBricks.size() + k];
      const Brick& b = bricks[t * g.bricks.size() + k * 97];
      ASSERT_EQ(l.position, b.position) << "tile " << t << " light " << k;
      ASSERT_EQ(l.radius, 5.f);
    }
  // The build's own lights: tile (0, 0) is the input itself.
  const std::vector<BuildLight> own = tileLights(g.lights, g.bounds, 2, 2, gap);
  ASSERT_EQ(own.size(), g.lights.size() * 4);
  EXPECT_TRUE(sameLights(std::vector<BuildLight>(own.begin(), own.begin() + long(g.lights.size())), g.lights));
  // Same argument checks; no lights, no output.
  EXPECT_THROW(tileLights(g.lights, g.bounds, 0, 1, gap), InvalidInput);
  EXPECT_THROW(tileLights(g.lights, g.bounds, 1, 1, -1.f), InvalidInput);
  EXPECT_THROW(tileLights(g.lights, Aabb::empty(), 1, 1, gap), InvalidInput);
  EXPECT_TRUE(tileLights({}, Aabb::empty(), 4, 4, gap).empty());
}

}  // namespace
}  // namespace bw
