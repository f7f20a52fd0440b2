// World: bodies come to rest on grids at the right height, stacks stand, kinematic grids follow
// their script, and the final state is bit-identical for 1, 2, 4 and 16 threads.
#include <gtest/gtest.h>

#include "world/scene_file.h"
#include "world/world.h"

namespace bw {
namespace {

TEST(World, BoxDroppedOnAGridComesToRestOnIt) {
  const SceneDescription scene = parseScene(R"({
    "name": "drop", "settings": {"timestep": 0.016666667, "substeps": 2, "solver_iterations": 10},
    "grids": [{"name": "floor", "bricks": [{"position": [0, 0, -0.5], "half_size": [5, 5, 0.5]},
                                           {"position": [12, 0, -0.5], "half_size": [5, 5, 0.5]}]}],
    "spawners": [{"shape": "box", "count": 1, "half_extents": [0.25, 0.25, 0.25],
                  "region": {"min": [1, 1, 3], "max": [1, 1, 3]}}]})",
                                            "drop.json");
  World world(scene, 1);
  for (int f = 0; f < 240; ++f) world.step();
  const BodyStore& b = world.bodies();
  ASSERT_EQ(b.size(), 2u);
  // Resting on a face: its centre 0.25 above the floor top (z = 0), within solver slop.
  EXPECT_NEAR(b.position[1].z(), 0.25, 0.02);
  EXPECT_LT(b.linearVelocity[1].norm(), 0.05f);
  // It may tumble on landing (its orientation is random): within two box widths of where it fell.
  EXPECT_NEAR(b.position[1].x(), 1.0, 1.0);
}

TEST(World, TenBoxStackStaysStanding) {
  World world(loadScene(std::string(BW_SCENES_DIR) + "/stack10.json"), 1);
  for (int f = 0; f < 300; ++f) world.step();  // 5 s
  const BodyStore& b = world.bodies();
  for (uint32_t i = 1; i <= 10; ++i) {
    EXPECT_NEAR(b.position[i].z(), 0.25 + 0.5 * (i - 1), 0.03) << "box " << i;
    EXPECT_LT(std::hypot(b.position[i].x(), b.position[i].y()), 0.05) << "box " << i;
  }
}

TEST(World, KinematicGridFollowsItsScript) {
  const SceneDescription scene = parseScene(R"({
    "name": "spin", "settings": {"gravity": [0, 0, 0]},
    "grids": [{"name": "ring", "bricks": [{"position": [10, 0, 0], "half_size": [0.5, 0.5, 0.5]}],
               "motion": "kinematic", "angular_velocity": [0, 0, 0.5], "linear_velocity": [1, 0, 0]}]})",
                                            "spin.json");
  World world(scene, 1);
  for (int f = 0; f < 60; ++f) world.step();  // 1 s
  const BodyStore& b = world.bodies();
  EXPECT_NEAR(b.position[0].x(), 1.0, 1e-4);
  const float angle = 2.f * std::atan2(b.rotation[0].z(), b.rotation[0].w());
  EXPECT_NEAR(angle, 0.5f, 1e-3f);
}

TEST(World, StateIsIdenticalForAnyThreadCount) {
  const SceneDescription scene = parseScene(R"({
    "name": "det", "settings": {"timestep": 0.016666667, "frames": 40},
    "grids": [{"name": "city", "generator": "city_block", "scale": 0.003, "seed": 7},
              {"name": "crate", "bricks": [{"position": [0, 0, 0], "half_size": [0.2, 0.2, 0.2]},
                                           {"position": [0.4, 0, 0], "half_size": [0.2, 0.2, 0.2]}],
               "position": [0, 0, -500]}],
    "spawners": [{"shape": "box", "count": 60, "half_extents": [0.25, 0.25, 0.25], "region": {"min": [5, 5, 55], "max": [60, 60, 62]}},
                 {"shape": "capsule", "count": 30, "radius": 0.2, "half_height": 0.3, "region": {"min": [5, 5, 55], "max": [60, 60, 62]}},
                 {"shape": "grid", "grid": "crate", "count": 10, "region": {"min": [5, 5, 55], "max": [60, 60, 62]}}]})",
                                            "det.json");
  uint64_t reference = 0;
  for (int threads : {1, 2, 4, 16}) {
    World world(scene, threads);
    uint32_t contacts = 0;
    for (int f = 0; f < 150; ++f) {
      world.step();
      contacts += world.lastStats().contacts;
    }
    if (threads == 1) {
      reference = world.stateHash();
      EXPECT_GT(contacts, 100u) << "the bodies must actually land and touch";
    }
    EXPECT_EQ(world.stateHash(), reference) << threads << " threads";
  }
}

}  // namespace
}  // namespace bw

namespace bw {
namespace {

// Shock propagation and big-island colouring together (a pile poured into a bin): the same
// state for any thread count.
TEST(World, ShockPropagationAndColouredIslandsAreIdenticalForAnyThreadCount) {
  SceneDescription scene = loadScene(std::string(BW_SCENES_DIR) + "/crate_pile.json");
  scene.settings.shockPropagation = true;
  scene.spawners[0].count = 400;
  scene.spawners[0].regionMax.z() = 8;
  uint64_t reference = 0;
  uint32_t split = 0;
  for (int threads : {1, 2, 4}) {
    World world(scene, threads);
    for (int f = 0; f < 90; ++f) {
      world.step();
      if (threads == 1) split += world.lastStats().splitIslands;
    }
    if (threads == 1) reference = world.stateHash();
    EXPECT_EQ(world.stateHash(), reference) << threads << " threads";
  }
  EXPECT_GT(split, 0u) << "the pile must form an island big enough to be coloured";
}

// An L of three bricks flies and spins with no gravity; one arm is removed between steps. The
// body must take the two remaining bricks' mass, centre of mass and inertia, and every remaining
// brick keep its velocity: from then on it moves exactly as a world built with only those two
// bricks, placed where the grid was and moving as its bricks moved.
GridDescription flyingL(std::vector<Brick> bricks, const Vec3d& position, const Quatf& rotation, const Vec3d& velocity,
                        const Vec3f& spin) {
  GridDescription g;
  g.name = "l";
  g.bricks = std::move(bricks);
  g.position = position;
  g.rotation = rotation;
  g.motion = MotionType::Dynamic;
  g.kinematic.linearVelocity = velocity;
  g.kinematic.angularVelocity = spin;
  return g;
}

TEST(World, DynamicGridTakesItsNewMassAfterAnEditAndItsBricksKeepTheirVelocity) {
  const Brick corner = Brick::box(Vec3f(0, 0, 0), Vec3f::Constant(0.5f)), armX = Brick::box(Vec3f(1, 0, 0), Vec3f::Constant(0.5f)),
              armY = Brick::box(Vec3f(0, 2, 0), Vec3f(0.5f, 1.5f, 0.5f));
  SceneDescription scene;
  scene.name = "edit_mass";
  scene.settings.gravity = Vec3d::Zero();
  scene.grids = {flyingL({corner, armX, armY}, Vec3d(3, -2, 7), Quatf::Identity(), Vec3d(1, 2, -0.5), Vec3f(0.3f, -0.2f, 0.9f))};
  World edited(scene, 1);
  for (int f = 0; f < 10; ++f) edited.step();
  const float massBefore = 1.f / edited.bodies().inverseMass[0];
  // The brick ids are the scene's order; remove the x arm.
  ASSERT_EQ(edited.grid(0).brick(1).position, armX.position);
  edited.editGrid(0).removeBrick(1);

  // The reference: the two remaining bricks where the grid is now, the centre of mass moving as
  // that point of the three-brick body moved (v + w x r).
  const BodyStore& b = edited.bodies();
  const RigidTransform gridPose = b.shapePose(0);
  const MassProperties two = edited.grid(0).massProperties();
  const Vec3d newCentre = gridPose.pointToWorld(two.centerOfMass.cast<float>());
  const Vec3f w = b.angularVelocity[0];
  const Vec3f v = b.linearVelocity[0] + w.cross((newCentre - b.position[0]).cast<float>());
  SceneDescription remaining = scene;
  remaining.grids = {flyingL({corner, armY}, gridPose.translation, gridPose.rotation, v.cast<double>(), w)};
  World reference(remaining, 1);

  for (int f = 0; f < 60; ++f) {
    edited.step();
    reference.step();
  }
  const BodyStore& r = reference.bodies();
  EXPECT_NEAR(1.f / b.inverseMass[0], massBefore * 0.8f, massBefore * 1e-4f) << "the x arm was a fifth of the mass";
  EXPECT_NEAR(b.inverseMass[0], r.inverseMass[0], r.inverseMass[0] * 1e-5f);
  EXPECT_LT((b.inverseInertia[0] - r.inverseInertia[0]).norm(), r.inverseInertia[0].norm() * 1e-4f);
  EXPECT_LT((b.position[0] - r.position[0]).norm(), 1e-4) << "centre of mass";
  EXPECT_LT((b.linearVelocity[0] - r.linearVelocity[0]).norm(), 1e-4f);
  EXPECT_LT((b.angularVelocity[0] - r.angularVelocity[0]).norm(), 1e-5f);
  const RigidTransform poseE = b.shapePose(0), poseR = r.shapePose(0);
  EXPECT_LT((poseE.translation - poseR.translation).norm(), 1e-4) << "the grid's origin";
  EXPECT_LT(poseE.rotation.angularDistance(poseR.rotation), 1e-4f) << "the grid's orientation";
}

}  // namespace
}  // namespace bw
