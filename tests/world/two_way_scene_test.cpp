// Issue 19's scenes and the scene checks that judge them (scene_checks.h): the chain stays
// linked brick against brick and comes apart when its links meet as hulls; the docking ship
// enters the hangar's slot two-way and is stopped at its mouth by the hangar's hull; the link
// check sees a link pulled away, ends_in sees a ship outside its box; bad checks are refused.
#include <gtest/gtest.h>
#include <string>

#include "world/containment.h"
#include "world/scene_checks.h"
#include "world/scene_file.h"
#include "world/world.h"

namespace bw {
namespace {

SceneDescription shipped(const std::string& name) { return loadScene(std::string(BW_SCENES_DIR) + "/" + name + ".json"); }

struct Outcome {
  LinkCheckReport links;
  std::vector<EndsInReport> ends;
  bool pass = false;
  uint32_t insideSolid = 0;
  float deepest = 0;       // deepest contact over the run (m)
  float fastestEnd = 0;    // fastest dynamic body at the end (m/s)
  uint64_t hash = 0;
};

// Under a sanitizer (BW_SANITIZED, cmake/warnings.cmake) the long runs are a fifth as long: the
// same code, whose memory is what a sanitizer checks (the release run checks the physics of the
// whole stretch, and the CLI's chain test runs 10 s of the chain under the sanitizers as well).
#ifdef BW_SANITIZED
constexpr uint32_t kLongRunDivisor = 5;
#else
constexpr uint32_t kLongRunDivisor = 1;
#endif

Outcome run(SceneDescription scene, uint32_t frames, GridPairMode mode, int threads = 1) {
  scene.settings.gridPairs = mode;
  World world(scene, threads);
  ContainmentTracker containment(world);
  SceneCheckTracker checks(world);
  Outcome o;
  for (uint32_t f = 0; f < frames; ++f) {
    world.step();
    containment.update();
    checks.update();
    for (uint32_t k = 0; k < world.pairs().size(); ++k)
      for (const Contact& c : world.pairContacts(k)) o.deepest = std::max(o.deepest, c.depth);
  }
  o.links = checks.links();
  o.ends = checks.endsIn();
  o.pass = checks.pass();
  o.insideSolid = containment.report().count();
  for (uint32_t i = 0; i < world.bodies().size(); ++i)
    if (world.bodies().motion[i] == MotionType::Dynamic) o.fastestEnd = std::max(o.fastestEnd, world.bodies().linearVelocity[i].norm());
  o.hash = world.stateHash();
  return o;
}

// 10 s of the chain swinging (the CLI test runs the full 60 s): every link stays linked, none
// sinks into another, nothing ends inside solid, and the chain still swings.
TEST(TwoWayScenes, ChainStaysLinkedBrickAgainstBrick) {
  const Outcome o = run(shipped("chain"), 600 / kLongRunDivisor, GridPairMode::TwoWay);
  EXPECT_EQ(o.links.pairs, 12u);
  EXPECT_EQ(o.links.everParted, 0u) << o.links.firstParted << " at frame " << o.links.firstPartedFrame;
  EXPECT_TRUE(o.pass);
  EXPECT_EQ(o.insideSolid, 0u);
  EXPECT_LT(o.deepest, 0.02f);
  EXPECT_GT(o.fastestEnd, 0.1f) << "the chain stopped swinging";
}

// The check can fail: as hulls the links' holes are solid, interlocked links start 'inside'
// each other and are pushed apart.
TEST(TwoWayScenes, ChainComesApartAsHulls) {
  const Outcome o = run(shipped("chain"), 120, GridPairMode::Convex);
  EXPECT_GT(o.links.everParted, 0u);
  EXPECT_FALSE(o.pass);
}

// auto takes the two-way path for every pair of links (a link's hull is far more than 1.5x its
// bricks), so it is the same simulation bit for bit, at any thread count.
TEST(TwoWayScenes, AutoPairsLinksBrickAgainstBrick) {
  const SceneDescription chain = shipped("chain");
  const uint32_t frames = 240 / kLongRunDivisor;
  const uint64_t twoWay = run(chain, frames, GridPairMode::TwoWay).hash;
  EXPECT_EQ(run(chain, frames, GridPairMode::Auto).hash, twoWay);
  EXPECT_EQ(run(chain, frames, GridPairMode::Auto, 4).hash, twoWay);
}

// The ship enters the slot and slides on its floor two-way; as the hangar's hull (it has fewer
// bricks than the ship, so the convex approach takes its hull) the mouth is closed.
TEST(TwoWayScenes, DockingShipEntersTheSlotOnlyTwoWay) {
  const SceneDescription docking = shipped("docking");
  const Outcome in = run(docking, docking.settings.frames, GridPairMode::Auto);
  ASSERT_EQ(in.ends.size(), 1u);
  EXPECT_TRUE(in.ends[0].inside) << "ship at x = " << in.ends[0].position.x();
  EXPECT_TRUE(in.pass);
  EXPECT_EQ(in.insideSolid, 0u);
  EXPECT_GT(in.fastestEnd, 1.f) << "the ship was stopped in the slot";
  const Outcome stopped = run(docking, docking.settings.frames, GridPairMode::Convex);
  EXPECT_FALSE(stopped.ends[0].inside);
  EXPECT_LT(stopped.ends[0].position.x(), 0.0) << "the ship's centre of mass passed the mouth";
  EXPECT_FALSE(stopped.pass);
}

// A link moved away from its neighbours parts two pairs; brought back they are linked again,
// but the run stays failed (a pair that parted once may have passed through).
TEST(TwoWayScenes, LinkCheckSeesALinkPulledAway) {
  World world(shipped("chain"), 1);
  SceneCheckTracker checks(world);
  EXPECT_TRUE(checks.pass());
  EXPECT_EQ(checks.links().partedNow, 0u);
  std::vector<Vec3d> positions = world.bodies().position;
  const std::vector<Quatf> rotations = world.bodies().rotation;
  const uint32_t link = world.gridBody("link_06");
  positions[link].x() += 3.0;  // wider than a link (1.92 m): out of both neighbours' holes
  world.setPoses(positions, rotations);
  checks.update();
  EXPECT_EQ(checks.links().partedNow, 2u);
  EXPECT_EQ(checks.links().everParted, 2u);
  EXPECT_EQ(checks.links().firstParted, "link_05 / link_06");
  positions[link].x() -= 3.0;
  world.setPoses(positions, rotations);
  checks.update();
  EXPECT_EQ(checks.links().partedNow, 0u);
  EXPECT_EQ(checks.links().everParted, 2u);
  EXPECT_FALSE(checks.pass());
}

// A link turned a quarter about its long axis stays within its neighbour's bounds: only a
// displacement out of the hole parts a pair, not a turn in place.
TEST(TwoWayScenes, LinkCheckIgnoresATurnInPlace) {
  World world(shipped("chain"), 1);
  SceneCheckTracker checks(world);
  std::vector<Quatf> rotations = world.bodies().rotation;
  const uint32_t link = world.gridBody("link_03");
  rotations[link] = (rotations[link] * Quatf(Eigen::AngleAxisf(1.5707963f, Vec3f::UnitZ()))).normalized();
  world.setPoses(world.bodies().position, rotations);
  checks.update();
  EXPECT_EQ(checks.links().partedNow, 0u);
}

TEST(TwoWayScenes, EndsInFollowsTheGridsCentreOfMass) {
  World world(shipped("docking"), 1);
  SceneCheckTracker checks(world);
  ASSERT_EQ(checks.endsIn().size(), 1u);
  EXPECT_FALSE(checks.endsIn()[0].inside);  // it starts outside the hangar
  std::vector<Vec3d> positions = world.bodies().position;
  const uint32_t ship = world.gridBody("ship");
  EXPECT_EQ(checks.endsIn()[0].position, positions[ship]);
  positions[ship].x() = 40.0;
  world.setPoses(positions, world.bodies().rotation);
  EXPECT_TRUE(checks.endsIn()[0].inside);
  EXPECT_TRUE(checks.pass());
}

// Checks built in code get the scene file's validation: unknown grids and empty chains are
// refused before anything is built.
TEST(TwoWayScenes, BadChecksInCodeAreRefusedNamingTheField) {
  SceneDescription scene = shipped("chain");
  scene.checks.linked[0][3] = "link_99";
  try {
    World world(scene, 1);
    ADD_FAILURE() << "accepted an unknown grid";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("checks.linked[0][3]"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("link_99"), std::string::npos) << e.what();
  }
  scene = shipped("docking");
  scene.checks.endsIn[0].min.x() = 200;
  EXPECT_THROW(World(scene, 1), SceneError);
  scene = shipped("chain");
  scene.checks.linked[0].resize(1);
  EXPECT_THROW(World(scene, 1), SceneError);
}

}  // namespace
}  // namespace bw
