// Containment (world/containment.h) and the tunnelling it found: fast capsules and boxes rained
// onto a floor of thin plates never end up inside a brick or below the floor they landed on.
#include <algorithm>
#include <cstdio>
#include <string>
#include <gtest/gtest.h>

#include "collision/bricks/brick_geometry.h"
#include "collision/core/seeded_random.h"
#include "world/containment.h"
#include "world/world.h"

namespace bw {
namespace {

// A 40 x 40 m floor of 0.8 x 0.8 x 0.16 plates (top face z = 0, nothing below), and bodies of one
// kind spawned 40-60 m above it: they land at 28-34 m/s, tilted and spinning after the first
// bounces.
SceneDescription rainOnPlates(SpawnerDescription::Shape shape, uint32_t count, uint64_t seed) {
  SceneDescription s;
  s.name = "rain_on_plates";
  GridDescription floor;
  floor.name = "floor";
  for (int x = 0; x < 50; ++x)
    for (int y = 0; y < 50; ++y) floor.bricks.push_back(Brick::box(Vec3f(float(x) * 0.8f, float(y) * 0.8f, -0.08f), Vec3f(0.4f, 0.4f, 0.08f)));
  s.grids.push_back(floor);
  SpawnerDescription rain;
  rain.shape = shape;
  rain.count = count;
  rain.seed = seed;
  rain.regionMin = Vec3d(2, 2, 40);
  rain.regionMax = Vec3d(37, 37, 60);
  rain.halfExtents = Vec3f::Constant(0.25f);
  rain.radius = 0.15f;
  rain.halfHeight = 0.3f;
  s.spawners.push_back(rain);
  return s;
}

// Runs the scene; returns how many bodies are inside solid at the end, and prints the most
// at any one frame (a capsule may pass through a plate's top for a frame and be pushed back out).
uint32_t containmentAtTheEnd(const SceneDescription& scene, int frames) {
  World world(scene, 2);
  ContainmentTracker tracker(world);
  uint32_t worst = tracker.report().count();
  for (int f = 0; f < frames; ++f) {
    world.step();
    worst = std::max(worst, tracker.update().count());
  }
  const ContainmentReport& r = tracker.report();
  for (uint32_t k = 0; k < r.count(); ++k)
    ADD_FAILURE() << scene.name << ": body " << r.bodies[k] << " " << insideSolidName(r.reasons[k]) << " at z "
                  << world.bodies().position[r.bodies[k]].z();
  std::printf("[ containment ] %u bodies inside solid at the end, at most %u in any frame\n", r.count(), worst);
  return r.count();
}

// Midway through the fixes (capsule ends in, the reduction still geometric), 19 of these 300
// capsules ended below the floor (at 400 frames): a capsule landing tilted
// got one contact per plate, the pair's four kept contacts went to far-away plate edges
// (purely geometric manifold reduction), and its other end swung through.
TEST(Containment, CapsulesRainingOnThinPlatesStayAboveThem) {
  EXPECT_EQ(containmentAtTheEnd(rainOnPlates(SpawnerDescription::Shape::Capsule, 300, 5), 330), 0u);
}

// Boxes landing on plates next to others, corner first and spinning: before the fixes, exactly
// touching cores gave GJK no normal and the box no contact in the step after it landed.
TEST(Containment, BoxesRainingOnThinPlatesStayAboveThem) {
  EXPECT_EQ(containmentAtTheEnd(rainOnPlates(SpawnerDescription::Shape::Box, 300, 5), 330), 0u);
}

// (A body that starts inside solid is pushed out when the world is built: start_in_solid_test.cpp.)
TEST(Containment, ABodyABrickWasPlacedOverIsReportedAsInsideIt) {
  SceneDescription scene = rainOnPlates(SpawnerDescription::Shape::Sphere, 1, 1);
  scene.spawners[0].regionMin = scene.spawners[0].regionMax = Vec3d(10.15, 10.15, 2);
  World world(scene, 1);
  world.editGrid(0).placeBrick(Brick::box(Vec3f(10.15f, 10.15f, 2.f), Vec3f::Constant(0.5f)));
  ContainmentTracker tracker(world);
  ASSERT_EQ(tracker.report().count(), 1u);
  EXPECT_EQ(tracker.report().reasons[0], InsideSolid::InBrick);
  EXPECT_EQ(world.pointInsideSolid(Vec3d(10.15, 10.15, 0.5), kInvalidIndex), InsideSolid::No);
  EXPECT_TRUE(world.segmentHitsStatic(Vec3d(10, 10, 1), Vec3d(10, 10, -1)));   // through the floor
  EXPECT_FALSE(world.segmentHitsStatic(Vec3d(10, 10, 1), Vec3d(12, 10, 0.5)));  // above it
  EXPECT_FALSE(world.segmentHitsStatic(Vec3d(50, 10, 1), Vec3d(50, 10, -1)));  // beside it
}

// The reference the tracker's shortcuts are held to: every dynamic body checked fully (point
// test, then the path from its last clear place against every static solid); returns the bodies
// inside solid and moves each clear body's last clear place to where it is.
std::vector<uint32_t> insideByFullChecks(World& world, std::vector<Vec3d>& lastClear, const std::vector<uint8_t>& hasClear) {
  const BodyStore& bodies = world.bodies();
  std::vector<uint32_t> inside;
  for (uint32_t i = 0; i < bodies.size(); ++i) {
    if (bodies.motion[i] != MotionType::Dynamic) continue;
    const Vec3d& p = bodies.position[i];
    InsideSolid s = world.pointInsideSolid(p, i);
    if (s == InsideSolid::No && hasClear[i] && world.segmentHitsStatic(lastClear[i], p)) s = InsideSolid::WentThrough;
    if (s == InsideSolid::No) lastClear[i] = p;
    if (s != InsideSolid::No) inside.push_back(i);
  }
  return inside;
}

// The tracker's shortcuts (bodies far from solid, bodies at rest, static grids answered by the
// path) against a reference that checks every dynamic body fully every frame: the same report
// in every frame, through a rain, a brick placed around a resting body and a body teleported
// under the floor (which then falls, far from everything, and must stay reported).
TEST(Containment, ShortcutsReportWhatCheckingEveryBodyEveryFrameReports) {
  World world(rainOnPlates(SpawnerDescription::Shape::Box, 120, 9), 2);
  ContainmentTracker tracker(world);
  const BodyStore& bodies = world.bodies();
  std::vector<Vec3d> lastClear(bodies.position.begin(), bodies.position.end());
  std::vector<uint8_t> hasClear(bodies.size(), 1);
  uint32_t framesWithBodiesInside = 0;
  for (int f = 0; f < 340; ++f) {
    if (f == 240 || f == 280) {
      // A resting crate (they land after about 3 s): a brick placed around it (240), or the crate
      // set under the floor (280).
      uint32_t body = 0;
      while (body < bodies.size() &&
             (bodies.motion[body] != MotionType::Dynamic || bodies.linearVelocity[body].norm() > 0.05f || bodies.position[body].z() < 0))
        ++body;
      ASSERT_LT(body, bodies.size()) << "no crate at rest at frame " << f;
      if (f == 240) {
        world.editGrid(0).placeBrick(Brick::box(bodies.position[body].cast<float>(), Vec3f::Constant(0.3f)));
      } else {
        std::vector<Vec3d> positions(bodies.position.begin(), bodies.position.end());
        std::vector<Quatf> rotations(bodies.rotation.begin(), bodies.rotation.end());
        positions[body].z() = -5;
        world.setPoses(positions, rotations);
      }
    }
    if (f != 280) world.step();
    const ContainmentReport& got = tracker.update();
    const std::vector<uint32_t> expected = insideByFullChecks(world, lastClear, hasClear);
    ASSERT_EQ(got.bodies, expected) << "frame " << f;
    framesWithBodiesInside += expected.empty() ? 0 : 1;
  }
  EXPECT_GE(framesWithBodiesInside, 50u);  // the placed brick and the teleport are seen
}

// The same against terrain, whose crossing tests run in the parallel pass when the chunks they
// walk are built and are left for the serial pass when one is not: crates rained onto a quarry
// (their contacts build the chunks under them), one set straight down under the ground (through
// built chunks) and one lifted across the quarry and then set down under the ground there
// (through chunks nothing built yet).
TEST(Containment, OnTerrainShortcutsReportWhatCheckingEveryBodyEveryFrameReports) {
  SceneDescription scene;
  scene.name = "rain_on_quarry";
  TerrainDescription quarry;
  quarry.name = "quarry";
  quarry.generator = "quarry";
  quarry.size = {40, 40, 20};
  quarry.seed = 3;
  scene.terrains.push_back(quarry);
  SpawnerDescription rain;
  rain.shape = SpawnerDescription::Shape::Box;
  rain.count = 60;
  rain.seed = 4;
  rain.regionMin = Vec3d(4, 4, 24);
  rain.regionMax = Vec3d(16, 16, 34);
  rain.halfExtents = Vec3f::Constant(0.3f);
  scene.spawners.push_back(rain);
  World world(scene, 2);
  ContainmentTracker tracker(world);
  const BodyStore& bodies = world.bodies();
  std::vector<Vec3d> lastClear(bodies.position.begin(), bodies.position.end());
  std::vector<uint8_t> hasClear(bodies.size(), 1);
  uint32_t framesWithBodiesInside = 0;
  std::vector<uint32_t> setUnder;
  for (int f = 0; f < 260; ++f) {
    if (f == 231) {
      // The crate lifted last frame, set straight down under the ground far from the rain.
      std::vector<Vec3d> positions(bodies.position.begin(), bodies.position.end());
      std::vector<Quatf> rotations(bodies.rotation.begin(), bodies.rotation.end());
      positions[setUnder.back()].z() = -3;
      world.setPoses(positions, rotations);
    } else if (f == 200 || f == 230) {
      uint32_t body = 0;
      while (body < bodies.size() && (bodies.motion[body] != MotionType::Dynamic || bodies.linearVelocity[body].norm() > 0.05f ||
                                      std::find(setUnder.begin(), setUnder.end(), body) != setUnder.end()))
        ++body;
      ASSERT_LT(body, bodies.size()) << "no crate at rest at frame " << f;
      std::vector<Vec3d> positions(bodies.position.begin(), bodies.position.end());
      std::vector<Quatf> rotations(bodies.rotation.begin(), bodies.rotation.end());
      positions[body] = f == 200 ? Vec3d(positions[body].x(), positions[body].y(), -3) : Vec3d(32, 30, 30);
      world.setPoses(positions, rotations);
      setUnder.push_back(body);
    } else {
      world.step();
    }
    const ContainmentReport& got = tracker.update();
    const std::vector<uint32_t> expected = insideByFullChecks(world, lastClear, hasClear);
    ASSERT_EQ(got.bodies, expected) << "frame " << f;
    framesWithBodiesInside += expected.empty() ? 0 : 1;
  }
  EXPECT_GE(framesWithBodiesInside, 50u);  // both crates set under the ground are seen
  for (uint32_t body : setUnder)
    EXPECT_TRUE(std::find(tracker.report().bodies.begin(), tracker.report().bodies.end(), body) != tracker.report().bodies.end()) << body;
}

// The free balls the tracker keeps (World::staticSolidClearance) against brute force: from
// random places among a clutter of bricks (thin plates to 4 m blocks, in 24 orientations, on a
// grid far from the origin and turned) and over a quarry terrain (far from the origin too), the
// clearance never reaches past the nearest brick's bounds or solid voxel, and is within a
// millimetre of that distance (capped at the reach: two voxels in a terrain).
TEST(Containment, AFreeBallReachesNoBrickAndNoSolidVoxel) {
  SceneDescription scene;
  scene.name = "clutter";
  GridDescription clutter;
  clutter.name = "clutter";
  clutter.position = Vec3d(5000, -3000, 200);
  clutter.rotation = Quatf(Eigen::AngleAxisf(0.7f, Vec3f(1, 2, 3).normalized()));
  SeededRandom r(17);
  for (int k = 0; k < 400; ++k) {
    Brick b = Brick::box(Vec3f(float(r.uniform(-12, 12)), float(r.uniform(-12, 12)), float(r.uniform(-4, 4))),
                         Vec3f(float(r.uniform(0.1, 2)), float(r.uniform(0.1, 2)), float(k % 4 == 0 ? 0.01 : r.uniform(0.1, 2))));
    b.rotation = AxisRotation::fromIndex(int(r.below(AxisRotation::kCount)));
    clutter.bricks.push_back(b);
  }
  scene.grids.push_back(clutter);
  TerrainDescription quarry;
  quarry.name = "quarry";
  quarry.generator = "quarry";
  quarry.size = {32, 32, 16};
  quarry.seed = 3;
  quarry.voxelSize = 0.4f;
  quarry.position = Vec3d(-7000, 2500, -50);
  scene.terrains.push_back(quarry);
  World world(scene, 1);
  world.step();  // (the solids' reach is known after a step)
  const uint32_t gridBody = world.gridBody("clutter");
  const RigidTransform gridPose = world.bodies().shapePose(gridBody);
  const BrickGrid& grid = world.grid(0);
  const Terrain& terrain = world.terrain(0);
  constexpr double kReach = 0.5;
  // Distances in double from the exact local coordinates.
  const auto nearestBrick = [&](const Vec3d& p) {
    const Vec3d local = gridPose.rotation.cast<double>().conjugate() * (p - gridPose.translation);
    double best = 1e30;
    grid.forEachBrick([&](uint32_t id) {
      const Aabb b = brickBounds(grid.brick(id));
      const Vec3d gap = (b.min.cast<double>() - local).cwiseMax(local - b.max.cast<double>()).cwiseMax(0.0);
      best = std::min(best, gap.norm());
    });
    return best;
  };
  const auto nearestVoxel = [&](const Vec3d& p) {
    const double size = terrain.voxelSize();
    const Vec3d v = (terrain.placement().rotation.cast<double>().conjugate() * (p - terrain.placement().translation)) / size;
    double best = 1e30;
    const Int3 n = terrain.voxels().size();
    for (int z = 0; z < n.z; ++z)
      for (int y = 0; y < n.y; ++y)
        for (int x = 0; x < n.x; ++x) {
          if (!terrain.voxels().get(Int3{x, y, z}).isSolid()) continue;
          const Vec3d c(x, y, z);
          best = std::min(best, (c - v).cwiseMax(v - (c + Vec3d::Ones())).cwiseMax(0.0).norm() * size);
        }
    return best;
  };
  uint32_t free = 0, near = 0;
  for (int k = 0; k < 600; ++k) {
    const bool inGrid = k % 2 == 0;
    const Vec3d p = inGrid ? Vec3d(gridPose.pointToWorld(Vec3f(float(r.uniform(-13, 13)), float(r.uniform(-13, 13)), float(r.uniform(-5, 5)))))
                           : quarry.position + Vec3d(r.uniform(-1, 13.8), r.uniform(-1, 13.8), r.uniform(-1, 7.4));
    const double cap = inGrid ? kReach : std::min(kReach, 2.0 * terrain.voxelSize());
    const double exact = std::min(inGrid ? nearestBrick(p) : nearestVoxel(p), cap);
    const double clearance = world.staticSolidClearance(p, kReach);
    ASSERT_LE(clearance, exact) << (inGrid ? "grid" : "terrain") << " point " << k;
    ASSERT_GE(clearance, exact - 1e-3) << (inGrid ? "grid" : "terrain") << " point " << k;
    free += clearance > 0.1 ? 1 : 0;
    near += exact < cap ? 1 : 0;
  }
  EXPECT_GE(free, 100u);  // places with room around them
  EXPECT_GE(near, 100u);  // and places a brick or a solid voxel cuts the ball short
}

// A crate riding a kinematic deck (4 m/s, a wall across the deck behind the crate) is followed
// in the deck's frame: at rest on it, it is not queried again; the path of a nudge is the path
// relative to the deck (from its last clear place in world coordinates, that path would cross the
// wall the deck carried past it); a teleport under the deck is a path through it.
TEST(Containment, ACrateRidingAKinematicDeckIsFollowedInTheDecksFrame) {
  SceneDescription scene;
  scene.name = "deck_ride";
  GridDescription deck;
  deck.name = "deck";
  deck.motion = MotionType::Kinematic;
  deck.kinematic.linearVelocity = Vec3d(4, 0, 0);
  for (int x = 0; x < 20; ++x)
    for (int y = 0; y < 4; ++y) deck.bricks.push_back(Brick::box(Vec3f(float(x) + 0.5f, float(y) + 0.5f, -0.05f), Vec3f(0.5f, 0.5f, 0.05f)));
  deck.bricks.push_back(Brick::box(Vec3f(3.f, 2.f, 0.5f), Vec3f(0.1f, 2.f, 0.5f)));  // the wall, 2 m behind the crate
  scene.grids.push_back(deck);
  SpawnerDescription crate;
  crate.shape = SpawnerDescription::Shape::Box;
  crate.count = 1;
  crate.regionMin = crate.regionMax = Vec3d(5, 2, 0.26);
  crate.halfExtents = Vec3f::Constant(0.25f);
  crate.velocity = Vec3d(4, 0, 0);
  scene.spawners.push_back(crate);
  World world(scene, 2);
  const BodyStore& bodies = world.bodies();
  const uint32_t body = 1;
  ASSERT_EQ(bodies.motion[body], MotionType::Dynamic);
  ContainmentTracker tracker(world);
  uint32_t queriedLate = 0;
  for (int f = 0; f < 120; ++f) {
    world.step();
    ASSERT_EQ(tracker.update().count(), 0u) << "frame " << f;
    if (f >= 60) queriedLate += tracker.lastQueried();
  }
  // It rode along (moved 8 m in the world, still 0.25 m above the deck near where it landed).
  const Vec3d onDeck = bodies.rotation[0].cast<double>().conjugate() * (bodies.position[body] - bodies.position[0]);
  EXPECT_GT(bodies.position[body].x(), 12.0);
  EXPECT_NEAR(onDeck.x(), 5.0, 0.15);
  EXPECT_NEAR(onDeck.z(), 0.25, 0.01);
  // Resting, it creeps by micrometres a frame: queried again only after each half millimetre
  // (in the world's frame it moved 6.7 cm every frame: 60 queries).
  EXPECT_LE(queriedLate, 2u) << "a crate at rest on the deck was queried again and again";

  // A 1 mm nudge along the deck: checked, and clear (the path on the deck crosses nothing).
  std::vector<Vec3d> positions(bodies.position.begin(), bodies.position.end());
  std::vector<Quatf> rotations(bodies.rotation.begin(), bodies.rotation.end());
  positions[body].x() += 1e-3;
  world.setPoses(positions, rotations);
  EXPECT_EQ(tracker.update().count(), 0u);
  EXPECT_EQ(tracker.lastQueried(), 1u);
  // The world-frame path from where it was last clear crosses the wall the deck carried past it.
  EXPECT_TRUE(world.segmentHitsStatic(positions[body] - Vec3d(4.0, 0, 0), positions[body]));

  // Set under the deck: its path relative to the deck goes through the deck's plates.
  positions[body].z() -= 0.5;
  world.setPoses(positions, rotations);
  const ContainmentReport& r = tracker.update();
  ASSERT_EQ(r.count(), 1u);
  EXPECT_EQ(r.reasons[0], InsideSolid::WentThrough);
}

// The solids' index (World::indexSolids) changes no answer: 40 small grids (static, kinematic
// and a dynamic one falling) with crates raining through them, 10 km from the origin; random
// points and segments near them queried with the index and without (the loop over every solid).
TEST(Containment, TheSolidsIndexAnswersLikeTheLoopOverEverySolid) {
  SceneDescription scene;
  scene.name = "many_solids";
  const Vec3d origin(1e4, -1e4, 0);
  SeededRandom rng(17);
  for (int k = 0; k < 40; ++k) {
    GridDescription g;
    g.name = "g" + std::to_string(k);
    g.position = origin + Vec3d(rng.uniform(0, 60), rng.uniform(0, 60), rng.uniform(0, 20));
    g.motion = k % 3 == 0 ? MotionType::Kinematic : k == 7 ? MotionType::Dynamic : MotionType::Static;
    g.kinematic.linearVelocity = Vec3d(rng.uniform(-3, 3), rng.uniform(-3, 3), 0);
    for (int b = 0; b < 12; ++b)
      g.bricks.push_back(Brick::box(Vec3f(float(rng.uniform(-3, 3)), float(rng.uniform(-3, 3)), float(rng.uniform(-1, 1))),
                                    Vec3f(float(rng.uniform(0.1, 1.5)), float(rng.uniform(0.1, 1.5)), float(rng.uniform(0.05, 0.6)))));
    scene.grids.push_back(g);
  }
  SpawnerDescription rain;
  rain.count = 200;
  rain.seed = 3;
  rain.regionMin = origin + Vec3d(0, 0, 25);
  rain.regionMax = origin + Vec3d(60, 60, 40);
  scene.spawners.push_back(rain);
  World world(scene, 2);
  uint32_t inside = 0, hits = 0, sole = 0;
  for (int f = 0; f < 40; ++f) {
    world.step();
    std::vector<Vec3d> points, ends;
    for (int q = 0; q < 400; ++q) {
      // Half near a grid's centre (inside its bricks often), half anywhere around them.
      const Vec3d around = world.bodies().position[uint32_t(rng.uniform(0, 39.99))];
      points.push_back(q % 2 ? around + Vec3d(rng.uniform(-3, 3), rng.uniform(-3, 3), rng.uniform(-1, 1))
                             : origin + Vec3d(rng.uniform(-5, 65), rng.uniform(-5, 65), rng.uniform(-3, 25)));
      ends.push_back(points.back() + Vec3d(rng.uniform(-4, 4), rng.uniform(-4, 4), rng.uniform(-4, 4)));
    }
    std::vector<InsideSolid> in;
    std::vector<uint8_t> hit;
    std::vector<uint32_t> near;
    for (size_t q = 0; q < points.size(); ++q) {
      in.push_back(world.pointInsideSolid(points[q], kInvalidIndex));
      hit.push_back(world.segmentHitsStaticGrid(points[q], ends[q]));
      near.push_back(world.soleSolidReaching(WorldAabb{points[q].cwiseMin(ends[q]), points[q].cwiseMax(ends[q])}, 40));
    }
    world.indexSolids();
    for (size_t q = 0; q < points.size(); ++q) {
      ASSERT_EQ(world.pointInsideSolid(points[q], kInvalidIndex), in[q]) << "frame " << f << " point " << q;
      ASSERT_EQ(world.segmentHitsStaticGrid(points[q], ends[q]), hit[q] != 0) << "frame " << f << " segment " << q;
      ASSERT_EQ(world.soleSolidReaching(WorldAabb{points[q].cwiseMin(ends[q]), points[q].cwiseMax(ends[q])}, 40), near[q])
          << "frame " << f << " segment " << q;
      inside += in[q] != InsideSolid::No;
      hits += hit[q];
      sole += near[q] != kInvalidIndex;
    }
  }
  // A segment against one grid alone (`only`) and against all but one (`except`): together, as
  // against all of them.
  for (size_t q = 0; q < 60; ++q) {
    const Vec3d a = world.bodies().position[uint32_t(q % 40)] + Vec3d(rng.uniform(-4, 4), rng.uniform(-4, 4), rng.uniform(-2, 2));
    const Vec3d b = a + Vec3d(rng.uniform(-6, 6), rng.uniform(-6, 6), rng.uniform(-3, 3));
    bool any = false;
    for (uint32_t g = 0; g < 40; ++g) any = any || world.segmentHitsStaticGrid(a, b, g);
    ASSERT_EQ(world.segmentHitsStaticGrid(a, b), any) << "segment " << q;
    const uint32_t g = uint32_t(q % 40);
    ASSERT_EQ(world.segmentHitsStaticGrid(a, b), world.segmentHitsStaticGrid(a, b, g) || world.segmentHitsStaticGrid(a, b, kInvalidIndex, g))
        << "segment " << q;
  }
  // The comparison meant something: points inside bricks, segments through them, points near one grid.
  std::printf("[ containment ] %u points inside, %u segments hit, %u segments near one solid\n", inside, hits, sole);
  EXPECT_GT(inside, 500u);
  EXPECT_GT(hits, 1000u);
  EXPECT_GT(sole, 1000u);
}

// A ball lying 5 mm over a dynamic raft (no gravity), a wall on the raft 0.6 m from it: bricks
// cut off the raft's far end move its centre of mass (its body frame) 1.8 m along the raft while
// its bricks stay where they were. The ball's places are kept in the raft's shape frame, so
// they stay put too: the ball is at rest on the raft and not queried again (kept in the body
// frame, it would seem to have moved 1.8 m).
TEST(Containment, PlacesOnADynamicGridStayPutWhenItsCentreOfMassMoves) {
  SceneDescription scene;
  scene.name = "raft";
  scene.settings.gravity = Vec3d::Zero();
  GridDescription raft;
  raft.name = "raft";
  raft.motion = MotionType::Dynamic;
  for (int x = 0; x < 12; ++x) raft.bricks.push_back(Brick::box(Vec3f(float(x) + 0.5f, 1.f, 0.1f), Vec3f(0.5f, 1.f, 0.1f)));
  raft.bricks.push_back(Brick::box(Vec3f(5.7f, 1.f, 0.7f), Vec3f(0.1f, 1.f, 0.5f)));  // the wall
  scene.grids.push_back(raft);
  SpawnerDescription ball;  // not a box: a box spawns turned, its corners in the raft
  ball.shape = SpawnerDescription::Shape::Sphere;
  ball.count = 1;
  ball.regionMin = ball.regionMax = Vec3d(5.0, 1.0, 0.405);  // 5 mm over the raft: near its bricks
  ball.radius = 0.2f;
  scene.spawners.push_back(ball);
  World world(scene, 2);
  const uint32_t ballBody = 1;
  ContainmentTracker tracker(world);
  for (int f = 0; f < 5; ++f) {
    world.step();
    ASSERT_EQ(tracker.update().count(), 0u);
    ASSERT_TRUE(world.nearSolidLastStep(ballBody)) << "the ball lies on the raft's bricks";
  }
  const Vec3d before = world.bodies().position[0];
  const std::vector<uint32_t> farEnd{0, 1, 2, 3};
  world.removeBricks(0, farEnd);
  uint32_t queried = 0;
  for (int f = 0; f < 5; ++f) {
    world.step();
    const ContainmentReport& r = tracker.update();
    ASSERT_EQ(r.count(), 0u) << "frame " << f << ": " << insideSolidName(r.reasons[0]);
    queried += tracker.lastQueried();
  }
  // Queried: the raft alone (a dynamic body too), whose centre moved 1.8 m in the world.
  EXPECT_EQ(queried, 1u) << "the ball did not move on the raft";
  EXPECT_GT((world.bodies().position[0] - before).x(), 1.5) << "the raft's centre of mass moved along it";
  EXPECT_LT(world.bodies().linearVelocity[ballBody].norm(), 1e-3f) << "the ball stayed where it was";
}

}  // namespace
}  // namespace bw
