// Bodies that start inside solid (depenetration.h): found after the scene is built, then moved
// out frame by frame at settings.depenetration_speed, or refused.
#include "world/depenetration.h"

#include <array>
#include <cmath>

#include "collision/bricks/brick_narrowphase.h"
#include "collision/terrain/terrain_contacts.h"
#include "world/scene_file.h"
#include "world/world.h"
#include "world/world_tuning.h"

namespace bw {

namespace {

// Up first (where a player expects a stuck body to go), then sideways, down, and the diagonals.
std::array<Vec3d, 26> searchDirections() {
  std::array<Vec3d, 26> d;
  int n = 0;
  for (const Vec3d& v : {Vec3d(0, 0, 1), Vec3d(1, 0, 0), Vec3d(-1, 0, 0), Vec3d(0, 1, 0), Vec3d(0, -1, 0), Vec3d(0, 0, -1)}) d[n++] = v;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z) {
        const int nonZero = (x != 0) + (y != 0) + (z != 0);
        if (nonZero == 2) d[n++] = Vec3d(x, y, z).normalized();
      }
  for (int x = -1; x <= 1; x += 2)
    for (int y = -1; y <= 1; y += 2)
      for (int z = -1; z <= 1; z += 2) d[n++] = Vec3d(x, y, z).normalized();
  return d;
}

std::string formatPoint(const Vec3d& p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.3f, %.3f, %.3f)", p.x(), p.y(), p.z());
  return text;
}

}  // namespace

std::string World::bodySource(uint32_t body) const {
  // Bodies are built in scene order: one per grid, one per terrain, then each spawner's count.
  uint32_t first = uint32_t(scene_.grids.size());
  if (body < first) return "grid '" + scene_.grids[body].name + "'";
  first += uint32_t(scene_.terrains.size());
  for (size_t i = 0; i < scene_.spawners.size(); ++i) {
    const uint32_t count = scene_.spawners[i].count;
    if (body < first + count)
      return "spawners[" + std::to_string(i) + "] body " + std::to_string(body - first) + " of " + std::to_string(count);
    first += count;
  }
  return "body " + std::to_string(body);
}

float World::deepestStaticOverlap(uint32_t body, const Vec3d& position, ContactScratch& scratch, std::vector<Contact>& contacts) {
  const RigidTransform gridPose = RigidTransform{position, bodies_.rotation[body]} * bodies_.shapeFromBody[body];
  RigidTransform pose = gridPose;
  QueryShape shape = bodies_.shape[body].primitive;
  const bool isGrid = bodies_.shape[body].isGrid();
  if (isGrid) {
    // A grid meets terrain through its convex approximation (as in a step).
    const ConvexApproximation& hull = grids_[bodies_.shape[body].grid]->convexApproximation(scene_.settings.approximationDepth);
    pose.translation = pose.pointToWorld(hull.shapeCenter());
    shape = hull.shape();
  }
  ContactParams params;
  params.lodFraction = 0.f;  // exact shapes: this decides where a body is let go
  params.maxContacts = 1;    // the deepest is enough
  float deepest = 0.f;
  for (uint32_t g : solidBodies_) {
    if (g == body) continue;
    contacts.clear();
    if (bodies_.shape[g].isGrid() && isGrid) {
      // Grid against grid as a step pairs them (the scene's grid_pairs): two interlocked chain
      // links overlap as hulls but not as bricks.
      // note: unchecked: the bodies' poses and shapes were checked when added, and each spot the
      // start search tries is one of them moved by a finite offset (the search tries thousands).
      int smaller = 0;
      collideGridsChecked(*grids_[bodies_.shape[g].grid], bodies_.shapePose(g), *grids_[bodies_.shape[body].grid], gridPose,
                          scene_.settings.approximationDepth, params, scratch, contacts, smaller, nullptr, scene_.settings.gridPairs);
    } else if (bodies_.shape[g].isGrid()) {
      grids_[bodies_.shape[g].grid]->collideChecked(bodies_.shapePose(g), shape, pose, params, scratch, contacts);
    } else if (bodies_.shape[g].isTerrain()) {
      terrainContacts(*terrains_[bodies_.shape[g].terrain], shape, pose, 0.f, contacts);
    }
    for (const Contact& c : contacts) deepest = std::max(deepest, c.depth);
  }
  return deepest;
}

void World::resolveStartsInSolid() {
  ContactScratch scratch;
  std::vector<Contact> contacts;
  const std::array<Vec3d, 26> directions = searchDirections();
  auto innerSize = [&](uint32_t body) {
    const Vec3f half = bodies_.shape[body].isGrid() ? grids_[bodies_.shape[body].grid]->bounds().halfExtent()
                                                    : bodies_.shape[body].primitive.localHalfExtents();
    return std::max(double(half.minCoeff()), 1e-3);
  };
  // Which dynamic bodies start in solid, and why.
  std::vector<uint32_t> inSolid;
  std::vector<InsideSolid> why;
  for (uint32_t body = 0; body < bodies_.size(); ++body) {
    if (bodies_.motion[body] != MotionType::Dynamic) continue;
    const InsideSolid centre = pointInsideSolid(bodies_.position[body], body);
    if (centre == InsideSolid::No && deepestStaticOverlap(body, bodies_.position[body], scratch, contacts) <= 0.5 * innerSize(body)) continue;
    inSolid.push_back(body);
    why.push_back(centre);
  }
  startedInSolid_ = uint32_t(inSolid.size());
  ghost_.assign(bodies_.size(), 0);
  if (inSolid.empty()) return;
  // Primitives that stay where they are (not in solid), then each one placed here, are in the
  // way too: twenty crates spawned in one tower must not all be let go in the same spot.
  std::vector<uint32_t> placed;
  std::vector<Vec3d> placedAt;
  for (uint32_t body = 0, next = 0; body < bodies_.size(); ++body) {
    if (next < inSolid.size() && inSolid[next] == body) {
      ++next;
      continue;
    }
    if (bodies_.motion[body] == MotionType::Dynamic && !bodies_.shape[body].isGrid()) {
      placed.push_back(body);
      placedAt.push_back(bodies_.position[body]);
    }
  }
  auto overlapsPlaced = [&](uint32_t body, const Vec3d& p) {
    if (bodies_.shape[body].isGrid()) return false;  // grids meet primitives in the solver
    const QueryShape& shape = bodies_.shape[body].primitive;
    const float reach = shape.localHalfExtents().norm();
    for (size_t k = 0; k < placed.size(); ++k) {
      const QueryShape& other = bodies_.shape[placed[k]].primitive;
      const Vec3d offset = placedAt[k] - p;
      if (offset.norm() > double(reach + other.localHalfExtents().norm())) continue;
      LocalContact c[kMaxContactsPerBrick];
      const int n = collideShapes(shape, LocalPose{Vec3f::Zero(), bodies_.rotation[body]}, other,
                                  LocalPose{offset.cast<float>(), bodies_.rotation[placed[k]]}, 0.f, c);
      for (int i = 0; i < n; ++i)
        if (c[i].depth > tuning::kSlop) return true;
    }
    return false;
  };
  for (size_t i = 0; i < inSolid.size(); ++i) {
    const uint32_t body = inSolid[i];
    const Vec3d start = bodies_.position[body];
    const std::string where = why[i] == InsideSolid::No ? "overlapping a grid or terrain by more than half its size" : insideSolidName(why[i]);
    if (scene_.settings.startInSolid == StartInSolid::Refuse)
      throw SceneError(scene_.source + ": " + bodySource(body) + " starts inside solid (" + where + ") at " + formatPoint(start) +
                       "; the scene refuses bodies in solid (settings.start_in_solid \"refuse\")");
    auto isFree = [&](const Vec3d& p) {
      return pointInsideSolid(p, body) == InsideSolid::No && deepestStaticOverlap(body, p, scratch, contacts) <= tuning::kSlop &&
             !overlapsPlaced(body, p);
    };
    // Shells of growing radius; in the first with a free pose, the first free direction.
    // note: a translation by r changes the overlap's depth by at most r, so no shell nearer
    // than the start's depth (less the slop) can hold a free pose: those shells are skipped
    // untried (the same shells, so the same answer). Trying each took 3 s for five 11 m slabs
    // spawned in a terrain, each try a box against a thousand triangles (the scene fuzz
    // target's timeout).
    const double startDepth = double(deepestStaticOverlap(body, start, scratch, contacts)) - double(tuning::kSlop);
    double inside = 0, radius = 0.25 * innerSize(body);
    while (radius * 1.3 < startDepth && radius <= kMaxDepenetrationSearch) {
      inside = radius;
      radius *= 1.3;
    }
    int direction = -1;
    while (radius <= kMaxDepenetrationSearch) {
      for (int d = 0; d < 26 && direction < 0; ++d)
        if (isFree(start + directions[d] * radius)) direction = d;
      if (direction >= 0) break;
      inside = radius;
      radius *= 1.3;
    }
    if (direction < 0)
      throw SceneError(scene_.source + ": " + bodySource(body) + " starts inside solid (" + where + ") at " + formatPoint(start) +
                       " and no free space was found within " + std::to_string(int(kMaxDepenetrationSearch)) + " m");
    // The nearest free distance along that direction (free at `radius`; the last shell was not).
    for (int k = 0; k < 12; ++k) {
      const double mid = 0.5 * (inside + radius);
      if (isFree(start + directions[direction] * mid))
        radius = mid;
      else
        inside = mid;
    }
    Depenetration d;
    d.body = body;
    d.remaining = directions[direction] * radius;
    d.baseVelocity = bodies_.linearVelocity[body];
    d.inverseMass = bodies_.inverseMass[body];
    d.inverseInertia = bodies_.inverseInertia[body];
    depenetrating_.push_back(d);
    if (!bodies_.shape[body].isGrid()) {
      placed.push_back(body);
      placedAt.push_back(start + d.remaining);
    }
    // Kinematic and a ghost on the way out: it passes through the solid it leaves and through
    // other bodies. (Pushing them aside, it crushed one against a wall; the impulse kept for
    // warm starting then launched it at 150 m/s when it was let go.)
    ghost_[body] = 1;
    bodies_.motion[body] = MotionType::Kinematic;
    bodies_.inverseMass[body] = 0.f;
    bodies_.inverseInertia[body] = Vec3f::Zero();
    bodies_.angularVelocity[body] = Vec3f::Zero();
  }
}

void World::advanceDepenetration() {
  const double frame = scene_.settings.timestep;
  const double step = double(scene_.settings.depenetrationSpeed) * frame;
  for (Depenetration& d : depenetrating_) {
    const double left = d.remaining.norm();
    const double travel = std::min(left, step);
    const Vec3d along = left > 0 ? Vec3d(d.remaining / left) : Vec3d::Zero();
    bodies_.linearVelocity[d.body] = d.baseVelocity + (along * (travel / frame)).cast<float>();
    d.remaining = travel < left ? Vec3d(d.remaining - along * travel) : Vec3d::Zero();
  }
}

void World::finishDepenetration() {
  size_t kept = 0;
  for (const Depenetration& d : depenetrating_) {
    if (d.remaining.squaredNorm() > 0) {
      depenetrating_[kept++] = d;
      continue;
    }
    ghost_[d.body] = 0;
    bodies_.motion[d.body] = MotionType::Dynamic;
    bodies_.inverseMass[d.body] = d.inverseMass;
    bodies_.inverseInertia[d.body] = d.inverseInertia;
    bodies_.linearVelocity[d.body] = d.baseVelocity;
    sleep_.wake(d.body);
  }
  depenetrating_.resize(kept);
}

const Depenetration* World::depenetration(uint32_t body) const {
  for (const Depenetration& d : depenetrating_)
    if (d.body == body) return &d;
  return nullptr;
}

}  // namespace bw
