#pragma once
/// The scene's ray load (`rays` in a scene file): per frame, seeded rays between random points
/// of the static and kinematic grids' bounds, each cast against every such grid (in the grid's
/// frame) keeping the closest hit. One slot per ray, so the result does not depend on the
/// thread count. Rays read the world; they change nothing.
#include <cstdint>
#include <memory>
#include <vector>

#include "collision/bricks/brick_grid.h"
#include "jobs/job_system.h"
#include "jobs/profiler.h"
#include "world/body_store.h"
#include "world/broadphase.h"
#include "world/scene_description.h"

namespace bw {

/// One ray of the load, in world space.
struct LoadRay {
  Vec3d from = Vec3d::Zero();
  Vec3d direction = Vec3d::Zero();  ///< unit; zero for a ray whose two points coincided (not cast)
  double length = 0;                ///< how far it looks (m)
};

/// Figures of one frame's ray load.
struct RayLoadStats {
  uint32_t rays = 0, hits = 0;
  uint64_t boxTests = 0;
};

class RayLoad {
 public:
  /// Casts frame `frame`'s rays. bounds[i] is body i's broadphase box (the rays span the grids'
  /// boxes); `stage` is the profiling stage id.
  RayLoadStats fire(const RayLoadDescription& load, uint32_t frame, const BodyStore& bodies,
                    const std::vector<std::unique_ptr<BrickGrid>>& grids, const std::vector<WorldAabb>& bounds,
                    JobSystem& jobs, Profiler& profiler, int stage);
  /// Ray k of frame `frame`: between two seeded random points of the box [lo, hi] (the union of
  /// the static and kinematic grids' broadphase boxes), looking load.length, or across the box
  /// when that is 0. The same for every engine given the same box (the Bullet baseline fires
  /// these too).
  static LoadRay makeRay(const RayLoadDescription& load, uint32_t frame, uint32_t k, const Vec3d& lo, const Vec3d& hi);
  /// The last frame's rays and each one's closest hit distance along it (infinity: no hit).
  const std::vector<LoadRay>& rays() const { return rays_; }
  const std::vector<float>& hitDistances() const { return hitT_; }

 private:
  std::vector<LoadRay> rays_;
  std::vector<float> hitT_;
  std::vector<QueryStats> stats_;
  std::vector<uint32_t> gridBodies_;
};

}  // namespace bw
