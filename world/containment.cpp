#include "world/containment.h"

#include <algorithm>
#include <cmath>

#include "collision/bricks/brick_geometry.h"
#include "collision/terrain/terrain_queries.h"
#include "world/world.h"
#include "world/world_tuning.h"

namespace bw {

const char* insideSolidName(InsideSolid reason) {
  switch (reason) {
    case InsideSolid::No: return "no";
    case InsideSolid::InBrick: return "inside a brick";
    case InsideSolid::InVoxel: return "inside a solid voxel";
    case InsideSolid::WentThrough: return "went through a surface";
  }
  return "?";
}

InsideSolid World::pointInsideSolid(const Vec3d& p, uint32_t self, bool staticGrids) const {
  thread_local std::vector<uint32_t> candidates;
  for (uint32_t g : solidBodies_) {
    const BodyShape& shape = bodies_.shape[g];
    if (g == self || !mayOverlapSolid(g, WorldAabb{p, p})) continue;
    if (!staticGrids && shape.isGrid() && bodies_.motion[g] == MotionType::Static) continue;
    if (shape.isGrid()) {
      const BrickGrid& grid = *grids_[shape.grid];
      const Vec3f local = bodies_.shapePose(g).pointToLocal(p);
      candidates.clear();
      grid.overlapBricks(Aabb{local, local}, ~0u, candidates);
      for (uint32_t b : candidates)
        if (brickContains(grid.brick(b), local)) return InsideSolid::InBrick;
    } else if (shape.isTerrain()) {
      const Terrain& t = *terrains_[shape.terrain];
      const Vec3f v = t.placement().pointToLocal(p) / t.voxelSize();
      const Int3 cell{int(std::floor(v.x())), int(std::floor(v.y())), int(std::floor(v.z()))};
      if (t.voxels().contains(cell) && t.voxels().get(cell).isSolid()) return InsideSolid::InVoxel;
    }
  }
  return InsideSolid::No;
}

// The solid body's broadphase bounds of the last substep hold it wherever it is now (they
// cover its motion); before the first step, or after poses were set from outside, every solid
// body is a candidate.
bool World::mayOverlapSolid(uint32_t solid, const WorldAabb& box) const {
  return !boundsCurrent_ || bounds_[solid].overlaps(box);
}

uint64_t World::staticGridEdits() const {
  uint64_t edits = 0;
  for (uint32_t g : solidBodies_)
    if (bodies_.shape[g].isGrid() && bodies_.motion[g] == MotionType::Static) edits += grids_[bodies_.shape[g].grid]->editCount();
  return edits;
}

bool World::segmentHitsStatic(const Vec3d& from, const Vec3d& to) { return segmentHitsStaticGrid(from, to) || segmentHitsTerrain(from, to); }

bool World::segmentHitsStaticGrid(const Vec3d& from, const Vec3d& to) const {
  const double length = (to - from).norm();
  if (!(length > 0)) return false;
  const Vec3d dir = (to - from) / length;
  for (uint32_t g : solidBodies_) {
    const BodyShape& shape = bodies_.shape[g];
    if (bodies_.motion[g] == MotionType::Dynamic || !shape.isGrid()) continue;
    if (!mayOverlapSolid(g, WorldAabb{from.cwiseMin(to), from.cwiseMax(to)})) continue;
    const RigidTransform pose = bodies_.shapePose(g);
    const Ray ray = Ray::make(pose.pointToLocal(from), pose.directionToLocal(Vec3f(dir.cast<float>())), float(length));
    if (grids_[shape.grid]->raycast(ray, ~0u).hit()) return true;
  }
  return false;
}

bool World::segmentHitsTerrain(const Vec3d& from, const Vec3d& to) {
  const double length = (to - from).norm();
  if (!(length > 0)) return false;
  const Vec3d dir = (to - from) / length;
  for (uint32_t g : solidBodies_) {
    const BodyShape& shape = bodies_.shape[g];
    if (bodies_.motion[g] == MotionType::Dynamic || !shape.isTerrain()) continue;
    TerrainRayHit hit;
    if (raycastTerrain(*terrains_[shape.terrain], from, dir, length, hit)) return true;
  }
  return false;
}

ContainmentTracker::ContainmentTracker(World& world) : world_(world) {
  const BodyStore& bodies = world.bodies();
  lastSeen_.assign(bodies.position.begin(), bodies.position.end());
  staticEdits_ = world.staticGridEdits();
  lastClear_ = lastSeen_;
  state_.assign(bodies.size(), InsideSolid::No);
  for (uint32_t i = 0; i < bodies.size(); ++i)
    if (bodies.motion[i] == MotionType::Dynamic) state_[i] = world.pointInsideSolid(bodies.position[i], i);
  // A body first seen inside solid (or kinematic, being pushed out of it) has no clear place
  // yet: the first place it is seen clear becomes one.
  hasClear_.assign(bodies.size(), 0);
  for (uint32_t i = 0; i < bodies.size(); ++i) hasClear_[i] = bodies.motion[i] == MotionType::Dynamic && state_[i] == InsideSolid::No;
  report_ = {};
  for (uint32_t i = 0; i < bodies.size(); ++i)
    if (state_[i] != InsideSolid::No) {
      report_.bodies.push_back(i);
      report_.reasons.push_back(state_[i]);
    }
}

const ContainmentReport& ContainmentTracker::update() {
  const BodyStore& bodies = world_.bodies();
  const uint32_t n = bodies.size();
  // Bodies added since (parts split off grids): seen where they are, clear if outside solid.
  for (uint32_t i = uint32_t(lastSeen_.size()); i < n; ++i) {
    lastSeen_.push_back(bodies.position[i]);
    lastClear_.push_back(bodies.position[i]);
    state_.push_back(bodies.motion[i] == MotionType::Dynamic ? world_.pointInsideSolid(bodies.position[i], i) : InsideSolid::No);
    hasClear_.push_back(bodies.motion[i] == MotionType::Dynamic && state_.back() == InsideSolid::No);
  }
  // Pass 1, in parallel: the point test and the crossing test against grids (both only read)
  // for every body that needs a check; a crossing test against terrain (which fills chunk
  // caches) is left for pass 2.
  checked_.assign(n, Check::None);
  const uint64_t edits = world_.staticGridEdits();
  const bool staticEdited = edits != staticEdits_;
  staticEdits_ = edits;
  JobSystem& jobs = world_.jobs();
  jobs.parallelFor(0, n, tuning::bodyGrain(n), [&](uint32_t begin, uint32_t end) {
    for (uint32_t i = begin; i < end; ++i) {
      if (bodies.motion[i] != MotionType::Dynamic) continue;
      const Vec3d& p = bodies.position[i];
      if (p == lastSeen_[i]) continue;
      if (state_[i] == InsideSolid::No && !world_.nearSolidLastStep(i)) {
        checked_[i] = Check::FarFromSolid;
        continue;
      }
      if (state_[i] == InsideSolid::No && hasClear_[i] && (p - lastSeen_[i]).squaredNorm() < kRecheckDistance * kRecheckDistance)
        continue;  // at rest: checked again once it has moved further (from lastClear_ then)
      // A centre inside a static grid's brick got there through the brick's surface, unless the
      // brick appeared around it (an edit): while static grids are unedited, the crossing test
      // from the last clear place answers for them, and the point test looks at the rest.
      const bool viaCrossing = hasClear_[i] && !staticEdited;
      InsideSolid s = world_.pointInsideSolid(p, i, !viaCrossing);
      if (s == InsideSolid::No && hasClear_[i] && world_.segmentHitsStaticGrid(lastClear_[i], p))
        s = viaCrossing && world_.pointInsideSolid(p, i) == InsideSolid::InBrick ? InsideSolid::InBrick : InsideSolid::WentThrough;
      checked_[i] = s == InsideSolid::InBrick   ? Check::InBrick
                    : s == InsideSolid::InVoxel ? Check::InVoxel
                    : s == InsideSolid::WentThrough ? Check::WentThrough
                                                    : Check::ClearOfGrids;
    }
  });
  // Pass 2, in body order: terrain crossings, then every checked body's state.
  report_.bodies.clear();
  report_.reasons.clear();
  for (uint32_t i = 0; i < n; ++i) {
    const Vec3d& p = bodies.position[i];
    switch (checked_[i]) {
      case Check::None: break;
      case Check::FarFromSolid:
        // Clear before, and nowhere near a grid or terrain on its whole way here: clear now.
        lastSeen_[i] = lastClear_[i] = p;
        hasClear_[i] = 1;
        break;
      default: {
        InsideSolid s = checked_[i] == Check::InBrick ? InsideSolid::InBrick
                        : checked_[i] == Check::InVoxel ? InsideSolid::InVoxel
                        : checked_[i] == Check::WentThrough ? InsideSolid::WentThrough
                                                              : InsideSolid::No;
        if (s == InsideSolid::No && hasClear_[i] && world_.segmentHitsTerrain(lastClear_[i], p)) s = InsideSolid::WentThrough;
        if (s == InsideSolid::No) {
          lastClear_[i] = p;
          hasClear_[i] = 1;
        }
        lastSeen_[i] = p;
        state_[i] = s;
      }
    }
    if (bodies.motion[i] == MotionType::Dynamic && state_[i] != InsideSolid::No) {
      report_.bodies.push_back(i);
      report_.reasons.push_back(state_[i]);
    }
  }
  return report_;
}

}  // namespace bw
