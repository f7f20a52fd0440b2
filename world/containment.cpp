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

template <class Visit>
void World::visitSolidsReaching(const WorldAabb& box, Visit&& visit) const {
  if (!solidIndexCurrent_) {
    for (uint32_t g : solidBodies_)
      if (mayOverlapSolid(g, box) && visit(g)) return;
    return;
  }
  thread_local std::vector<uint32_t> solids;
  solids.clear();
  solidIndex_.any(box, [&](uint32_t g) {
    solids.push_back(g);
    return false;  // every one
  });
  std::sort(solids.begin(), solids.end());
  for (uint32_t g : solids)
    if (visit(g)) return;
}

InsideSolid World::pointInsideSolid(const Vec3d& p, uint32_t self, bool staticGrids) const {
  thread_local std::vector<uint32_t> candidates;
  InsideSolid found = InsideSolid::No;
  visitSolidsReaching(WorldAabb{p, p}, [&](uint32_t g) {
    const BodyShape& shape = bodies_.shape[g];
    if (g == self) return false;
    if (!staticGrids && shape.isGrid() && bodies_.motion[g] == MotionType::Static) return false;
    if (shape.isGrid()) {
      const BrickGrid& grid = *grids_[shape.grid];
      const Vec3f local = bodies_.shapePose(g).pointToLocal(p);
      candidates.clear();
      grid.overlapBricks(Aabb{local, local}, ~0u, candidates);
      for (uint32_t b : candidates)
        if (brickContains(grid.brick(b), local)) found = InsideSolid::InBrick;
    } else if (shape.isTerrain()) {
      const Terrain& t = *terrains_[shape.terrain];
      const Vec3f v = t.placement().pointToLocal(p) / t.voxelSize();
      const Int3 cell{int(std::floor(v.x())), int(std::floor(v.y())), int(std::floor(v.z()))};
      if (t.voxels().contains(cell) && t.voxels().get(cell).isSolid()) found = InsideSolid::InVoxel;
    }
    return found != InsideSolid::No;
  });
  return found;
}

uint32_t World::soleSolidReaching(const WorldAabb& box, uint32_t self) const {
  uint32_t found = kInvalidIndex, count = 0;
  visitSolidsReaching(box, [&](uint32_t g) {
    if (g == self) return false;
    found = g;
    return ++count > 1;
  });
  return count == 1 ? found : kInvalidIndex;
}

bool World::hasMovingSolid() const {
  return std::any_of(solidBodies_.begin(), solidBodies_.end(), [&](uint32_t g) { return bodies_.motion[g] != MotionType::Static; });
}

void World::indexSolids() {
  constexpr size_t kIndexFrom = 16;  // fewer solids: the loop over them costs less than the index
  // Not before the first step or after poses were set (every solid is a candidate then), nor
  // while a part split off between steps has no bounds yet.
  if (solidIndexCurrent_ || !boundsCurrent_ || solidBodies_.size() < kIndexFrom || bounds_.size() < bodies_.size()) return;
  std::vector<WorldAabb> boxes;
  boxes.reserve(solidBodies_.size());
  for (uint32_t g : solidBodies_) boxes.push_back(bounds_[g]);
  solidIndex_.build(std::move(boxes), solidBodies_);
  solidIndexCurrent_ = true;
}


// The solid body's broadphase bounds of the last substep hold it wherever it is now (they
// cover its motion); before the first step, or after poses were set from outside, every solid
// body is a candidate, and so is a part split off between steps (no bounds until the next).
bool World::mayOverlapSolid(uint32_t solid, const WorldAabb& box) const {
  return !boundsCurrent_ || solid >= bounds_.size() || bounds_[solid].overlaps(box);
}

uint64_t World::staticGridEdits() const {
  uint64_t edits = 0;
  for (uint32_t g : solidBodies_)
    if (bodies_.shape[g].isGrid() && bodies_.motion[g] == MotionType::Static) edits += grids_[bodies_.shape[g].grid]->editCount();
  return edits;
}

bool World::segmentHitsStatic(const Vec3d& from, const Vec3d& to) { return segmentHitsStaticGrid(from, to) || segmentHitsTerrain(from, to); }

bool World::segmentHitsStaticGrid(const Vec3d& from, const Vec3d& to, uint32_t only, uint32_t except) const {
  const double length = (to - from).norm();
  if (!(length > 0)) return false;
  const Vec3d dir = (to - from) / length;
  bool hit = false;
  visitSolidsReaching(WorldAabb{from.cwiseMin(to), from.cwiseMax(to)}, [&](uint32_t g) {
    const BodyShape& shape = bodies_.shape[g];
    if (bodies_.motion[g] == MotionType::Dynamic || !shape.isGrid() || g == except || (only != kInvalidIndex && g != only)) return false;
    const RigidTransform pose = bodies_.shapePose(g);
    const Ray ray = Ray::make(pose.pointToLocal(from), pose.directionToLocal(Vec3f(dir.cast<float>())), float(length));
    hit = grids_[shape.grid]->raycast(ray, ~0u).hit();
    return hit;
  });
  return hit;
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

std::optional<bool> World::segmentHitsBuiltTerrain(const Vec3d& from, const Vec3d& to) const {
  const double length = (to - from).norm();
  if (!(length > 0)) return false;
  const Vec3d dir = (to - from) / length;
  for (uint32_t g : solidBodies_) {
    const BodyShape& shape = bodies_.shape[g];
    if (bodies_.motion[g] == MotionType::Dynamic || !shape.isTerrain()) continue;
    TerrainRayHit hit;
    const std::optional<bool> hits = raycastTerrainCached(*terrains_[shape.terrain], from, dir, length, hit);
    if (!hits || *hits) return hits;
  }
  return false;
}

// A moving solid alone reaching the box: the places of a body there move with it (static
// ones are the world's).
uint32_t ContainmentTracker::frameAt(const WorldAabb& box, uint32_t self) const {
  if (!movingSolids_) return kWorldFrame;
  const uint32_t g = world_.soleSolidReaching(box, self);
  return g != kInvalidIndex && world_.bodies().motion[g] != MotionType::Static ? g : kWorldFrame;
}

// The solid's shape frame, not its body frame: a dynamic grid's body frame is its centre of
// mass and principal axes, which move over its bricks when it is edited.
Vec3d ContainmentTracker::toSolidFrame(uint32_t solid, const Vec3d& p) const {
  const RigidTransform pose = world_.bodies().shapePose(solid);
  return pose.rotation.cast<double>().conjugate() * (p - pose.translation);
}

Vec3d ContainmentTracker::fromSolidFrame(uint32_t solid, const Vec3d& q) const {
  const RigidTransform pose = world_.bodies().shapePose(solid);
  return pose.rotation.cast<double>() * q + pose.translation;
}

// The crossing test against grids from the body's last clear place: in the world, or, kept in
// a moving grid's frame, against that grid from there and against the others from where it
// was last clear of them in the world.
bool ContainmentTracker::crossesGrid(uint32_t body, const Vec3d& p) const {
  const uint32_t f = clearFrame_[body];
  if (f == kWorldFrame) return world_.segmentHitsStaticGrid(lastClear_[body], p);
  return world_.segmentHitsStaticGrid(fromSolidFrame(f, lastClear_[body]), p, f) ||
         world_.segmentHitsStaticGrid(lastClearWorld_[body], p, kInvalidIndex, f);
}

ContainmentTracker::ContainmentTracker(World& world) : world_(world) {
  world.indexSolids();
  movingSolids_ = world.hasMovingSolid();
  const BodyStore& bodies = world.bodies();
  const uint32_t n = bodies.size();
  seenFrame_.assign(n, kWorldFrame);
  lastSeen_.assign(bodies.position.begin(), bodies.position.end());
  lastWorld_ = lastClearWorld_ = lastSeen_;
  for (uint32_t i = 0; i < n; ++i)
    if (bodies.motion[i] == MotionType::Dynamic) {
      seenFrame_[i] = frameAt(WorldAabb{bodies.position[i], bodies.position[i]}, i);
      lastSeen_[i] = toFrame(seenFrame_[i], bodies.position[i]);
    }
  staticEdits_ = world.staticGridEdits();
  lastClear_ = lastSeen_;
  clearFrame_ = seenFrame_;
  state_.assign(n, InsideSolid::No);
  for (uint32_t i = 0; i < n; ++i)
    if (bodies.motion[i] == MotionType::Dynamic) state_[i] = world.pointInsideSolid(bodies.position[i], i);
  // A body first seen inside solid (or kinematic, being pushed out of it) has no clear place
  // yet: the first place it is seen clear becomes one.
  hasClear_.assign(n, 0);
  for (uint32_t i = 0; i < n; ++i) hasClear_[i] = bodies.motion[i] == MotionType::Dynamic && state_[i] == InsideSolid::No;
  report_ = {};
  for (uint32_t i = 0; i < n; ++i)
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
    lastWorld_.push_back(bodies.position[i]);
    lastClearWorld_.push_back(bodies.position[i]);
    seenFrame_.push_back(kWorldFrame);
    clearFrame_.push_back(kWorldFrame);
    state_.push_back(bodies.motion[i] == MotionType::Dynamic ? world_.pointInsideSolid(bodies.position[i], i) : InsideSolid::No);
    hasClear_.push_back(bodies.motion[i] == MotionType::Dynamic && state_.back() == InsideSolid::No);
  }
  // Pass 1, in parallel: the point test and the crossing tests against grids and built terrain
  // chunks (all only read) for every body that needs a check; a crossing test that needs a
  // terrain chunk not built yet (building fills the chunk cache) is left for pass 2.
  world_.indexSolids();
  movingSolids_ = world_.hasMovingSolid();
  checked_.assign(n, Check::None);
  checkFrame_.resize(n);
  checkPlace_.resize(n);
  const uint64_t edits = world_.staticGridEdits();
  const bool staticEdited = edits != staticEdits_;
  staticEdits_ = edits;
  constexpr double kRecheck2 = kRecheckDistance * kRecheckDistance;
  JobSystem& jobs = world_.jobs();
  jobs.parallelFor(0, n, tuning::bodyGrain(n), [&](uint32_t begin, uint32_t end) {
    for (uint32_t i = begin; i < end; ++i) {
      if (bodies.motion[i] != MotionType::Dynamic) continue;
      const Vec3d& p = bodies.position[i];
      const Vec3d previous = lastWorld_[i];  // where the last update saw it (each body its own slot)
      lastWorld_[i] = p;
      if (seenFrame_[i] == kWorldFrame && p == lastSeen_[i]) continue;
      const bool clear = state_[i] == InsideSolid::No;
      if (clear && !world_.nearSolidLastStep(i)) {
        checked_[i] = Check::FarFromSolid;
        checkFrame_[i] = kWorldFrame;
        checkPlace_[i] = p;
        continue;
      }
      // At rest (in the frame it was last seen in): checked again once it has moved further
      // (from lastClear_ then). A body riding a moving grid rests only while its way here
      // since the last update reached no other solid (a static plate it was carried through);
      // then it is clear of every other solid where it is now.
      if (clear && hasClear_[i]) {
        const uint32_t f = seenFrame_[i];
        if (f == kWorldFrame && (p - lastSeen_[i]).squaredNorm() < kRecheck2) continue;
        if (f != kWorldFrame && (toFrame(f, p) - lastSeen_[i]).squaredNorm() < kRecheck2 &&
            frameAt(WorldAabb{previous.cwiseMin(p), previous.cwiseMax(p)}, i) == f) {
          lastClearWorld_[i] = p;
          continue;
        }
      }
      const uint32_t frame = frameAt(WorldAabb{p, p}, i);
      checkFrame_[i] = frame;
      checkPlace_[i] = toFrame(frame, p);
      // A centre inside a static grid's brick got there through the brick's surface, unless the
      // brick appeared around it (an edit): while static grids are unedited, the crossing test
      // from the last clear place answers for them, and the point test looks at the rest. A
      // last clear place kept in a moving grid's frame is tested against that grid there, and
      // against the others from where it was last clear of them in the world.
      const bool viaCrossing = hasClear_[i] && !staticEdited;
      InsideSolid s = world_.pointInsideSolid(p, i, !viaCrossing);
      if (s == InsideSolid::No && hasClear_[i] && crossesGrid(i, p))
        s = viaCrossing && world_.pointInsideSolid(p, i) == InsideSolid::InBrick ? InsideSolid::InBrick : InsideSolid::WentThrough;
      // The crossing test against terrain too, when the chunks it needs are built (it only
      // reads them then); else pass 2 asks it, building them.
      bool terrainAsked = false;
      if (s == InsideSolid::No && hasClear_[i]) {
        const std::optional<bool> crossed = world_.segmentHitsBuiltTerrain(lastClearWorld_[i], p);
        terrainAsked = crossed.has_value();
        if (crossed.value_or(false)) s = InsideSolid::WentThrough;
      }
      checked_[i] = s == InsideSolid::InBrick       ? Check::InBrick
                    : s == InsideSolid::InVoxel     ? Check::InVoxel
                    : s == InsideSolid::WentThrough ? Check::WentThrough
                    : terrainAsked                  ? Check::Clear
                                                    : Check::ClearOfGrids;
    }
  });
  // Pass 2, in body order: terrain crossings, then every checked body's state.
  report_.bodies.clear();
  report_.reasons.clear();
  queried_ = 0;
  for (uint32_t i = 0; i < n; ++i) {
    const Vec3d& p = bodies.position[i];
    switch (checked_[i]) {
      case Check::None: break;
      case Check::FarFromSolid:
        // Clear before, and nowhere near a grid or terrain on its whole way here: clear now.
        lastSeen_[i] = lastClear_[i] = lastClearWorld_[i] = p;
        seenFrame_[i] = clearFrame_[i] = kWorldFrame;
        hasClear_[i] = 1;
        break;
      default: {
        ++queried_;
        InsideSolid s = checked_[i] == Check::InBrick ? InsideSolid::InBrick
                        : checked_[i] == Check::InVoxel ? InsideSolid::InVoxel
                        : checked_[i] == Check::WentThrough ? InsideSolid::WentThrough
                                                              : InsideSolid::No;
        if (checked_[i] == Check::ClearOfGrids && hasClear_[i] && world_.segmentHitsTerrain(lastClearWorld_[i], p))
          s = InsideSolid::WentThrough;
        if (s == InsideSolid::No) {
          lastClear_[i] = checkPlace_[i];
          clearFrame_[i] = checkFrame_[i];
          lastClearWorld_[i] = p;
          hasClear_[i] = 1;
        }
        lastSeen_[i] = checkPlace_[i];
        seenFrame_[i] = checkFrame_[i];
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
