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

// A large static grid's cover boxes, taken again after an edit (static grids do not move: their
// world boxes stay).
const std::vector<WorldAabb>& World::coverOf(uint32_t body) {
  auto it = std::find_if(covers_.begin(), covers_.end(), [&](const GridCover& c) { return c.body == body; });
  if (it == covers_.end()) it = covers_.insert(covers_.end(), GridCover{body, ~0ull, {}});
  const BrickGrid& grid = *grids_[bodies_.shape[body].grid];
  if (it->edit != grid.editCount()) {
    grid.coverBoxes(tuning::kCoverBoxes, coverScratch_);
    const RigidTransform pose = bodies_.shapePose(body);
    const Mat3f R = pose.rotation.toRotationMatrix().cwiseAbs();
    it->boxes.clear();
    for (const Aabb& b : coverScratch_) {
      const Vec3d centre = pose.pointToWorld(b.center());
      const Vec3d half = (R * b.halfExtent()).cast<double>() + Vec3d::Constant(tuning::kBroadphaseMargin);
      it->boxes.push_back({centre - half, centre + half});
    }
    it->edit = grid.editCount();
  }
  return it->boxes;
}

void World::findPairs() {
  // Per body: no proxy (a grid edited away meets nothing), its bounds, or a large static grid's
  // cover boxes. Counted in parallel chunks (covered grids listed per chunk, their boxes taken
  // on this thread), then written at each chunk's offset in parallel: the proxies in body order.
  const uint32_t n = bodies_.size();
  const auto kind = [&](uint32_t i) {  // 0: none, 1: its bounds, 2: cover boxes
    if (!bodies_.shape[i].isGrid()) return 1;
    const uint32_t bricks = grids_[bodies_.shape[i].grid]->brickCount();
    return bricks == 0 ? 0 : isStatic_[i] && bricks >= tuning::kCoverMinBricks ? 2 : 1;
  };
  const uint32_t grain = tuning::bodyGrain(n);
  const uint32_t chunks = JobSystem::chunkCount(0, n, grain);
  proxyChunks_.resize(chunks);
  jobs_.parallelFor(0, n, grain, [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler_, "broadphase: proxies", stage_ + 0);
    ProxyChunk& c = proxyChunks_[begin / grain];
    c.singles = 0;
    c.covered.clear();
    for (uint32_t i = begin; i < end; ++i) {
      const int k = kind(i);
      if (k == 1) ++c.singles;
      if (k == 2) c.covered.push_back(i);
    }
  });
  {
    ProfileZone z(profiler_, "broadphase: proxy offsets", stage_ + 13);
    uint32_t at = 0;
    for (ProxyChunk& c : proxyChunks_) {
      c.offset = at;
      at += c.singles;
      for (const uint32_t body : c.covered) at += uint32_t(coverOf(body).size());
    }
    proxyBounds_.resize(at);
    proxyStatic_.resize(at);
    proxyBody_.resize(at);
  }
  jobs_.parallelFor(0, n, grain, [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler_, "broadphase: proxies", stage_ + 14);
    uint32_t at = proxyChunks_[begin / grain].offset;
    for (uint32_t i = begin; i < end; ++i) {
      const int k = kind(i);
      if (k == 0) continue;
      if (k == 1) {
        proxyBounds_[at] = bounds_[i];
        proxyStatic_[at] = isStatic_[i];
        proxyBody_[at++] = i;
        continue;
      }
      // note: coverOf() found this grid's boxes current in the serial pass: only read here.
      const auto it = std::find_if(covers_.begin(), covers_.end(), [&](const GridCover& c) { return c.body == i; });
      for (const WorldAabb& b : it->boxes) {
        proxyBounds_[at] = b;
        proxyStatic_[at] = 1;
        proxyBody_[at++] = i;
      }
    }
  });
  // Proxies of one grid pair with a body once: the broadphase's pairs are of owners.
  broadphase_.update(proxyBounds_, proxyStatic_, pairs_, &jobs_, &profiler_, stage_ + kBroadphaseStage, &proxyBody_);
}

}  // namespace bw
