// Tests of the seeded build generators (collision/build_generators.h): valid bricks,
// determinism, the scale law, bounds, empty interiors, the city block's microbricks beside long
// ramps, the ring station's floor radius and the absence of self-overlap.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <gtest/gtest.h>
#include <set>
#include <unordered_map>

#include "collision/bricks/brick_geometry.h"
#include "collision/content/build_generators.h"
#include "collision/core/argument_checks.h"
#include "collision/core/seeded_random.h"

namespace bw {
namespace {

// Scales each build is tested at: small enough to keep the file fast under ASan, the second
// four times the first so the scale law can be checked. The chain link has one shape (its
// seed is unused) whose lengths scale, not its brick count.
struct BuildCase {
  const char* name;
  float small;
  float large;
  bool seeded = true;       // another seed gives other bricks
  bool countScales = true;  // the brick count grows about linearly with scale
};
constexpr BuildCase kCases[] = {
    {"house", 0.25f, 1.f},         {"truck", 0.25f, 1.f},       {"carrier", 0.04f, 0.16f},
    {"ring_station", 0.04f, 0.16f}, {"plate_stack", 0.1f, 0.4f}, {"city_block", 0.01f, 0.04f},
    {"chain_link", 0.25f, 1.f, false, false}, {"hangar", 0.25f, 1.f},
};

Aabb worldBox(const Brick& b) {
  const Vec3f h = b.rotation.applyToExtent(b.halfSize);
  return {b.position - h, b.position + h};
}

float overlapVolume(const Aabb& a, const Aabb& b) {
  const Vec3f lo = a.min.cwiseMax(b.min), hi = a.max.cwiseMin(b.max);
  if ((hi.array() <= lo.array()).any()) return 0.f;
  return (hi - lo).prod();
}

bool sameBricks(const GeneratedBuild& a, const GeneratedBuild& b) {
  return a.bricks.size() == b.bricks.size() &&
         std::memcmp(a.bricks.data(), b.bricks.data(), a.bricks.size() * sizeof(Brick)) == 0;
}

// Bricks of a build grouped by the cells (of side `cell`) their boxes touch. Bricks touching
// more than `maxCells` cells go to `huge` and are compared against everything.
struct BrickHash {
  float cell;
  std::unordered_map<uint64_t, std::vector<uint32_t>> cells;
  std::vector<uint32_t> huge;

  static uint64_t key(int x, int y, int z) {
    return (uint64_t(uint32_t(x) & 0x1FFFFF) << 42) | (uint64_t(uint32_t(y) & 0x1FFFFF) << 21) | uint64_t(uint32_t(z) & 0x1FFFFF);
  }
  template <class F>
  void forCells(const Aabb& box, F&& f) const {
    const Eigen::Array3i lo = (box.min / cell).array().floor().cast<int>(), hi = (box.max / cell).array().floor().cast<int>();
    for (int z = lo.z(); z <= hi.z(); ++z)
      for (int y = lo.y(); y <= hi.y(); ++y)
        for (int x = lo.x(); x <= hi.x(); ++x) f(key(x, y, z));
  }
  BrickHash(const std::vector<Brick>& bricks, float cellSize, double maxCells = 4096) : cell(cellSize) {
    for (uint32_t i = 0; i < bricks.size(); ++i) {
      const Aabb box = worldBox(bricks[i]);
      const Eigen::Array3f span = (box.max / cell).array().floor() - (box.min / cell).array().floor() + 1.f;
      if (double(span.x()) * span.y() * span.z() > maxCells) {
        huge.push_back(i);
        continue;
      }
      forCells(box, [&](uint64_t k) { cells[k].push_back(i); });
    }
  }
  // Indices of bricks whose cells meet `box` (a superset of the bricks overlapping it), sorted.
  std::vector<uint32_t> near(const Aabb& box) const {
    std::vector<uint32_t> out(huge);
    forCells(box, [&](uint64_t k) {
      const auto it = cells.find(k);
      if (it != cells.end()) out.insert(out.end(), it->second.begin(), it->second.end());
    });
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }
};

TEST(BuildGenerators, NamesDispatchAndCoverEveryBuild) {
  const std::vector<std::string> names = buildNames();
  ASSERT_EQ(names.size(), std::size(kCases));
  for (const BuildCase& c : kCases) {
    EXPECT_NE(std::find(names.begin(), names.end(), c.name), names.end()) << c.name;
    EXPECT_EQ(generateBuild(c.name, 1, c.small).name, c.name);
  }
}

TEST(BuildGenerators, RejectsBadArgumentsNamingThem) {
  for (const BuildCase& c : kCases) {
    for (float bad : {std::nanf(""), 0.f, -1.f, 1e9f, INFINITY}) {
      try {
        generateBuild(c.name, 1, bad);
        ADD_FAILURE() << c.name << " accepted scale " << bad;
      } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("scale"), std::string::npos) << e.what();
      }
    }
  }
  try {
    generateBuild("castle", 1, 1.f);
    ADD_FAILURE() << "unknown name accepted";
  } catch (const InvalidInput& e) {
    const std::string message = e.what();
    for (const std::string& n : buildNames()) EXPECT_NE(message.find(n), std::string::npos) << message;
  }
}

// Finite, positive sizes, rotation index < 24, known shape, cylinder sides a multiple of 4
// (what makes `bounds` exact), and bw::validateBrick accepts every brick.
TEST(BuildGenerators, EveryBrickIsValid) {
  for (const BuildCase& c : kCases) {
    for (float scale : {c.small, c.large}) {
      const GeneratedBuild g = generateBuild(c.name, 7, scale);
      ASSERT_FALSE(g.bricks.empty()) << c.name;
      size_t bad = 0;
      for (const Brick& b : g.bricks) {
        const bool ok = b.position.allFinite() && b.halfSize.allFinite() && (b.halfSize.array() > 0.f).all() &&
                        b.rotation.index() < AxisRotation::kCount && uint8_t(b.shape) <= uint8_t(BrickShape::Cylinder) &&
                        (b.shape != BrickShape::Cylinder || b.sides % 4 == 0);
        bad += ok ? 0 : 1;
        try {
          validateBrick(b, "build generator");
        } catch (const InvalidInput& e) {
          ++bad;
          if (bad < 4) ADD_FAILURE() << c.name << ": " << e.what();
        }
      }
      EXPECT_EQ(bad, 0u) << c.name << " scale " << scale;
    }
  }
}

TEST(BuildGenerators, SameSeedSameBricksOtherSeedOtherBricks) {
  for (const BuildCase& c : kCases) {
    const GeneratedBuild a = generateBuild(c.name, 11, c.small), b = generateBuild(c.name, 11, c.small);
    const GeneratedBuild other = generateBuild(c.name, 12, c.small);
    EXPECT_TRUE(sameBricks(a, b)) << c.name;
    EXPECT_EQ(a.bounds, b.bounds) << c.name;
    if (c.seeded) {
      EXPECT_FALSE(sameBricks(a, other)) << c.name;
    }
  }
}

// Law for every build: the brick count is about proportional to scale (shell builds grow their
// linear size with sqrt(scale), the plate stack and city block add plates, lots and patches).
// Lattice snapping and fixed parts (wheels, hub, ramps) bend it, so 4x the scale must give
// between 2x and 8x the bricks; the plate stack is exact: round(300 * scale) plates.
TEST(BuildGenerators, CountIsAboutProportionalToScale) {
  for (const BuildCase& c : kCases) {
    const double small = double(generateBuild(c.name, 3, c.small).bricks.size());
    const double large = double(generateBuild(c.name, 3, c.large).bricks.size());
    const double ratio = large / small;
    if (!c.countScales) {
      EXPECT_EQ(ratio, 1.0) << c.name;
      continue;
    }
    EXPECT_GE(ratio, 2.0) << c.name << ": " << small << " -> " << large;
    EXPECT_LE(ratio, 8.0) << c.name << ": " << small << " -> " << large;
  }
  EXPECT_EQ(generatePlateStackBricks(3, 0.1f).bricks.size(), 30u);
  EXPECT_EQ(generatePlateStackBricks(3, 1.f).bricks.size(), 300u);
  // The headline sizes, within a factor of 1.5 (scale 1 builds that are quick to make).
  const std::pair<const char*, double> headline[] = {{"house", 5000}, {"truck", 3000}, {"carrier", 50000}};
  for (const auto& [name, expected] : headline) {
    const double n = double(generateBuild(name, 3, 1.f).bricks.size());
    EXPECT_GT(n, expected / 1.5) << name;
    EXPECT_LT(n, expected * 1.5) << name;
  }
  const double city = double(generateCityBlock(3, 0.01f).bricks.size());
  EXPECT_GT(city, 20000 / 1.5);
  EXPECT_LT(city, 20000 * 1.5);
}

// `bounds` is the union of the exact shape bounds (brick_geometry), so it contains each one.
TEST(BuildGenerators, BoundsContainEveryBrickAndAreTight) {
  for (const BuildCase& c : kCases) {
    const GeneratedBuild g = generateBuild(c.name, 5, c.small);
    Aabb merged = Aabb::empty();
    size_t outside = 0;
    for (const Brick& b : g.bricks) {
      const Aabb box = brickBounds(b);
      merged.merge(box);
      outside += g.bounds.expanded(1e-4f).contains(box) ? 0 : 1;
    }
    EXPECT_EQ(outside, 0u) << c.name;
    EXPECT_LT((merged.min - g.bounds.min).cwiseAbs().maxCoeff(), 1e-3f) << c.name;
    EXPECT_LT((merged.max - g.bounds.max).cwiseAbs().maxCoeff(), 1e-3f) << c.name;
  }
}

// Parts are contiguous, in order, and cover every brick; detail parts carry the detail filter.
TEST(BuildGenerators, PartsCoverEveryBrick) {
  for (const BuildCase& c : kCases) {
    const GeneratedBuild g = generateBuild(c.name, 5, c.small);
    ASSERT_FALSE(g.parts.empty()) << c.name;
    uint32_t next = 0;
    for (const BuildPart& p : g.parts) {
      EXPECT_EQ(p.begin, next) << c.name << " " << p.name;
      EXPECT_LE(p.begin, p.end);
      next = p.end;
    }
    EXPECT_EQ(next, g.bricks.size()) << c.name;
    for (const Brick& b : g.bricks) ASSERT_TRUE(b.filter == kBuildFilterStructure || b.filter == kBuildFilterDetail);
  }
}

// The truck bed, the carrier's hangar, the chain link's hole and the docking hangar's slot are open: no brick centre strictly inside, and no brick box
// reaches more than 1e-3 into them.
TEST(BuildGenerators, InteriorsAreEmpty) {
  const std::pair<const char*, float> open[] = {{"truck", 0.25f},      {"truck", 1.f},      {"carrier", 0.04f}, {"carrier", 0.16f},
                                                {"chain_link", 0.25f}, {"chain_link", 4.f}, {"hangar", 0.25f},  {"hangar", 1.f}};
  for (const auto& [name, scale] : open) {
    const GeneratedBuild g = generateBuild(name, 9, scale);
    ASSERT_EQ(g.interiors.size(), 1u) << name;
    const Aabb space = g.interiors[0];
    ASSERT_FALSE(space.isEmpty());
    EXPECT_GT(space.volume(), 0.02f * g.bounds.volume()) << name;
    const Aabb shrunk = space.expanded(-1e-3f);
    size_t centres = 0, reaching = 0;
    for (const Brick& b : g.bricks) {
      centres += ((b.position.array() > space.min.array()).all() && (b.position.array() < space.max.array()).all()) ? 1 : 0;
      reaching += overlapVolume(worldBox(b), shrunk) > 0.f ? 1 : 0;
    }
    EXPECT_EQ(centres, 0u) << name << " scale " << scale;
    EXPECT_EQ(reaching, 0u) << name << " scale " << scale;
  }
  for (const char* name : {"house", "ring_station", "plate_stack", "city_block"})
    EXPECT_TRUE(generateBuild(name, 9, name == std::string("house") ? 0.25f : 0.01f).interiors.empty()) << name;
}

// Two links interlock: the second turned a quarter about Z and hung its pitch below the first
// (the hole's inner length, 2 (arcRadius - wireRadius) + straight, less a 6 cm gap) reaches
// through the first's hole without any brick box of one overlapping one of the other, and the
// wire stays within a cell's half diagonal of its radius around the centre line.
TEST(BuildGenerators, ChainLinksInterlockWithoutTouching) {
  for (float scale : {0.25f, 1.f, 8.f}) {
    const GeneratedBuild a = generateChainLink(1, scale);
    const LinkDimensions d = chainLinkDimensions(scale);
    EXPECT_GT(a.bricks.size(), 128u) << "too few bricks to take the two-way path";
    for (const Brick& brick : a.bricks) {
      const Vec3f p = brick.position;
      const float dz = std::max(std::abs(p.z()) - d.straight * 0.5f, 0.f);
      const float inPlane = std::sqrt(p.x() * p.x() + dz * dz) - d.arcRadius;
      ASSERT_LE(std::sqrt(inPlane * inPlane + p.y() * p.y()), d.wireRadius + 0.87f * d.cell) << "scale " << scale;
    }
    const float pitch = d.straight + 2.f * (d.arcRadius - d.wireRadius) - 0.06f * scale;
    const AxisRotation quarter = AxisRotation::fromDirectionSpin(AxisRotation::PosZ, 1);
    std::vector<Aabb> boxesB;
    for (const Brick& brick : a.bricks) {
      Brick b = brick;
      b.position = quarter.apply(brick.position) - Vec3f(0, 0, pitch);
      b.rotation = quarter * brick.rotation;
      boxesB.push_back(worldBox(b));
    }
    size_t overlapping = 0, throughHole = 0;
    for (const Aabb& boxB : boxesB) {
      throughHole += a.bounds.expanded(-1e-4f).overlaps(boxB) ? 1 : 0;
      for (const Brick& brick : a.bricks) overlapping += overlapVolume(worldBox(brick), boxB) > 0.f ? 1 : 0;
    }
    EXPECT_EQ(overlapping, 0u) << "scale " << scale;
    EXPECT_GT(throughHole, 10u) << "scale " << scale;
  }
}

// The article's mix: microbricks (half size <= 0.05) within 5 units of ramps longer than 100.
TEST(BuildGenerators, CityBlockHasMicrobricksBesideLongRamps) {
  const GeneratedBuild g = generateCityBlock(21, 0.01f);
  std::vector<Aabb> ramps;
  std::vector<uint32_t> micro;
  for (uint32_t i = 0; i < g.bricks.size(); ++i) {
    const Brick& b = g.bricks[i];
    const Aabb box = worldBox(b);
    if (b.shape == BrickShape::Wedge && box.extent().maxCoeff() > 100.f) ramps.push_back(box);
    if (b.halfSize.maxCoeff() <= 0.05f) micro.push_back(i);
  }
  ASSERT_FALSE(ramps.empty());
  ASSERT_GT(micro.size(), 1000u);
  // Grid hash of microbrick centres in 5-unit cells; each ramp visits the cells around it.
  const float cell = 5.f;
  std::unordered_map<uint64_t, std::vector<uint32_t>> grid;
  for (uint32_t i : micro) {
    const Eigen::Array3i k = (g.bricks[i].position / cell).array().floor().cast<int>();
    grid[BrickHash::key(k.x(), k.y(), k.z())].push_back(i);
  }
  size_t beside = 0;
  for (const Aabb& ramp : ramps) {
    const Aabb reach = ramp.expanded(5.f);
    const Eigen::Array3i lo = (reach.min / cell).array().floor().cast<int>(), hi = (reach.max / cell).array().floor().cast<int>();
    for (int z = lo.z(); z <= hi.z(); ++z)
      for (int y = lo.y(); y <= hi.y(); ++y)
        for (int x = lo.x(); x <= hi.x(); ++x) {
          const auto it = grid.find(BrickHash::key(x, y, z));
          if (it == grid.end()) continue;
          for (uint32_t i : it->second) beside += reach.contains(g.bricks[i].position) ? 1 : 0;
        }
  }
  EXPECT_GT(beside, 1000u);
}

// A quarter of the full city block: ~500k bricks (the count is proportional to scale, so scale
// 1 gives ~2M), sized exactly once, generated far within the budget. Scale 1 itself takes about
// 0.25 s in release; it is measured outside the tests to keep this file fast under ASan.
TEST(BuildGenerators, CityBlockQuarterScaleIsLargeAndQuick) {
  const auto start = std::chrono::steady_clock::now();
  const GeneratedBuild g = generateCityBlock(1, 0.25f);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GT(g.bricks.size(), 375'000u);
  EXPECT_LT(g.bricks.size(), 625'000u);
  EXPECT_LT(seconds, 5.0);
  EXPECT_EQ(g.bricks.capacity(), g.bricks.size()) << "the output vector is sized exactly, once";
}

// Floor bricks sit in the 1.5-cell shell starting at the floor radius, and their local +Z
// (their walking surface) points at the ring's axis.
TEST(BuildGenerators, RingFloorLiesAtFloorRadiusFacingTheAxis) {
  for (float scale : {0.04f, 0.16f}) {
    const GeneratedBuild g = generateRingStation(4, scale);
    const RingDimensions r = g.ring;
    ASSERT_GT(r.innerRadius, 0.f);
    ASSERT_GT(r.floorRadius, r.innerRadius);
    ASSERT_GT(r.width, 0.f);
    const auto floor = std::find_if(g.parts.begin(), g.parts.end(), [](const BuildPart& p) { return p.name == "floor"; });
    ASSERT_NE(floor, g.parts.end());
    ASSERT_GT(floor->end - floor->begin, 100u);
    const float tolerance = 0.6f + 1e-3f;  // shell thickness: 1.5 cells of 0.4
    size_t off = 0, facingAway = 0;
    for (uint32_t i = floor->begin; i < floor->end; ++i) {
      const Brick& b = g.bricks[i];
      const float d = std::sqrt(b.position.x() * b.position.x() + b.position.y() * b.position.y());
      off += (d < r.floorRadius - 1e-3f || d > r.floorRadius + tolerance || std::abs(b.position.z()) > r.width * 0.5f) ? 1 : 0;
      const Vec3f up = b.rotation.apply(Vec3f(0, 0, 1));
      facingAway += (up.x() * b.position.x() + up.y() * b.position.y() >= 0.f) ? 1 : 0;
    }
    EXPECT_EQ(off, 0u) << "scale " << scale;
    EXPECT_EQ(facingAway, 0u) << "scale " << scale;
    // Nothing but the floor lies beyond the floor radius within the habitable band.
    for (uint32_t i = 0; i < g.bricks.size(); ++i) {
      if (i >= floor->begin && i < floor->end) continue;
      const Brick& b = g.bricks[i];
      const float d = std::sqrt(b.position.x() * b.position.x() + b.position.y() * b.position.y());
      if (std::abs(b.position.z()) < r.width * 0.5f) {
        ASSERT_LT(d, r.floorRadius) << "brick " << i;
      }
    }
  }
}

// Bricks are laid next to each other: among up to 1500 sampled bricks, fewer than 1% overlap
// another brick by more than 1e-3 of the smaller one's volume (boxes of the rotated shapes).
TEST(BuildGenerators, LittleSelfOverlap) {
  for (const BuildCase& c : kCases) {
    const GeneratedBuild g = generateBuild(c.name, 13, c.small);
    const BrickHash hash(g.bricks, 2.f);
    SeededRandom rng(99);
    const uint32_t samples = uint32_t(std::min<size_t>(1500, g.bricks.size()));
    size_t overlapping = 0;
    for (uint32_t s = 0; s < samples; ++s) {
      const uint32_t i = samples == g.bricks.size() ? s : rng.below(uint32_t(g.bricks.size()));
      const Aabb a = worldBox(g.bricks[i]);
      bool any = false;
      for (uint32_t j : hash.near(a)) {
        if (j == i) continue;
        const Aabb b = worldBox(g.bricks[j]);
        any = any || overlapVolume(a, b) > 1e-3f * std::min(a.volume(), b.volume());
      }
      overlapping += any ? 1 : 0;
    }
    EXPECT_LT(double(overlapping), 0.01 * samples) << c.name << ": " << overlapping << " of " << samples;
  }
}

// All four shapes appear where natural, and builds use several of the 24 rotations.
TEST(BuildGenerators, UsesAllShapesAndSeveralRotations) {
  const std::pair<const char*, float> builds[] = {{"house", 0.25f}, {"truck", 0.25f}, {"carrier", 0.16f}, {"city_block", 0.01f}};
  for (const auto& [name, scale] : builds) {
    const GeneratedBuild g = generateBuild(name, 2, scale);
    std::set<int> shapes, rotations;
    for (const Brick& b : g.bricks) {
      shapes.insert(int(b.shape));
      rotations.insert(b.rotation.index());
    }
    EXPECT_EQ(shapes.size(), 4u) << name;
    EXPECT_GE(rotations.size(), 3u) << name;
  }
  std::set<int> ringRotations;
  for (const Brick& b : generateRingStation(2, 0.04f).bricks) ringRotations.insert(b.rotation.index());
  EXPECT_GE(ringRotations.size(), 12u);
}

}  // namespace
}  // namespace bw
