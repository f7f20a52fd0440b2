// Contacts per pair: the bodies' broadphase bounds, then every pair's contacts in parallel
// (primitive vs grid through the grid's query, grid vs grid through the smaller grid's convex
// approximation, primitive pairs directly), each pair writing its own slot, with speculative
// margins and the pair cache. Pairs with a terrain are made afterwards (terrain_pairs.cpp).
#include <optional>
#include <string>

#include "collision/core/errors.h"
#include "world/scene_validation.h"
#include "world/world.h"
#include "world/world_tuning.h"

namespace bw {

float World::closingSpeed(uint32_t a, uint32_t b) const {
  // Relative speed of the centres plus each body's spin times its radius: the fastest any two
  // points of the pair can approach (reach_ holds speed + spin x radius per body).
  const float spinA = reach_[a] - bodies_.linearVelocity[a].norm(), spinB = reach_[b] - bodies_.linearVelocity[b].norm();
  return (bodies_.linearVelocity[a] - bodies_.linearVelocity[b]).norm() + spinA + spinB;
}

bool World::canCollide(uint32_t a, uint32_t b) const {
  // A body on its way out of solid is a ghost: it touches nothing until it is let go.
  if (!depenetrating_.empty() && (ghost_[a] || ghost_[b])) return false;
  return bodies_.inverseMass[a] > 0.f || bodies_.inverseMass[b] > 0.f;
}

World::BoxNow World::boxNow(uint32_t i) const {
  const RigidTransform pose = bodies_.shapePose(i);
  const Mat3f R = pose.rotation.toRotationMatrix().cwiseAbs();
  Vec3d centre, half;
  if (bodies_.shape[i].isGrid() || bodies_.shape[i].isTerrain()) {
    Aabb b;
    if (bodies_.shape[i].isGrid()) {
      b = grids_[bodies_.shape[i].grid]->bounds();
      // note: a grid edited down to no bricks is a point at its origin (and gets no proxy).
      if (b.isEmpty()) b = {Vec3f::Zero(), Vec3f::Zero()};
    } else {
      const Terrain& t = *terrains_[bodies_.shape[i].terrain];
      const Int3 size = t.voxels().size();
      b = {Vec3f::Zero(), Vec3f(float(size.x), float(size.y), float(size.z)) * t.voxelSize()};
    }
    centre = pose.pointToWorld(b.center());
    half = (R * b.halfExtent()).cast<double>();
  } else {
    centre = pose.translation;
    half = (R * bodies_.shape[i].primitive.localHalfExtents()).cast<double>();
  }
  return {centre, half, (centre - bodies_.position[i]).norm() + half.norm()};
}

WorldAabb World::BoxNow::grown(double reach, double timestep) const {
  // A margin of how far the body can move this frame keeps fast bodies in their pairs.
  const double margin = tuning::kBroadphaseMargin + reach * timestep;
  return {centre - half - Vec3d::Constant(margin), centre + half + Vec3d::Constant(margin)};
}

WorldAabb World::boundsOf(uint32_t i, float& reach) const {
  const BoxNow now = boxNow(i);
  // How far any point of the body can move per second: its speed plus its spin times its
  // radius about the centre of mass (a spinning capsule's ends outrun its centre).
  reach = float(double(bodies_.linearVelocity[i].norm()) + double(bodies_.angularVelocity[i].norm()) * now.radius);
  return now.grown(double(reach), scene_.settings.timestep);
}

WorldAabb World::boundsMovingBeside(uint32_t i, uint32_t carrier) const {
  float reach;
  if (!bodies_.translates(carrier) && !bodies_.turns(carrier)) return boundsOf(i, reach);
  const BoxNow now = boxNow(i);
  // The carrier's velocity at the body's centre, and how far it varies over the body's extent.
  const Vec3f w = bodies_.movingAngular(carrier);
  const Vec3f v = bodies_.movingLinear(carrier) + w.cross((now.centre - bodies_.position[carrier]).cast<float>());
  const double relative = double((bodies_.movingLinear(i) - v).norm()) + double(bodies_.movingAngular(i).norm()) * now.radius +
                          double(w.norm()) * now.half.norm();
  return now.grown(relative, scene_.settings.timestep);
}

WorldAabb World::broadphaseBounds(uint32_t body) const {
  if (body >= bodies_.size()) throw InvalidInput("World::broadphaseBounds: no body " + std::to_string(body));
  float reach;
  return boundsOf(body, reach);
}

void World::computeBounds(const Vec3f& gravityDt, int stage) {
  const uint32_t n = bodies_.size();
  bounds_.resize(n);
  isStatic_.resize(n);
  reach_.resize(n);
  // Per body: gravity on an awake dynamic body (semi-implicit Euler: before everything that
  // reads the velocity), then its bounds. Each body writes only its own slots: parallel, and
  // the same for any thread count.
  jobs_.parallelFor(0, n, tuning::bodyGrain(n), [&](uint32_t begin, uint32_t end) {
    ProfileZone z(profiler_, "gravity and bounds", stage);
    for (uint32_t i = begin; i < end; ++i) {
      if (bodies_.motion[i] == MotionType::Dynamic && !sleep_.asleep(i)) bodies_.linearVelocity[i] += gravityDt;
      bounds_[i] = boundsOf(i, reach_[i]);
      isStatic_[i] = bodies_.motion[i] == MotionType::Static;
    }
  });
}

void World::generateContacts(float dt) {
  const uint32_t n = uint32_t(pairs_.size());
  if (pairContacts_.size() < n) {
    pairContacts_.resize(n);
    scratch_.resize(n);
  }
  // note: sized here, each pair's entries reset by its contacts job: filling them here was a
  // serial 31 us a frame on crate_pile (6,900 pairs, 36 bytes each).
  pairFlipped_.resize(n);
  pairStats_.resize(n);
  pairReused_.resize(n);
  ContactParams base;
  base.lodFraction = scene_.settings.lodFraction;
  base.maxContacts = scene_.settings.manifoldSize;
  // Convex approximations are cached per grid and refreshed lazily: warm them serially so the
  // parallel stage only reads them (copies of one crate grid share one cache).
  std::optional<ProfileZone> warm(std::in_place, profiler_, "contacts: warm hulls", stage_ + kContactStepsStage);
  for (const BodyPair& p : pairs_) {
    const BodyShape& sa = bodies_.shape[p.a];
    const BodyShape& sb = bodies_.shape[p.b];
    if (sa.isGrid() && sb.isGrid() && canCollide(p.a, p.b) && pairMoves(p.a, p.b)) {
      BrickGrid& ga = *grids_[sa.grid];
      BrickGrid& gb = *grids_[sb.grid];
      BrickGrid& smaller = ga.brickCount() <= gb.brickCount() ? ga : gb;
      // (else brick by brick; and two-way grid pairs need no hull)
      if (smaller.brickCount() > kBrickwiseGridBricks && scene_.settings.gridPairs != GridPairMode::TwoWay)
        smaller.convexApproximation(scene_.settings.approximationDepth);
    }
  }
  // Pair cache: a pair whose relative pose has barely moved reuses its last contacts.
  warm.reset();
  pairCache_.match(pairs_, jobs_, profiler_, stage_ + kContactStepsStage + 1);
  // Each pair writes only its own slot: the result does not depend on the thread count.
  jobs_.parallelFor(0, n, tuning::kPairGrain, [&](uint32_t begin, uint32_t end) {
    ProfileZone zone(profiler_, "contacts", stage_ + 1);
    for (uint32_t k = begin; k < end; ++k) {
      std::vector<Contact>& out = pairContacts_[k];
      out.clear();
      pairFlipped_[k] = 0;  // (terrainPairs() sets its pairs' after this)
      pairStats_[k] = ContactStats{};
      pairReused_[k] = 0;
      uint32_t a = pairs_[k].a, b = pairs_[k].b;
      if (!canCollide(a, b) || !pairMoves(a, b)) continue;  // nothing moves: nothing to do
      if (bodies_.shape[a].isTerrain() || bodies_.shape[b].isTerrain()) continue;  // terrainPairs()
      const RigidTransform poseA{bodies_.position[a], bodies_.rotation[a]}, poseB{bodies_.position[b], bodies_.rotation[b]};
      if (pairCache_.reuse(k, poseA, poseB, scene_.settings.reuseTranslation, scene_.settings.reuseRotation, out, pairFlipped_[k])) {
        pairReused_[k] = 1;
        continue;
      }
      // Speculative contacts: look as far ahead as the pair can close in one step, so fast
      // bodies meet thin plates before they pass them (the solver lets gaps close, not cross).
      ContactParams params = base;
      params.speculativeMargin = tuning::kSpeculativeMargin + closingSpeed(a, b) * dt;
      const BodyShape& sa = bodies_.shape[a];
      const BodyShape& sb = bodies_.shape[b];
      // note: a body's shape was checked when it was added and its pose is the integrator's
      // (rotation normalised, position checked finite by the broadphase's bounds every step):
      // checking them again for every pair was 3% of ship_refit's step. The params carry this
      // step's margin, so a grid pair still checks them (as collide did).
      if (sa.isGrid() || sb.isGrid()) BrickGrid::validateContactParams(params, "World (contacts)");
      if (sa.isGrid() && sb.isGrid()) {
        int smaller = 0;
        collideGridsChecked(*grids_[sa.grid], bodies_.shapePose(a), *grids_[sb.grid], bodies_.shapePose(b),
                            scene_.settings.approximationDepth, params, scratch_[k], out, smaller, &pairStats_[k], scene_.settings.gridPairs);
        pairFlipped_[k] = smaller == 1;  // normals point from the larger (a) to the smaller (b)
      } else if (sa.isGrid() || sb.isGrid()) {
        const uint32_t g = sa.isGrid() ? a : b, p = sa.isGrid() ? b : a;
        grids_[bodies_.shape[g].grid]->collideChecked(bodies_.shapePose(g), bodies_.shape[p].primitive, bodies_.shapePose(p), params,
                                                      scratch_[k], out, &pairStats_[k]);
        pairFlipped_[k] = p == b;  // normals point from the grid towards the primitive
      } else {
        // Two primitives: in a frame at a's position (double -> float once, per the precision rule).
        const RigidTransform frame{bodies_.position[a], Quatf::Identity()};
        const RigidTransform pa = bodies_.shapePose(a), pb = bodies_.shapePose(b);
        LocalContact c[kMaxContactsPerBrick];
        const int m = collideShapes(sa.primitive, LocalPose{frame.pointToLocal(pa.translation), pa.rotation}, sb.primitive,
                                    LocalPose{frame.pointToLocal(pb.translation), pb.rotation}, params.speculativeMargin, c);
        for (int i = 0; i < m; ++i)
          out.push_back({frame.pointToWorld(c[i].position), c[i].normal, c[i].depth, 0u, 0u});
      }
    }
  });
}

const std::vector<std::vector<Contact>>& World::probeContacts(float lodFraction, int approximationDepth, int manifoldSize,
                                                             uint64_t* boxTests) {
  const SceneSettings saved = scene_.settings;
  scene_.settings.lodFraction = lodFraction;
  scene_.settings.approximationDepth = approximationDepth;
  scene_.settings.manifoldSize = manifoldSize;
  scene_.settings.reuseTranslation = 0;  // nothing counts as still: every pair is collided
  try {
    validateScene(scene_);
    generateContacts(float(scene_.settings.timestep / scene_.settings.substeps));
  } catch (...) {
    scene_.settings = saved;
    throw;
  }
  scene_.settings = saved;
  if (boxTests) {
    *boxTests = 0;
    for (const ContactStats& s : pairStats_) *boxTests += s.index.boxTests;
  }
  return pairContacts_;
}

}  // namespace bw
