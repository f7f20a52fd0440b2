// Continuous collision: fast bodies do not tunnel through thin structures. The world's design is
// speculative contacts (README "Continuous collision"): a pair whose bodies can close a gap this
// step gets contacts out to that gap, and the solver lets the gap close but not cross. These
// tests fire bodies far faster than their size per step at thin targets, from seeded random
// positions, orientations and directions, and demand that every run stays on the near side.
#include <cmath>
#include <gtest/gtest.h>
#include <string>

#include "collision/core/seeded_random.h"
#include "world/scene_file.h"
#include "world/world.h"

namespace bw {
namespace {

struct Shot {
  SpawnerDescription::Shape shape;
  float size;        // box half extent or sphere radius
  double speed;      // m/s along -z
  double timestep;
};

// A static target whose top face is z = 0; the body starts `start` above it, aimed down with a
// seeded sideways tilt. Returns the lowest z the body's centre reached.
double fire(const SceneDescription& target, const Shot& shot, uint64_t seed, double start, int frames) {
  SceneDescription scene = target;
  SeededRandom r(seed);
  scene.settings.timestep = shot.timestep;
  scene.settings.gravity = Vec3d::Zero();
  scene.settings.sleeping = false;
  SpawnerDescription s;
  s.shape = shot.shape;
  s.count = 1;
  s.halfExtents = Vec3f::Constant(shot.size);
  s.radius = shot.size;
  s.density = 500;
  s.seed = seed;
  const Vec3d p(r.uniform(-0.3, 0.3), r.uniform(-0.3, 0.3), start + r.uniform(0, 0.05 * shot.speed * shot.timestep));
  s.regionMin = s.regionMax = p;
  const Vec3d tilt(r.uniform(-0.2, 0.2), r.uniform(-0.2, 0.2), -1.0);
  s.velocity = tilt.normalized() * shot.speed;
  scene.spawners = {s};
  World world(scene, 1);
  const uint32_t body = world.bodies().size() - 1;
  double lowest = world.bodies().position[body].z();
  for (int f = 0; f < frames; ++f) {
    world.step();
    lowest = std::min(lowest, world.bodies().position[body].z());
  }
  return lowest;
}

TEST(ContinuousCollision, HalfMetreBoxAt100MetresPerSecondNeverPassesA02Plate) {
  // One 0.2-thick plate, 20 x 20, top face at z = 0.
  const SceneDescription plate = parseScene(R"({"name": "plate",
      "grids": [{"name": "plate", "bricks": [{"position": [0, 0, -0.1], "half_size": [10, 10, 0.1]}]}]})", "plate.json");
  int runs = 0;
  for (double timestep : {1.0 / 30, 1.0 / 60, 1.0 / 120})
    for (uint64_t seed = 1; seed <= 40; ++seed) {
      const Shot shot{SpawnerDescription::Shape::Box, 0.25f, 100.0, timestep};
      // Starts 1.5 steps of travel above the plate: it reaches the plate mid-step.
      const double lowest = fire(plate, shot, seed, 1.5 * 100.0 * timestep, 30);
      // A box's centre stays at least its half extent above the top face minus the slop, in any
      // orientation that still has it in front of the plate (far above -0.2, the plate's bottom).
      EXPECT_GT(lowest, 0.0) << "seed " << seed << ", dt " << timestep << ": the box's centre went below the plate's top";
      ++runs;
    }
  EXPECT_EQ(runs, 120);
}

TEST(ContinuousCollision, TenCentimetreSphereAt300MetresPerSecondNeverPassesAMicrobrickWall) {
  // A wall of 0.08 micro bricks (half size 0.04), 4 x 4 m, one brick thick; top face at z = 0.
  std::string bricks;
  for (int i = 0; i < 50; ++i)
    for (int j = 0; j < 50; ++j)
      bricks += std::string(bricks.empty() ? "" : ",") + "{\"position\": [" + std::to_string(-1.96 + 0.08 * i) + ", " +
                std::to_string(-1.96 + 0.08 * j) + ", -0.04], \"half_size\": [0.04, 0.04, 0.04]}";
  const SceneDescription wall = parseScene("{\"name\": \"wall\", \"grids\": [{\"name\": \"wall\", \"bricks\": [" + bricks + "]}]}",
                                           "wall.json");
  for (double timestep : {1.0 / 60, 1.0 / 120})
    for (uint64_t seed = 1; seed <= 30; ++seed) {
      const Shot shot{SpawnerDescription::Shape::Sphere, 0.05f, 300.0, timestep};
      const double lowest = fire(wall, shot, seed, 1.5 * 300.0 * timestep, 20);
      EXPECT_GT(lowest, 0.0) << "seed " << seed << ", dt " << timestep << ": the sphere's centre went below the wall's face";
    }
}

}  // namespace
}  // namespace bw
