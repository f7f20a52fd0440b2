#include "world/ray_load.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "collision/core/hash.h"
#include "collision/core/seeded_random.h"
#include "world/world_tuning.h"

namespace bw {

LoadRay RayLoad::makeRay(const RayLoadDescription& load, uint32_t frame, uint32_t k, const Vec3d& lo, const Vec3d& hi) {
  SeededRandom r((load.seed ^ (uint64_t(frame) * kGoldenGamma)) + k);
  // note: one draw per statement, so the rays do not depend on the compiler's argument order.
  Vec3d from, to;
  for (int a = 0; a < 3; ++a) from[a] = r.uniform(lo[a], hi[a]);
  for (int a = 0; a < 3; ++a) to[a] = r.uniform(lo[a], hi[a]);
  LoadRay ray;
  ray.from = from;
  const double span = (to - from).norm();
  if (span == 0) return ray;  // not cast
  ray.direction = (to - from) / span;
  ray.length = load.length > 0 ? double(load.length) : (hi - lo).norm();
  return ray;
}

RayLoadStats RayLoad::fire(const RayLoadDescription& load, uint32_t frame, const BodyStore& bodies,
                           const std::vector<std::unique_ptr<BrickGrid>>& grids, const std::vector<WorldAabb>& bounds,
                           JobSystem& jobs, Profiler& profiler, int stage) {
  RayLoadStats stats;
  rays_.clear();
  hitT_.clear();
  if (load.count == 0) return stats;
  Vec3d lo = Vec3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  gridBodies_.clear();
  for (uint32_t i = 0; i < bodies.size(); ++i) {
    if (!bodies.shape[i].isGrid() || bodies.motion[i] == MotionType::Dynamic) continue;
    gridBodies_.push_back(i);
    lo = lo.cwiseMin(bounds[i].min);
    hi = hi.cwiseMax(bounds[i].max);
  }
  if (gridBodies_.empty()) return stats;
  rays_.assign(load.count, LoadRay{});
  hitT_.assign(load.count, std::numeric_limits<float>::infinity());
  stats_.assign(load.count, QueryStats{});
  jobs.parallelFor(0, load.count, tuning::kRayGrain, [&](uint32_t begin, uint32_t end) {
    ProfileZone zone(profiler, "rays", stage);
    for (uint32_t k = begin; k < end; ++k) {
      rays_[k] = makeRay(load, frame, k, lo, hi);
      if (rays_[k].length == 0) continue;
      const Vec3d& from = rays_[k].from;
      const Vec3d& dir = rays_[k].direction;
      const double length = rays_[k].length;
      for (uint32_t body : gridBodies_) {
        const RigidTransform pose = bodies.shapePose(body);
        const Ray ray = Ray::make(pose.pointToLocal(from), pose.directionToLocal(Vec3f(dir.cast<float>())),
                                  std::min(float(length), hitT_[k]));
        const GridRayHit hit = grids[bodies.shape[body].grid]->raycast(ray, ~0u, &stats_[k]);
        if (hit.hit()) hitT_[k] = hit.t;
      }
    }
  });
  stats.rays = load.count;
  for (uint32_t k = 0; k < load.count; ++k) {
    stats.hits += std::isfinite(hitT_[k]) ? 1u : 0u;
    stats.boxTests += stats_[k].boxTests;
  }
  return stats;
}

}  // namespace bw
