// The scene's ray load against brute force: every ray's closest hit equals the nearest exact
// ray/brick intersection over every brick of every static and kinematic grid.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "collision/bricks/brick_geometry.h"
#include "world/world.h"

namespace bw {
namespace {

// Closest hit of a world ray over every brick of every non-dynamic grid body, one brick at a
// time, with the world's own conversion to grid-local floats.
float bruteForceHit(const World& world, const LoadRay& r) {
  float best = std::numeric_limits<float>::infinity();
  const BodyStore& bodies = world.bodies();
  for (uint32_t i = 0; i < bodies.size(); ++i) {
    if (!bodies.shape[i].isGrid() || bodies.motion[i] == MotionType::Dynamic) continue;
    const RigidTransform pose = bodies.shapePose(i);
    const Ray ray = Ray::make(pose.pointToLocal(r.from), pose.directionToLocal(Vec3f(r.direction.cast<float>())), float(r.length));
    world.grid(bodies.shape[i].grid).forEachBrick([&](uint32_t id) {
      float t;
      Vec3f n;
      if (rayBrick(world.grid(bodies.shape[i].grid).brick(id), ray, std::min(best, float(r.length)), t, n)) best = std::min(best, t);
    });
  }
  return best;
}

TEST(RayLoad, ClosestHitsEqualBruteForceOverEveryBrick) {
  SceneDescription scene;
  scene.name = "ray_load_test";
  GridDescription house;
  house.name = "house";
  house.generator = "house";
  house.seed = 3;
  scene.grids.push_back(house);
  // A second grid, turned and spinning (kinematic), overlapping the house's bounds.
  GridDescription truck;
  truck.name = "truck";
  truck.generator = "truck";
  truck.seed = 5;
  truck.position = Vec3d(4, 3, 1);
  truck.rotation = Quatf(Eigen::AngleAxisf(0.7f, Vec3f(0.2f, 0.3f, 1.f).normalized()));
  truck.motion = MotionType::Kinematic;
  truck.kinematic.angularVelocity = Vec3f(0, 0, 0.5f);
  scene.grids.push_back(truck);
  scene.rays.count = 400;
  scene.rays.seed = 11;
  World world(scene, 2);
  uint32_t hits = 0, misses = 0;
  for (int frame = 0; frame < 3; ++frame) {
    world.step();
    const RayLoad& load = world.rayLoad();
    ASSERT_EQ(load.rays().size(), scene.rays.count);
    for (size_t k = 0; k < load.rays().size(); ++k) {
      const LoadRay& r = load.rays()[k];
      if (r.direction.isZero()) continue;
      const float expected = bruteForceHit(world, r);
      const float got = load.hitDistances()[k];
      if (std::isinf(expected)) {
        EXPECT_TRUE(std::isinf(got)) << "frame " << frame << " ray " << k << ": a hit where no brick is";
        ++misses;
      } else {
        EXPECT_EQ(got, expected) << "frame " << frame << " ray " << k;
        ++hits;
      }
    }
    EXPECT_EQ(world.lastStats().rayHits, [&] {
      uint32_t n = 0;
      for (float t : load.hitDistances()) n += std::isfinite(t) ? 1u : 0u;
      return n;
    }());
  }
  // Rays between random points of the grids' bounds both hit and miss: both sides are checked.
  EXPECT_GT(hits, 100u);
  EXPECT_GT(misses, 10u);
}

}  // namespace
}  // namespace bw
