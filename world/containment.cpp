#include "world/containment.h"

#include <algorithm>
#include <cmath>

#include "collision/bricks/brick_geometry.h"
#include "collision/terrain/terrain_queries.h"
#include "world/world.h"

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

InsideSolid World::pointInsideSolid(const Vec3d& p, uint32_t self) const {
  thread_local std::vector<uint32_t> candidates;
  for (uint32_t g : solidBodies_) {
    const BodyShape& shape = bodies_.shape[g];
    if (g == self) continue;
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

bool World::segmentHitsStatic(const Vec3d& from, const Vec3d& to) {
  const double length = (to - from).norm();
  if (!(length > 0)) return false;
  const Vec3d dir = (to - from) / length;
  for (uint32_t g : solidBodies_) {
    const BodyShape& shape = bodies_.shape[g];
    if (bodies_.motion[g] == MotionType::Dynamic) continue;
    if (shape.isGrid()) {
      const RigidTransform pose = bodies_.shapePose(g);
      const Ray ray = Ray::make(pose.pointToLocal(from), pose.directionToLocal(Vec3f(dir.cast<float>())), float(length));
      if (grids_[shape.grid]->raycast(ray, ~0u).hit()) return true;
    } else if (shape.isTerrain()) {
      TerrainRayHit hit;
      if (raycastTerrain(*terrains_[shape.terrain], from, dir, length, hit)) return true;
    }
  }
  return false;
}

ContainmentTracker::ContainmentTracker(World& world) : world_(world) {
  const BodyStore& bodies = world.bodies();
  lastSeen_.assign(bodies.position.begin(), bodies.position.end());
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
  report_.bodies.clear();
  report_.reasons.clear();
  for (uint32_t i = 0; i < bodies.size(); ++i) {
    if (bodies.motion[i] != MotionType::Dynamic) continue;
    const Vec3d& p = bodies.position[i];
    if (p != lastSeen_[i] && state_[i] == InsideSolid::No && !world_.nearSolidLastStep(i)) {
      // Clear before, and nowhere near a grid or terrain on its whole way here: clear now.
      lastSeen_[i] = lastClear_[i] = p;
      hasClear_[i] = 1;
    } else if (p != lastSeen_[i] && state_[i] == InsideSolid::No && hasClear_[i] &&
               (p - lastSeen_[i]).squaredNorm() < kRecheckDistance * kRecheckDistance) {
      // Clear, and within kRecheckDistance of where it was last checked (a resting body): the
      // next check, once it has moved further, tests the whole way from lastClear_.
    } else if (p != lastSeen_[i]) {
      lastSeen_[i] = p;
      InsideSolid s = world_.pointInsideSolid(p, i);
      if (s == InsideSolid::No && hasClear_[i] && world_.segmentHitsStatic(lastClear_[i], p)) s = InsideSolid::WentThrough;
      if (s == InsideSolid::No) {
        lastClear_[i] = p;
        hasClear_[i] = 1;
      }
      state_[i] = s;
    }
    if (state_[i] != InsideSolid::No) {
      report_.bodies.push_back(i);
      report_.reasons.push_back(state_[i]);
    }
  }
  return report_;
}

}  // namespace bw
