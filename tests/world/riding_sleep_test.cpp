// Bodies asleep on a kinematic deck in uniform flight ride it (SleepState's carriers): they fall
// asleep relative to the deck, move with it exactly and make no contacts while it flies
// straight; a deck that turns keeps them awake, and one that changes speed wakes them.
#include <algorithm>
#include <cstdio>
#include <gtest/gtest.h>
#include <limits>

#include "collision/core/argument_checks.h"
#include "world/containment.h"
#include "world/scene_file.h"
#include "world/world_tuning.h"
#include "world/world.h"

namespace bw {
namespace {

// A 20 m x 20 m deck far from the origin, flying at (4, 1, 0) m/s (turning at `turn` rad/s
// about z), and boxes of 0.2-1.2 m dropped onto it from 0.3-1 m up with the deck's velocity.
SceneDescription deckScene(float turn) {
  std::string json = R"({
    "name": "deck", "settings": {"timestep": 0.016666667, "substeps": 2, "solver_iterations": 10},
    "grids": [{"name": "deck", "bricks": [{"position": [0, 0, -0.25], "half_size": [10, 10, 0.25]}],
               "position": [30000, -20000, 100], "motion": "kinematic",
               "linear_velocity": [4, 1, 0], "angular_velocity": [0, 0, TURN]}],
    "spawners": [{"shape": "box", "count": 6, "half_extents": [0.1, 0.1, 0.1], "seed": 1, "velocity": [4, 1, 0],
                  "region": {"min": [29994, -20006, 100.4], "max": [30006, -19994, 101]}},
                 {"shape": "box", "count": 3, "half_extents": [0.6, 0.4, 0.3], "seed": 2, "velocity": [4, 1, 0],
                  "region": {"min": [29994, -20006, 101.0], "max": [30006, -19994, 101.2]}}]})";
  json.replace(json.find("TURN"), 4, std::to_string(turn));
  return parseScene(json, "deck.json");
}

constexpr uint32_t kDeck = 0, kBoxes = 9;

// Steps until every box is asleep (at most `frames`); returns the frames stepped.
int stepUntilAllAsleep(World& world, int frames) {
  for (int f = 0; f < frames; ++f) {
    world.step();
    if (world.sleepingCount() == kBoxes) return f + 1;
  }
  return frames;
}

TEST(RidingSleep, BoxesOnADeckInUniformFlightFallAsleepAndRideItExactly) {
  World world(deckScene(0.f), 1);
  ContainmentTracker containment(world);
  const int settled = stepUntilAllAsleep(world, 300);
  ASSERT_EQ(world.sleepingCount(), kBoxes) << "after " << settled << " frames";
  const BodyStore& b = world.bodies();
  std::vector<Vec3d> onDeck;
  for (uint32_t i = 1; i <= kBoxes; ++i) {
    onDeck.push_back(b.position[i] - b.position[kDeck]);
    EXPECT_EQ(b.linearVelocity[i], b.linearVelocity[kDeck]) << "box " << i << " rides with the deck's velocity";
    EXPECT_GT(onDeck.back().z(), 0.05) << "box " << i << " rests on the deck's top";
  }
  const Vec3d deckBefore = b.position[kDeck];
  for (int f = 0; f < 120; ++f) {
    world.step();
    EXPECT_EQ(world.sleepingCount(), kBoxes) << "frame " << f;
    EXPECT_EQ(world.lastStats().contacts, 0u) << "frame " << f << ": riders moving alike with the deck make no contacts";
    EXPECT_EQ(containment.update().count(), 0u);
  }
  EXPECT_NEAR((b.position[kDeck] - deckBefore).x(), 4.0 * 2.0, 1e-3);  // 2 s at 4 m/s
  for (uint32_t i = 1; i <= kBoxes; ++i) {
    const Vec3d drift = b.position[i] - b.position[kDeck] - onDeck[i - 1];
    EXPECT_LT(drift.norm(), 1e-9) << "box " << i << " moved on the deck while asleep";
  }
}

TEST(RidingSleep, TheSameOnAnyThreadCount) {
  uint64_t reference = 0;
  for (int threads : {1, 2, 4}) {
    World world(deckScene(0.f), threads);
    for (int f = 0; f < 200; ++f) world.step();
    EXPECT_EQ(world.sleepingCount(), kBoxes) << threads << " threads";
    if (threads == 1) reference = world.stateHash();
    EXPECT_EQ(world.stateHash(), reference) << threads << " threads";
  }
}

TEST(RidingSleep, ADeckThatTurnsKeepsItsBoxesAwake) {
  World world(deckScene(0.05f), 1);
  ContainmentTracker containment(world);
  for (int f = 0; f < 300; ++f) {
    world.step();
    ASSERT_EQ(world.sleepingCount(), 0u) << "frame " << f << ": a box slept on a turning deck";
  }
  EXPECT_EQ(containment.update().count(), 0u);
}

TEST(RidingSleep, ADeckThatChangesSpeedWakesItsBoxesAndTheyRideOnAtTheNewSpeed) {
  World world(deckScene(0.f), 1);
  ContainmentTracker containment(world);
  stepUntilAllAsleep(world, 300);
  ASSERT_EQ(world.sleepingCount(), kBoxes);
  const Vec3f faster(5.f, 1.f, 0.f);
  world.setKinematicVelocity(kDeck, faster, Vec3f::Zero());
  world.step();
  EXPECT_EQ(world.sleepingCount(), 0u) << "the deck sped up under its boxes: every one meets it again";
  const int settled = stepUntilAllAsleep(world, 600);
  ASSERT_EQ(world.sleepingCount(), kBoxes) << "after " << settled << " frames at the new speed";
  const BodyStore& b = world.bodies();
  for (uint32_t i = 1; i <= kBoxes; ++i) {
    EXPECT_EQ(b.linearVelocity[i], faster) << "box " << i;
    EXPECT_GT((b.position[i] - b.position[kDeck]).z(), 0.05) << "box " << i << " still on the deck";
  }
  EXPECT_EQ(containment.update().count(), 0u);
}

// The deck carries its sleeping boxes under a static wall hung 10 cm above its top: the wall
// moves unalike, so it meets each box, wakes it and holds it back while the deck slides away
// beneath (the boxes then fall off its back edge). None passes into the wall.
TEST(RidingSleep, AStaticWallInTheDecksWayWakesItsBoxesAndStopsThem) {
  SceneDescription scene = deckScene(0.f);
  const double wallFace = 30018;  // x of the wall's face towards the deck
  GridDescription wall;
  wall.name = "wall";
  wall.position = Vec3d(wallFace + 0.5, -20000, 101.55);  // spans z 100.1-103: a 10 cm gap above the deck
  wall.bricks.push_back(Brick::box(Vec3f::Zero(), Vec3f(0.5f, 20.f, 1.45f)));
  scene.grids.push_back(wall);
  World world(scene, 2);
  ContainmentTracker containment(world);
  const BodyStore& b = world.bodies();
  uint32_t boxes = 0;
  for (uint32_t i = 0; i < b.size(); ++i) boxes += b.motion[i] == MotionType::Dynamic;
  ASSERT_EQ(boxes, kBoxes);
  uint32_t mostAsleep = 0;
  for (int f = 0; f < 600; ++f) {
    world.step();
    mostAsleep = std::max(mostAsleep, world.sleepingCount());
    ASSERT_EQ(containment.update().count(), 0u) << "frame " << f;
    for (uint32_t i = 0; i < b.size(); ++i) {
      if (b.motion[i] != MotionType::Dynamic) continue;
      ASSERT_LT(b.position[i].x(), wallFace) << "frame " << f << ": body " << i << " went through the wall";
    }
  }
  EXPECT_EQ(mostAsleep, kBoxes) << "the boxes were asleep on the deck before the wall came";
  EXPECT_EQ(world.sleepingCount(), 0u) << "the wall woke them all";
}

// The deck, now 350 strips 4 cm wide across its flight, loses two random strips a frame (the
// scene's edit load) once its boxes sleep. A box wakes when a strip within 2 cm of it goes
// (the broadphase margin); one 3-8 cm from it stays asleep, though its world-frame sweep
// (4.1 m/s for a frame: 8.9 cm) reaches the strip: relative to the deck it does not move.
TEST(RidingSleep, EditsOnTheFlyingDeckWakeOnlyTheBoxesTheyReach) {
  SceneDescription scene = deckScene(0.f);
  GridDescription& deck = scene.grids[0];
  deck.bricks.clear();
  constexpr float kStrip = 0.04f;
  for (int k = 0; k < 350; ++k)
    deck.bricks.push_back(Brick::box(Vec3f(-7.f + kStrip * (k + 0.5f), 0.f, -0.25f), Vec3f(kStrip / 2, 10.f, 0.25f)));
  constexpr uint32_t kFirstEdit = 300, kLastEdit = 360;
  EditLoadDescription edits;
  edits.grid = "deck";
  edits.perFrame = 2;
  edits.firstFrame = kFirstEdit;
  edits.lastFrame = kLastEdit;
  edits.seed = 7;
  scene.edits.push_back(edits);
  World world(scene, 1);
  world.recordEdits(true);
  ContainmentTracker containment(world);
  const BodyStore& b = world.bodies();
  for (uint32_t f = 0; f < kFirstEdit; ++f) world.step();
  ASSERT_EQ(world.sleepingCount(), kBoxes) << "the boxes sleep on the deck before the edits start";
  // A box's tight world box, and the separation between two boxes (0 when they overlap).
  const auto tightBox = [&](uint32_t i) {
    const RigidTransform pose = b.shapePose(i);
    const Vec3d half = (pose.rotation.toRotationMatrix().cwiseAbs() * b.shape[i].primitive.localHalfExtents()).cast<double>();
    return WorldAabb{pose.translation - half, pose.translation + half};
  };
  const auto separation = [](const WorldAabb& x, const WorldAabb& y) {
    return std::max(0.0, ((x.min - y.max).cwiseMax(y.min - x.max)).maxCoeff());
  };
  const double sweep = tuning::kBroadphaseMargin + b.linearVelocity[kDeck].cast<double>().norm() * scene.settings.timestep;
  uint32_t woken = 0, spared = 0;
  for (uint32_t f = kFirstEdit; f <= kLastEdit; ++f) {
    std::vector<WorldAabb> before(b.size());
    std::vector<bool> wasAsleep(b.size());
    for (uint32_t i = 1; i <= kBoxes; ++i) before[i] = tightBox(i), wasAsleep[i] = world.asleep(i);
    const Vec3d deckAt = b.position[kDeck];
    world.step();
    for (uint32_t i = 1; i <= kBoxes; ++i) {
      if (!wasAsleep[i]) continue;
      double nearest = std::numeric_limits<double>::infinity();
      for (const BrickEdit& e : world.lastEdits().bricks) {
        const Vec3d centre = deckAt + e.value.position.cast<double>(), half = e.value.halfSize.cast<double>();
        nearest = std::min(nearest, separation(before[i], {centre - half, centre + half}));
      }
      bool nearAnother = false;  // a box touching another may wake with it
      for (uint32_t j = 1; j <= kBoxes; ++j) nearAnother |= j != i && separation(before[i], before[j]) < 0.1;
      if (nearest < tuning::kBroadphaseMargin - 1e-3) {
        EXPECT_FALSE(world.asleep(i)) << "frame " << f << ": a strip " << nearest << " m from box " << i << " went";
        woken += !world.asleep(i);
      } else if (nearest > 0.03 && nearest < sweep - 0.005 && !nearAnother) {
        EXPECT_TRUE(world.asleep(i)) << "frame " << f << ": a strip " << nearest << " m from box " << i
                                     << " woke it, though it does not move relative to the deck";
        spared += world.asleep(i);
      }
    }
    ASSERT_EQ(containment.update().count(), 0u) << "frame " << f;
  }
  EXPECT_GT(woken, 0u) << "no strip under a sleeping box went: the test shows nothing";
  EXPECT_GT(spared, 0u) << "no strip went within the world-frame sweep but beyond the margin: the test shows nothing";
  std::printf("[ edits ] %u boxes woken by strips under them, %u left asleep beside them\n", woken, spared);
}

TEST(RidingSleep, BadKinematicVelocitiesAreRefusedAndChangeNothing) {
  World world(deckScene(0.f), 1);
  const Vec3f before = world.bodies().linearVelocity[kDeck];
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(world.setKinematicVelocity(1, Vec3f::Zero(), Vec3f::Zero()), InvalidInput);  // a dynamic box
  EXPECT_THROW(world.setKinematicVelocity(99, Vec3f::Zero(), Vec3f::Zero()), InvalidInput);
  EXPECT_THROW(world.setKinematicVelocity(kDeck, Vec3f(nan, 0, 0), Vec3f::Zero()), InvalidInput);
  EXPECT_THROW(world.setKinematicVelocity(kDeck, Vec3f(0, 2e4f, 0), Vec3f::Zero()), InvalidInput);
  EXPECT_THROW(world.setKinematicVelocity(kDeck, Vec3f::Zero(), Vec3f(0, 0, 1e3f)), InvalidInput);
  EXPECT_EQ(world.bodies().linearVelocity[kDeck], before);
  try {
    world.setKinematicVelocity(1, Vec3f::Zero(), Vec3f::Zero());
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("not kinematic"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace bw
