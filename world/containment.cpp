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

uint64_t World::terrainChanges() const {
  uint64_t changes = 0;
  for (const std::unique_ptr<Terrain>& t : terrains_) changes += t->changeCount();
  return changes;
}

double World::staticSolidClearance(const Vec3d& p, double reach) const {
  thread_local std::vector<uint32_t> candidates;
  double clearance = reach;
  // note: local coordinates are rounded to float, and so are the bricks' bounds near them:
  // 16 ulps of the largest coordinate there (in `unit`s of the local frame) come off.
  const auto slackAt = [&](const Vec3f& local, double unit) { return (double(local.cwiseAbs().maxCoeff()) * unit + reach) * 0x1p-20 + 1e-9; };
  visitSolidsReaching(WorldAabb{p - Vec3d::Constant(reach), p + Vec3d::Constant(reach)}, [&](uint32_t g) {
    const BodyShape& shape = bodies_.shape[g];
    if (bodies_.motion[g] != MotionType::Static) return false;
    if (shape.isGrid()) {
      const BrickGrid& grid = *grids_[shape.grid];
      const Vec3f local = bodies_.shapePose(g).pointToLocal(p);
      const double slack = slackAt(local, 1.0);
      clearance = std::min(clearance, reach - slack);
      if (clearance <= 0) return true;
      const float r = float(clearance);
      candidates.clear();
      grid.overlapBricks(Aabb{local - Vec3f::Constant(r), local + Vec3f::Constant(r)}, ~0u, candidates);
      // A brick outside that box is farther than r along some axis; inside it, its shape lies
      // in its bounds, so the distance to the bounds is a lower bound on the distance to it.
      for (uint32_t b : candidates) {
        const Aabb bounds = brickBounds(grid.brick(b));
        const Vec3f gap = (bounds.min - local).cwiseMax(local - bounds.max).cwiseMax(0.f);
        clearance = std::min(clearance, double(gap.norm()) - slack);
      }
    } else if (shape.isTerrain()) {
      const Terrain& t = *terrains_[shape.terrain];
      const double size = double(t.voxelSize());
      const Vec3f v = t.placement().pointToLocal(p) / t.voxelSize();  // in voxels
      const double slack = slackAt(v, size);
      clearance = std::min(clearance, std::min(reach, 2.0 * size) - slack);
      if (clearance <= 0) return true;
      // Every cell the ball's box reaches; a solid one's distance is to its closed cube.
      const float r = float(clearance / size);
      const Int3 lo{int(std::floor(v.x() - r)), int(std::floor(v.y() - r)), int(std::floor(v.z() - r))};
      const Int3 hi{int(std::floor(v.x() + r)), int(std::floor(v.y() + r)), int(std::floor(v.z() + r))};
      for (int z = lo.z; z <= hi.z; ++z)
        for (int y = lo.y; y <= hi.y; ++y)
          for (int x = lo.x; x <= hi.x; ++x) {
            const Int3 cell{x, y, z};
            if (!t.voxels().contains(cell) || !t.voxels().get(cell).isSolid()) continue;
            const Vec3f corner{float(x), float(y), float(z)};
            const Vec3f gap = (corner - v).cwiseMax(v - (corner + Vec3f::Ones())).cwiseMax(0.f);
            clearance = std::min(clearance, double(gap.norm()) * size - slack);
          }
    }
    return clearance <= 0;
  });
  return std::max(clearance, 0.0);
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
  freeRadius2_.assign(n, 0.0);
  posesSet_ = world.posesSetCount();
  terrainChanges_ = world.terrainChanges();
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
    freeRadius2_.push_back(0.0);
  }
  // Pass 1, in parallel: the point test and the crossing tests against grids and built terrain
  // chunks (all only read) for every body that needs a check, and its new state (each body
  // writes only its own slots); a crossing test that needs a terrain chunk not built yet
  // (building fills the chunk cache) is left for pass 2.
  world_.indexSolids();
  movingSolids_ = world_.hasMovingSolid();
  terrainLeft_.assign(n, 0);
  checkFrame_.resize(n);
  checkPlace_.resize(n);
  const uint64_t edits = world_.staticGridEdits();
  const bool staticEdited = edits != staticEdits_;
  staticEdits_ = edits;
  // A brick or a solid voxel may now be inside a free ball: all are dropped.
  const uint64_t terrainChanges = world_.terrainChanges();
  if (staticEdited || world_.posesSetCount() != posesSet_ || terrainChanges != terrainChanges_)
    std::fill(freeRadius2_.begin(), freeRadius2_.end(), 0.0);
  posesSet_ = world_.posesSetCount();
  terrainChanges_ = terrainChanges;
  // The balls answer for static grids and terrains: used and made when there is no other solid.
  const bool balls = !movingSolids_;
  constexpr double kFreeMin2 = 4 * kRecheckDistance * kRecheckDistance;  // smaller: the rest test does as well
  // A body that moved more than half the reach since the last update leaves its ball at once (a
  // crate falling at 30 m/s): no ball is made for it (made under 6 cm a frame instead, crates_on_grid
  // queried 2.3x as many bodies and spent 26% more instructions).
  constexpr double kSlow2 = kFreeReach * kFreeReach / 4;
  constexpr double kRecheck2 = kRecheckDistance * kRecheckDistance;
  JobSystem& jobs = world_.jobs();
  const uint32_t grain = tuning::bodyGrain(n);
  chunks_.assign(JobSystem::chunkCount(0, n, grain), Chunk{});
  jobs.parallelFor(0, n, grain, [&](uint32_t begin, uint32_t end) {
    Chunk chunk;
    for (uint32_t i = begin; i < end; ++i) {
      if (bodies.motion[i] != MotionType::Dynamic) continue;
      const Vec3d& p = bodies.position[i];
      const Vec3d previous = lastWorld_[i];  // where the last update saw it
      lastWorld_[i] = p;
      const bool clear = state_[i] == InsideSolid::No;
      if (seenFrame_[i] == kWorldFrame && p == lastSeen_[i]) {
        chunk.busy |= !clear;
        continue;
      }
      if (clear && !world_.nearSolidLastStep(i)) {
        // Clear before, and nowhere near a grid or terrain on its whole way here: clear now.
        settle(i, InsideSolid::No, p, kWorldFrame, p, 0.0);
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
        // Inside the free ball around its last clear place: so is its way from there.
        if (balls && f == kWorldFrame && clearFrame_[i] == kWorldFrame && (p - lastClear_[i]).squaredNorm() < freeRadius2_[i]) continue;
      }
      ++chunk.queried;
      const uint32_t frame = frameAt(WorldAabb{p, p}, i);
      const Vec3d place = toFrame(frame, p);
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
      if (s == InsideSolid::No && hasClear_[i]) {
        const std::optional<bool> crossed = world_.segmentHitsBuiltTerrain(lastClearWorld_[i], p);
        if (!crossed) {
          terrainLeft_[i] = 1;
          checkFrame_[i] = frame;
          checkPlace_[i] = place;
          chunk.busy = true;
          continue;
        }
        if (*crossed) s = InsideSolid::WentThrough;
      }
      double free2 = 0;
      if (balls && s == InsideSolid::No && frame == kWorldFrame && (p - previous).squaredNorm() < kSlow2) {
        const double r = world_.staticSolidClearance(p, kFreeReach);
        if (r * r > kFreeMin2) free2 = r * r;
      }
      settle(i, s, p, frame, place, free2);
      chunk.busy |= s != InsideSolid::No;
    }
    chunks_[begin / grain] = chunk;
  });
  // Pass 2, in body order, over the chunks that hold one: the terrain crossings left, and the
  // bodies inside solid.
  report_.bodies.clear();
  report_.reasons.clear();
  queried_ = 0;
  for (uint32_t c = 0; c < uint32_t(chunks_.size()); ++c) {
    queried_ += chunks_[c].queried;
    if (!chunks_[c].busy) continue;
    for (uint32_t i = c * grain; i < std::min(n, (c + 1) * grain); ++i) {
      if (terrainLeft_[i]) {
        const Vec3d& p = bodies.position[i];
        const InsideSolid s = world_.segmentHitsTerrain(lastClearWorld_[i], p) ? InsideSolid::WentThrough : InsideSolid::No;
        settle(i, s, p, checkFrame_[i], checkPlace_[i], 0.0);
      }
      if (bodies.motion[i] == MotionType::Dynamic && state_[i] != InsideSolid::No) {
        report_.bodies.push_back(i);
        report_.reasons.push_back(state_[i]);
      }
    }
  }
  return report_;
}

// A checked body's new state; a clear one's place becomes its last clear place, with the free
// ball found there (0: none).
void ContainmentTracker::settle(uint32_t i, InsideSolid s, const Vec3d& p, uint32_t frame, const Vec3d& place, double free2) {
  if (s == InsideSolid::No) {
    lastClear_[i] = place;
    clearFrame_[i] = frame;
    lastClearWorld_[i] = p;
    hasClear_[i] = 1;
    freeRadius2_[i] = free2;
  }
  lastSeen_[i] = place;
  seenFrame_[i] = frame;
  state_[i] = s;
}

}  // namespace bw
