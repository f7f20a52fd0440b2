// The broadphase over proxies: every body enters the sweep as its bounds, except a large static
// grid, which enters as the boxes covering its bricks a few OctoBVH levels down (at most
// tuning::kCoverBoxes). A body falling
// onto a city is then paired with it only near a building or a street, not for its whole fall
// through the city's bounding box (each such pair cost a grid query that met nothing). Pairs
// found through several of a grid's boxes are one pair (the broadphase reports pairs of the
// proxies' owners); the pairs come out sorted as before.
// A body the boxes miss has no brick within its bounds, so it would have had no contacts: the
// contacts, and so the state, are the same as with one box per grid.
#include <algorithm>
#include <optional>

#include "world/world.h"
#include "world/world_tuning.h"

namespace bw {

void World::findPairs() {
  std::optional<ProfileZone> proxies(std::in_place, profiler_, "broadphase: proxies", stage_ + 0);
  const uint32_t n = bodies_.size();
  proxyBounds_.clear();
  proxyStatic_.clear();
  proxyBody_.clear();
  for (uint32_t i = 0; i < n; ++i) {
    if (bodies_.shape[i].isGrid() && grids_[bodies_.shape[i].grid]->brickCount() == 0) continue;  // edited away: meets nothing
    const bool covered = isStatic_[i] && bodies_.shape[i].isGrid() && grids_[bodies_.shape[i].grid]->brickCount() >= tuning::kCoverMinBricks;
    if (!covered) {
      proxyBounds_.push_back(bounds_[i]);
      proxyStatic_.push_back(isStatic_[i]);
      proxyBody_.push_back(i);
      continue;
    }
    auto it = std::find_if(covers_.begin(), covers_.end(), [&](const GridCover& c) { return c.body == i; });
    if (it == covers_.end()) it = covers_.insert(covers_.end(), GridCover{i, ~0ull, {}});
    const BrickGrid& grid = *grids_[bodies_.shape[i].grid];
    if (it->edit != grid.editCount()) {
      // Taken again after an edit (static grids do not move: their world boxes stay).
      grid.coverBoxes(tuning::kCoverBoxes, coverScratch_);
      const RigidTransform pose = bodies_.shapePose(i);
      const Mat3f R = pose.rotation.toRotationMatrix().cwiseAbs();
      it->boxes.clear();
      for (const Aabb& b : coverScratch_) {
        const Vec3d centre = pose.pointToWorld(b.center());
        const Vec3d half = (R * b.halfExtent()).cast<double>() + Vec3d::Constant(tuning::kBroadphaseMargin);
        it->boxes.push_back({centre - half, centre + half});
      }
      it->edit = grid.editCount();
    }
    for (const WorldAabb& b : it->boxes) {
      proxyBounds_.push_back(b);
      proxyStatic_.push_back(1);
      proxyBody_.push_back(i);
    }
  }
  proxies.reset();
  // Proxies of one grid pair with a body once: the broadphase's pairs are of owners.
  broadphase_.update(proxyBounds_, proxyStatic_, pairs_, &jobs_, &profiler_, stage_ + kBroadphaseStage, &proxyBody_);
}

}  // namespace bw
