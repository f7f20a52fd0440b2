#include "world/world.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <bit>
#include <chrono>
#include <cstring>
#include <limits>

#include "collision/content/brs_reader.h"
#include "collision/content/build_generators.h"
#include "collision/content/build_tiling.h"
#include "collision/content/vox_reader.h"
#include "collision/core/argument_checks.h"
#include "collision/core/hash.h"
#include "collision/core/seeded_random.h"
#include "collision/terrain/terrain_contacts.h"
#include "world/scene_file.h"
#include "world/scene_validation.h"

namespace bw {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// Solver constants (documented in README "World"): Baumgarte factor, allowed penetration,
// restitution and the speed below which bounces are not restituted.
constexpr float kBaumgarte = 0.2f;
constexpr float kSlop = 0.005f;
constexpr float kRestitution = 0.1f;
constexpr float kBounceThreshold = 1.0f;
// Deep overlaps (bodies spawned inside each other or inside terrain) separate at most this fast
// (m/s): Baumgarte alone would turn a 1 m overlap into a 12 m/s launch.
constexpr float kMaxPushOut = 3.0f;
// Sleeping: an island whose bodies all stayed below these speeds for kSleepTime seconds sleeps.
constexpr float kSleepLinear = 0.05f, kSleepAngular = 0.1f, kSleepTime = 0.5f;
// Water drag: velocities decay at this rate (1/s) times the submerged fraction, so floating
// bodies settle instead of bobbing for ever (a crate of half water's density rises at about
// g / kWaterLinearDrag = 2.5 m/s and does not leap out of the surface).
constexpr float kWaterLinearDrag = 4.f, kWaterAngularDrag = 4.f;
// Pair cache: contacts are reused while the relative pose moved less than these since they were
// made (a resting pile moves micrometres per step).

void primitiveMass(const QueryShape& s, float density, float& invMass, Vec3f& invInertia) {
  float m;
  Vec3f I;
  switch (s.kind) {
    case QueryShape::Kind::Sphere:
      m = density * 4.f / 3.f * 3.14159265f * s.radius * s.radius * s.radius;
      I = Vec3f::Constant(0.4f * m * s.radius * s.radius);
      break;
    case QueryShape::Kind::Capsule: {
      // Cylinder of the core plus two hemispheres (a sphere), about the centre.
      const float r = s.radius, h = 2 * s.halfHeight;
      const float mc = density * 3.14159265f * r * r * h, ms = density * 4.f / 3.f * 3.14159265f * r * r * r;
      m = mc + ms;
      const float iz = mc * r * r / 2 + ms * 0.4f * r * r;
      const float ix = mc * (3 * r * r + h * h) / 12 + ms * (0.4f * r * r + h * h / 4 + 3 * h * r / 8);
      I = Vec3f(ix, ix, iz);
      break;
    }
    default: {
      const Vec3f e = s.halfExtents * 2.f;
      m = density * e.prod();
      I = Vec3f(e.y() * e.y() + e.z() * e.z(), e.x() * e.x() + e.z() * e.z(), e.x() * e.x() + e.y() * e.y()) * (m / 12.f);
    }
  }
  invMass = 1.f / m;
  invInertia = I.cwiseInverse();
}

}  // namespace

World::World(const SceneDescription& scene, int threads) : scene_((validateScene(scene), scene)), jobs_(threads) {
  for (const GridDescription& g : scene_.grids) buildGrid(g);
  for (const TerrainDescription& t : scene_.terrains) buildTerrain(t);
  for (const SpawnerDescription& s : scene_.spawners) spawn(s);
  stillTime_.assign(bodies_.size(), 0.f);
  asleep_.assign(bodies_.size(), 0);
}

uint32_t World::sleepingCount() const {
  uint32_t n = 0;
  for (uint8_t a : asleep_) n += a;
  return n;
}

uint64_t World::brickCount() const {
  uint64_t n = 0;
  for (const auto& g : grids_) n += g->brickCount();
  return n;
}

// Bricks of a grid description: a generator's build, a save's bricks, or the listed ones, then
// tiled when asked. Content errors name the scene, the grid and the file.
std::vector<Brick> World::gridBricks(const GridDescription& g) const {
  std::vector<Brick> bricks;
  Aabb bounds = Aabb::empty();
  try {
    if (!g.file.empty()) {
      BrsLoadResult save = loadBrs(g.file);
      bricks = std::move(save.bricks);
      bounds = save.bounds;
    } else if (!g.generator.empty()) {
      GeneratedBuild build = generateBuild(g.generator, g.seed, g.scale);
      bricks = std::move(build.bricks);
      bounds = build.bounds;
    } else {
      return g.bricks;
    }
    if (g.tilesX > 1 || g.tilesY > 1) bricks = tileBuild(bricks, bounds, g.tilesX, g.tilesY, g.tileGap);
  } catch (const InvalidInput& e) {
    throw SceneError(scene_.source + ": grid '" + g.name + "': " + e.what());
  }
  if (bricks.empty()) throw SceneError(scene_.source + ": grid '" + g.name + "': has no bricks with collision");
  return bricks;
}

void World::buildGrid(const GridDescription& g) {
  const std::vector<Brick> bricks = gridBricks(g);
  auto grid = std::make_unique<BrickGrid>(BrickGrid::Config(uint32_t(bricks.size() + 1024)));
  for (const Brick& b : bricks) grid->placeBrick(b);
  grids_.push_back(std::move(grid));
  gridNames_.push_back(g.name);
  addGridBody(uint32_t(grids_.size() - 1), g.position, g.rotation, g.motion, g.kinematic.linearVelocity, g.kinematic.angularVelocity);
}

void World::buildTerrain(const TerrainDescription& t) {
  VoxMaterialMap materials;
  if (t.waterFirst >= 0) {
    materials.waterFirst = t.waterFirst;
    materials.waterLast = t.waterLast;
  }
  VoxTerrainOptions options;
  options.voxelSize = t.voxelSize;
  VoxTerrain built;
  try {
    built = buildVoxTerrain(loadVox(t.file), materials, options);
  } catch (const InvalidInput& e) {
    throw SceneError(scene_.source + ": terrain '" + t.name + "': " + e.what());
  }
  // The scene places the model's voxel (0, 0, 0) corner; the terrain adds a margin of air
  // around the model, so its own origin sits that margin lower.
  const Vec3d margin(built.voxToTerrain.x, built.voxToTerrain.y, built.voxToTerrain.z);
  built.terrain->setPlacement(RigidTransform{t.position - margin * double(t.voxelSize), Quatf::Identity()});
  BodyShape shape;
  shape.terrain = uint32_t(terrains_.size());
  terrains_.push_back(std::move(built.terrain));
  waterDensity_.push_back(t.waterDensity);
  const RigidTransform& placement = terrains_.back()->placement();
  bodies_.add(placement.translation, placement.rotation, MotionType::Static, shape, 0.f, Vec3f::Zero());
}

uint32_t World::addGridBody(uint32_t gridIndex, const Vec3d& position, const Quatf& rotation, MotionType motion,
                            const Vec3d& linearVelocity, const Vec3f& angularVelocity) {
  BodyShape shape;
  shape.grid = gridIndex;
  const BrickGrid& grid = *grids_[gridIndex];
  uint32_t id;
  if (motion != MotionType::Dynamic) {
    // Static and kinematic grids move about their own origin (a station spins about its hub).
    id = bodies_.add(position, rotation, motion, shape, 0.f, Vec3f::Zero());
  } else {
    // Body frame = centre of mass with principal axes; the grid sits inside it.
    const MassProperties mp = grid.massProperties();
    Eigen::SelfAdjointEigenSolver<Mat3d> eig(mp.inertia);
    Mat3d axes = eig.eigenvectors();
    if (axes.determinant() < 0) axes.col(2) = -axes.col(2);
    const Quatf principal = Quatf(axes.cast<float>()).normalized();
    const RigidTransform bodyInGrid{mp.centerOfMass, principal};
    const RigidTransform gridPose{position, rotation};
    const RigidTransform bodyPose = gridPose * bodyInGrid;
    const Vec3f invI = eig.eigenvalues().cast<float>().cwiseMax(1e-12f).cwiseInverse();
    id = bodies_.add(bodyPose.translation, bodyPose.rotation, motion, shape, float(1.0 / mp.mass), invI, bodyInGrid.inverse());
  }
  bodies_.linearVelocity[id] = linearVelocity.cast<float>();
  bodies_.angularVelocity[id] = angularVelocity;
  return id;
}

void World::spawn(const SpawnerDescription& s) {
  SeededRandom r(s.seed);
  for (uint32_t k = 0; k < s.count; ++k) {
    const Vec3d p(r.uniform(s.regionMin.x(), s.regionMax.x()), r.uniform(s.regionMin.y(), s.regionMax.y()),
                  r.uniform(s.regionMin.z(), s.regionMax.z()));
    const Quatf q = Quatf(Eigen::AngleAxisf(float(r.uniform(0, 6.283)), Vec3f(float(r.normal()), float(r.normal()), float(r.normal())).normalized())).normalized();
    if (s.shape == SpawnerDescription::Shape::Grid) {
      // Grid copies keep their template's orientation (a ship is loaded upright); primitives
      // get a random one.
      const auto it = std::find(gridNames_.begin(), gridNames_.end(), s.grid);
      addGridBody(uint32_t(it - gridNames_.begin()), p, Quatf::Identity(), MotionType::Dynamic, s.velocity, Vec3f::Zero());
      continue;
    }
    BodyShape shape;
    shape.primitive = s.shape == SpawnerDescription::Shape::Sphere  ? QueryShape::sphere(s.radius)
                      : s.shape == SpawnerDescription::Shape::Capsule ? QueryShape::capsule(s.radius, s.halfHeight)
                                                                       : QueryShape::box(s.halfExtents);
    float invMass;
    Vec3f invI;
    primitiveMass(shape.primitive, s.density, invMass, invI);
    const uint32_t id = bodies_.add(p, q, MotionType::Dynamic, shape, invMass, invI);
    bodies_.linearVelocity[id] = s.velocity.cast<float>();
  }
}

bool World::canCollide(uint32_t a, uint32_t b) const {
  return bodies_.inverseMass[a] > 0.f || bodies_.inverseMass[b] > 0.f;
}

void World::computeBounds() {
  const uint32_t n = bodies_.size();
  bounds_.resize(n);
  isStatic_.resize(n);
  for (uint32_t i = 0; i < n; ++i) {
    const RigidTransform pose = bodies_.shapePose(i);
    const Mat3f R = pose.rotation.toRotationMatrix().cwiseAbs();
    Vec3d centre, half;
    if (bodies_.shape[i].isGrid() || bodies_.shape[i].isTerrain()) {
      Aabb b;
      if (bodies_.shape[i].isGrid()) {
        b = grids_[bodies_.shape[i].grid]->bounds();
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
    // A margin of how far the body can move this frame keeps fast bodies in their pairs.
    const double margin = 0.02 + double(bodies_.linearVelocity[i].norm()) * scene_.settings.timestep;
    bounds_[i] = {centre - half - Vec3d::Constant(margin), centre + half + Vec3d::Constant(margin)};
    isStatic_[i] = bodies_.motion[i] == MotionType::Static;
  }
}

void World::generateContacts(float dt) {
  const uint32_t n = uint32_t(pairs_.size());
  if (pairContacts_.size() < n) {
    pairContacts_.resize(n);
    scratch_.resize(n);
  }
  pairFlipped_.assign(n, 0);
  pairStats_.assign(n, ContactStats{});
  ContactParams base;
  base.lodFraction = scene_.settings.lodFraction;
  base.maxContacts = scene_.settings.manifoldSize;
  // Convex approximations are cached per grid and refreshed lazily: warm them serially so the
  // parallel stage only reads them (copies of one crate grid share one cache).
  for (const BodyPair& p : pairs_) {
    const BodyShape& sa = bodies_.shape[p.a];
    const BodyShape& sb = bodies_.shape[p.b];
    if (sa.isGrid() && sb.isGrid() && canCollide(p.a, p.b) && (active(p.a) || active(p.b))) {
      BrickGrid& ga = *grids_[sa.grid];
      BrickGrid& gb = *grids_[sb.grid];
      (ga.brickCount() <= gb.brickCount() ? ga : gb).convexApproximation(scene_.settings.approximationDepth);
    }
  }
  // Pair cache lookup (both lists are sorted by pair): a hit reuses last contacts if the
  // relative pose has barely moved.
  pairCacheHit_.assign(n, -1);
  for (uint32_t k = 0, c = 0; k < n; ++k) {
    while (c < pairCache_.size() && pairCache_[c].pair < pairs_[k]) ++c;
    if (c < pairCache_.size() && pairCache_[c].pair == pairs_[k]) pairCacheHit_[k] = int32_t(c);
  }
  // Each pair writes only its own slot: the result does not depend on the thread count.
  jobs_.parallelFor(0, n, 4, [&](uint32_t begin, uint32_t end) {
    ProfileZone zone(profiler_, "contacts", stage_ + 1);
    for (uint32_t k = begin; k < end; ++k) {
      std::vector<Contact>& out = pairContacts_[k];
      out.clear();
      uint32_t a = pairs_[k].a, b = pairs_[k].b;
      if (!canCollide(a, b) || (!active(a) && !active(b))) continue;  // nothing awake: nothing to do
      if (bodies_.shape[a].isTerrain() || bodies_.shape[b].isTerrain()) continue;  // terrainPairs()
      const RigidTransform poseA{bodies_.position[a], bodies_.rotation[a]}, poseB{bodies_.position[b], bodies_.rotation[b]};
      if (pairCacheHit_[k] >= 0) {
        const PairCacheEntry& e = pairCache_[size_t(pairCacheHit_[k])];
        const RigidTransform rel = poseA.inverse() * poseB;
        const bool still = (rel.translation - e.relative.translation).norm() < scene_.settings.reuseTranslation &&
                           e.relative.rotation.angularDistance(rel.rotation) < scene_.settings.reuseRotation;
        if (still) {
          // Re-pose the cached points and measure the depth along the normal again.
          for (uint32_t i = 0; i < e.count; ++i) {
            const CachedContact& c = pairCacheContacts_[e.first + i];
            const Vec3d onA = poseA.pointToWorld(c.onA), onB = poseB.pointToWorld(c.onB);
            const Vec3f nrm = poseB.directionToWorld(c.normalB);
            // The slot's normal points from its "b side" towards its "a side" (flipped swaps them).
            const float depth = e.flipped ? float((onA - onB).dot(nrm.cast<double>())) : float((onB - onA).dot(nrm.cast<double>()));
            // The slot's point lies on the surface its normal leaves: b's (or a's when flipped).
            out.push_back({e.flipped ? onA : onB, nrm, depth, c.feature, c.material});
          }
          pairFlipped_[k] = e.flipped;
          pairStats_[k].rawContacts = uint32_t(-1);  // marks a reuse for the stats
          continue;
        }
      }
      // Speculative contacts: look as far ahead as the pair can close in one step, so fast
      // bodies meet thin plates before they pass them (the solver lets gaps close, not cross).
      ContactParams params = base;
      params.speculativeMargin = 0.01f + (bodies_.linearVelocity[a] - bodies_.linearVelocity[b]).norm() * dt;
      const BodyShape& sa = bodies_.shape[a];
      const BodyShape& sb = bodies_.shape[b];
      if (sa.isGrid() && sb.isGrid()) {
        int smaller = 0;
        collideGrids(*grids_[sa.grid], bodies_.shapePose(a), *grids_[sb.grid], bodies_.shapePose(b),
                     scene_.settings.approximationDepth, params, scratch_[k], out, smaller, &pairStats_[k]);
        pairFlipped_[k] = smaller == 1;  // normals point from the larger (a) to the smaller (b)
      } else if (sa.isGrid() || sb.isGrid()) {
        const uint32_t g = sa.isGrid() ? a : b, p = sa.isGrid() ? b : a;
        grids_[bodies_.shape[g].grid]->collide(bodies_.shapePose(g), bodies_.shape[p].primitive, bodies_.shapePose(p), params,
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

// Pairs with a terrain, in pair order on this thread: solid contacts against the chunk
// triangles, and buoyancy plus drag from the water voxels the body displaces.
void World::terrainPairs(float dt) {
  if (terrains_.empty()) return;
  const uint32_t n = uint32_t(pairs_.size());
  const Vec3f g = scene_.settings.gravity.cast<float>();
  stats_.floating = 0;  // bodies in water in the last substep
  for (uint32_t k = 0; k < n; ++k) {
    const uint32_t a = pairs_[k].a, b = pairs_[k].b;
    const bool terrainA = bodies_.shape[a].isTerrain();
    if (!terrainA && !bodies_.shape[b].isTerrain()) continue;
    if (!canCollide(a, b) || (!active(a) && !active(b))) continue;
    const uint32_t body = terrainA ? b : a, terrainBody = terrainA ? a : b;
    Terrain& terrain = *terrains_[bodies_.shape[terrainBody].terrain];
    RigidTransform pose = bodies_.shapePose(body);
    QueryShape shape = bodies_.shape[body].primitive;
    if (bodies_.shape[body].isGrid()) {
      // A grid meets terrain through its convex approximation (as it meets other grids).
      const ConvexApproximation& hull = grids_[bodies_.shape[body].grid]->convexApproximation(scene_.settings.approximationDepth);
      pose.translation = pose.pointToWorld(hull.shapeCenter());
      shape = hull.shape();
    }
    std::vector<Contact>& out = pairContacts_[k];
    out.clear();
    const float margin = 0.01f + bodies_.linearVelocity[body].norm() * dt;
    terrainContacts(terrain, shape, pose, margin, out);
    pairFlipped_[k] = body == b;  // normals point from the terrain towards the body
    stats_.terrainContacts += uint32_t(out.size());

    WaterContact water;
    if (bodies_.motion[body] != MotionType::Dynamic || !terrainWaterContact(terrain, shape, pose, water)) continue;
    // Archimedes: the displaced water's weight, applied at the centre of buoyancy, as an
    // impulse this substep; then drag in proportion to how deep the body sits.
    const float impulse = float(waterDensity_[bodies_.shape[terrainBody].terrain] * water.submergedVolume) * dt;
    const Vec3f j = -g * impulse;
    bodies_.linearVelocity[body] += j * bodies_.inverseMass[body];
    // note: the centre of buoyancy is estimated from the body's bounding box, so only a body
    // cut by the surface gets the righting torque; a submerged one would get a spurious torque
    // wherever its box overlaps solid voxels (and spin up without bound).
    if (water.submergedFraction < 0.98f) {
      const Vec3f r = (water.centreOfBuoyancy - bodies_.position[body]).cast<float>();
      bodies_.angularVelocity[body] += bodies_.inverseInertiaWorld(body) * r.cross(j);
    }
    const float f = water.submergedFraction;
    bodies_.linearVelocity[body] *= std::max(0.f, 1.f - kWaterLinearDrag * f * dt);
    bodies_.angularVelocity[body] *= std::max(0.f, 1.f - kWaterAngularDrag * f * dt);
    ++stats_.floating;
  }
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

// Stores every pair's contacts in both bodies' frames for the next step.
void World::updatePairCache() {
  nextPairCache_.clear();
  nextPairCacheContacts_.clear();
  for (uint32_t k = 0; k < pairs_.size(); ++k) {
    if (pairContacts_[k].empty()) continue;
    const uint32_t a = pairs_[k].a, b = pairs_[k].b;
    const RigidTransform poseA{bodies_.position[a], bodies_.rotation[a]}, poseB{bodies_.position[b], bodies_.rotation[b]};
    PairCacheEntry e{pairs_[k], poseA.inverse() * poseB, pairFlipped_[k], uint32_t(nextPairCacheContacts_.size()),
                     uint32_t(pairContacts_[k].size())};
    // A reused entry keeps its original relative pose, so slow creep is caught once it adds up.
    if (pairCacheHit_[k] >= 0 && pairStats_[k].rawContacts == uint32_t(-1)) e.relative = pairCache_[size_t(pairCacheHit_[k])].relative;
    for (const Contact& c : pairContacts_[k]) {
      // The point lies on the slot's "b side" surface; the "a side" point is depth along -normal.
      const Vec3d onSideB = c.position, onSideA = c.position - c.normal.cast<double>() * double(c.depth);
      const Vec3d onB = pairFlipped_[k] ? onSideA : onSideB, onA = pairFlipped_[k] ? onSideB : onSideA;
      nextPairCacheContacts_.push_back({poseA.pointToLocal(onA), poseB.pointToLocal(onB), poseB.directionToLocal(c.normal), c.featureB,
                                        c.material});
    }
    nextPairCache_.push_back(e);
  }
  std::swap(pairCache_, nextPairCache_);
  std::swap(pairCacheContacts_, nextPairCacheContacts_);
}

void World::prepareSolver(float dt) {
  contacts_.clear();
  inverseInertiaWorld_.resize(bodies_.size());
  for (uint32_t i = 0; i < bodies_.size(); ++i) inverseInertiaWorld_[i] = bodies_.inverseInertiaWorld(i);
  for (uint32_t k = 0; k < pairs_.size(); ++k) {
    // Solver convention: the normal points from b towards a.
    const uint32_t a = pairFlipped_[k] ? pairs_[k].b : pairs_[k].a;
    const uint32_t b = pairFlipped_[k] ? pairs_[k].a : pairs_[k].b;
    for (const Contact& c : pairContacts_[k]) {
      SolverContact s;
      s.a = a;
      s.b = b;
      s.point = c.position;
      s.normal = c.normal;
      s.depth = c.depth;
      s.key = (uint64_t(pairs_[k].a) << 40) ^ (uint64_t(pairs_[k].b) << 20) ^ c.featureB;
      s.rA = (c.position - bodies_.position[a]).cast<float>();
      s.rB = (c.position - bodies_.position[b]).cast<float>();
      const Vec3f n = s.normal;
      s.t1 = (std::abs(n.x()) > 0.57f ? Vec3f(n.y(), -n.x(), 0) : Vec3f(0, n.z(), -n.y())).normalized();
      s.t2 = n.cross(s.t1);
      const Mat3f& iA = inverseInertiaWorld_[a];
      const Mat3f& iB = inverseInertiaWorld_[b];
      const Vec3f dirs[3] = {n, s.t1, s.t2};
      float masses[3];
      for (int d = 0; d < 3; ++d) {
        s.angA[d] = iA * s.rA.cross(dirs[d]);
        s.angB[d] = iB * s.rB.cross(dirs[d]);
        const float k = bodies_.inverseMass[a] + bodies_.inverseMass[b] + s.angA[d].cross(s.rA).dot(dirs[d]) +
                        s.angB[d].cross(s.rB).dot(dirs[d]);
        masses[d] = k > 0 ? 1.f / k : 0.f;
      }
      s.massN = masses[0];
      s.massT1 = masses[1];
      s.massT2 = masses[2];
      if (scene_.settings.shockPropagation && bodies_.motion[a] == MotionType::Dynamic && bodies_.motion[b] == MotionType::Dynamic) {
        // The lower body (along gravity) is the support: in the shock sweep only the upper one moves.
        const Vec3d up = -scene_.settings.gravity.normalized();
        const double ha = up.dot(bodies_.position[a]), hb = up.dot(bodies_.position[b]);
        if (std::isfinite(ha) && std::abs(ha - hb) > 1e-3) {
          s.shockLower = ha < hb ? 1 : 2;
          s.height = std::min(ha, hb);
          for (int d = 0; d < 3; ++d) {
            const float k = s.shockLower == 1 ? bodies_.inverseMass[b] + s.angB[d].cross(s.rB).dot(dirs[d])
                                              : bodies_.inverseMass[a] + s.angA[d].cross(s.rA).dot(dirs[d]);
            s.shockMass[d] = k > 0 ? 1.f / k : 0.f;
          }
        }
      }
      s.friction = std::sqrt(bodies_.friction[a] * bodies_.friction[b]);
      const Vec3f vRel = bodies_.linearVelocity[a] + bodies_.angularVelocity[a].cross(s.rA) - bodies_.linearVelocity[b] -
                         bodies_.angularVelocity[b].cross(s.rB);
      const float vn = vRel.dot(n);
      // Penetrating: push out (Baumgarte) and restitute fast impacts. Speculative (a gap of -depth):
      // the bodies may approach by at most the gap this step.
      const float bounce = vn < -kBounceThreshold ? -kRestitution * vn : 0.f;
      s.bias = s.depth >= 0.f ? std::min(kBaumgarte / dt * std::max(s.depth - kSlop, 0.f), kMaxPushOut) + bounce : s.depth / dt;
      // The relax pass after integration keeps restitution and speculative gaps but drops the
      // push-out, so no push-out velocity survives into the next step (resting stacks stay put).
      s.relaxBias = s.depth >= 0.f ? bounce : s.depth / dt;
      // Warm start from the nearest cached impulse of the same pair and feature.
      auto range = std::equal_range(cache_.begin(), cache_.end(), CachedImpulse{s.key, {}, 0, 0, 0},
                                    [](const CachedImpulse& x, const CachedImpulse& y) { return x.key < y.key; });
      double best = 0.05 * 0.05;
      for (auto it = range.first; it != range.second; ++it) {
        const double d2 = (it->point - s.point).squaredNorm();
        if (d2 < best) {
          best = d2;
          s.lambdaN = it->n;
          s.lambdaT1 = it->t1;
          s.lambdaT2 = it->t2;
        }
      }
      contacts_.push_back(s);
    }
  }
  // A sleeping body touched by an awake one wakes up (its island rejoins the simulation).
  for (const SolverContact& s : contacts_) {
    for (uint32_t x : {s.a, s.b})
      if (asleep_[x]) {
        asleep_[x] = 0;
        stillTime_[x] = 0.f;
      }
  }
}

// Islands: dynamic bodies joined by contacts (static and kinematic bodies do not join islands,
// they are read but never written by the solver). Union-find with the smaller id as root makes
// the grouping a pure function of the contact list.
void World::buildIslands() {
  const uint32_t n = bodies_.size();
  islandOf_.resize(n);
  for (uint32_t i = 0; i < n; ++i) islandOf_[i] = i;
  auto find = [&](uint32_t x) {
    while (islandOf_[x] != x) x = islandOf_[x] = islandOf_[islandOf_[x]];
    return x;
  };
  for (const SolverContact& c : contacts_) {
    if (bodies_.motion[c.a] != MotionType::Dynamic || bodies_.motion[c.b] != MotionType::Dynamic) continue;
    const uint32_t ra = find(c.a), rb = find(c.b);
    if (ra != rb) islandOf_[std::max(ra, rb)] = std::min(ra, rb);
  }
  // Contacts grouped by the island of their dynamic body, islands ordered by root id (CSR).
  std::vector<uint32_t>& start = islandStart_;
  std::vector<uint32_t> rootIndex(n, kInvalidIndex);
  std::vector<uint32_t> roots;
  auto islandOfContact = [&](const SolverContact& c) {
    return find(bodies_.motion[c.a] == MotionType::Dynamic ? c.a : c.b);
  };
  for (const SolverContact& c : contacts_) {
    const uint32_t r = islandOfContact(c);
    if (rootIndex[r] == kInvalidIndex) {
      rootIndex[r] = 0;
      roots.push_back(r);
    }
  }
  std::sort(roots.begin(), roots.end());
  for (uint32_t i = 0; i < roots.size(); ++i) rootIndex[roots[i]] = i;
  start.assign(roots.size() + 1, 0);
  for (const SolverContact& c : contacts_) ++start[rootIndex[islandOfContact(c)] + 1];
  for (size_t i = 1; i < start.size(); ++i) start[i] += start[i - 1];
  islandContacts_.resize(contacts_.size());
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  for (uint32_t k = 0; k < contacts_.size(); ++k) islandContacts_[fill[rootIndex[islandOfContact(contacts_[k])]]++] = k;
}

// Applies impulse `lambda` along direction d (0 normal, 1 and 2 tangents) to the contact's
// dynamic bodies (static and kinematic bodies are read, never written).
void World::applyImpulse(const SolverContact& s, int d, const Vec3f& dir, float lambda) {
  SolverBody& a = solverBodies_[s.a];
  SolverBody& b = solverBodies_[s.b];
  if (a.dynamic) {
    a.v += dir * (lambda * a.invMass);
    a.w += s.angA[d] * lambda;
  }
  if (b.dynamic) {
    b.v -= dir * (lambda * b.invMass);
    b.w -= s.angB[d] * lambda;
  }
}

// The solver works on a compact copy of the bodies' velocities (one 32-byte record per body
// instead of five arrays); copied in before solving, out after.
void World::loadSolverBodies() {
  const uint32_t n = bodies_.size();
  solverBodies_.resize(n);
  for (uint32_t i = 0; i < n; ++i)
    solverBodies_[i] = {bodies_.linearVelocity[i], bodies_.inverseMass[i], bodies_.angularVelocity[i],
                        bodies_.motion[i] == MotionType::Dynamic ? 1u : 0u};
}

void World::storeSolverBodies() {
  for (uint32_t i = 0; i < bodies_.size(); ++i) {
    if (!solverBodies_[i].dynamic) continue;
    bodies_.linearVelocity[i] = solverBodies_[i].v;
    bodies_.angularVelocity[i] = solverBodies_[i].w;
  }
}

void World::warmStart(const SolverContact& s) {
  applyImpulse(s, 0, s.normal, s.lambdaN);
  applyImpulse(s, 1, s.t1, s.lambdaT1);
  applyImpulse(s, 2, s.t2, s.lambdaT2);
}

// One Gauss-Seidel update of one contact: normal impulse clamped at zero, then friction
// clamped by the Coulomb bound.
void World::solveContact(SolverContact& s, bool relax) {
  const SolverBody& a = solverBodies_[s.a];
  const SolverBody& b = solverBodies_[s.b];
  auto relative = [&] { return Vec3f(a.v + a.w.cross(s.rA) - b.v - b.w.cross(s.rB)); };
  const float oldN = s.lambdaN;
  s.lambdaN = std::max(oldN + s.massN * ((relax ? s.relaxBias : s.bias) - relative().dot(s.normal)), 0.f);
  applyImpulse(s, 0, s.normal, s.lambdaN - oldN);
  const float limit = s.friction * s.lambdaN;
  const Vec3f v = relative();
  const float o1 = s.lambdaT1, o2 = s.lambdaT2;
  s.lambdaT1 = std::clamp(o1 - s.massT1 * v.dot(s.t1), -limit, limit);
  s.lambdaT2 = std::clamp(o2 - s.massT2 * v.dot(s.t2), -limit, limit);
  applyImpulse(s, 1, s.t1, s.lambdaT1 - o1);
  applyImpulse(s, 2, s.t2, s.lambdaT2 - o2);
}

// Shock propagation (Guendelman et al.): after the iterations, one sweep from the bottom of the
// pile up in which each contact treats its lower body as immovable, so a heavy body cannot push
// a light one below it into the ground (the 1000:1 mass-ratio stack). Only the upper body's
// velocity changes; the accumulated impulses keep their clamps.
void World::solveContactShock(SolverContact& s) {
  SolverBody& a = solverBodies_[s.a];
  SolverBody& b = solverBodies_[s.b];
  SolverBody& upper = s.shockLower == 1 ? b : a;
  auto relative = [&] { return Vec3f(a.v + a.w.cross(s.rA) - b.v - b.w.cross(s.rB)); };
  // Impulse along dir on the upper body only (a receives +, b receives -).
  auto push = [&](int d, const Vec3f& dir, float lambda) {
    if (s.shockLower == 1) {
      upper.v -= dir * (lambda * upper.invMass);
      upper.w -= s.angB[d] * lambda;
    } else {
      upper.v += dir * (lambda * upper.invMass);
      upper.w += s.angA[d] * lambda;
    }
  };
  const float oldN = s.lambdaN;
  s.lambdaN = std::max(oldN + s.shockMass[0] * (s.bias - relative().dot(s.normal)), 0.f);
  push(0, s.normal, s.lambdaN - oldN);
  const float limit = s.friction * s.lambdaN;
  const Vec3f v = relative();
  const float o1 = s.lambdaT1, o2 = s.lambdaT2;
  s.lambdaT1 = std::clamp(o1 - s.shockMass[1] * v.dot(s.t1), -limit, limit);
  s.lambdaT2 = std::clamp(o2 - s.shockMass[2] * v.dot(s.t2), -limit, limit);
  push(1, s.t1, s.lambdaT1 - o1);
  push(2, s.t2, s.lambdaT2 - o2);
}

// The island's contacts bottom-up (by the lower body's height, ties by index: deterministic):
// contacts with a static or kinematic body first (they are the ground), then dynamic pairs.
void World::shockSweep(std::vector<uint32_t>& list) {
  std::stable_sort(list.begin(), list.end(), [&](uint32_t x, uint32_t y) {
    const SolverContact& p = contacts_[x];
    const SolverContact& q = contacts_[y];
    if ((p.shockLower == 0) != (q.shockLower == 0)) return p.shockLower == 0;
    return p.height < q.height;
  });
  for (uint32_t k : list) {
    if (contacts_[k].shockLower)
      solveContactShock(contacts_[k]);
    else
      solveContact(contacts_[k], false);  // against the ground (or side by side): a normal update
  }
}

void World::solveIsland(uint32_t island, bool relax) {
  const uint32_t begin = islandStart_[island], end = islandStart_[island + 1];
  if (!relax)
    for (uint32_t k = begin; k < end; ++k) warmStart(contacts_[islandContacts_[k]]);
  const int iterations = relax ? scene_.settings.relaxIterations : scene_.settings.solverIterations;
  for (int it = 0; it < iterations; ++it) {
    // note: sweeps alternate direction (symmetric Gauss-Seidel) so no contact is always solved
    // last; a fixed order makes friction in stacks creep one way.
    for (uint32_t j = begin; j < end; ++j) {
      const uint32_t k = (it & 1) ? end - 1 - (j - begin) : j;
      solveContact(contacts_[islandContacts_[k]], relax);
    }
  }
  if (!relax && scene_.settings.shockPropagation) {
    thread_local std::vector<uint32_t> list;  // note: per worker thread, reused across islands
    list.assign(islandContacts_.begin() + begin, islandContacts_.begin() + end);
    shockSweep(list);
  }
}

// A large island's contacts in colours: no two contacts of a colour share a dynamic body, so a
// colour's contacts can be solved at once on every thread. Greedy in island order (the lowest
// colour free for both bodies), so the colouring is a pure function of the contact list; a
// contact for which all kMaxColours are taken goes to a last, serial group.
void World::colourIsland(uint32_t island) {
  const uint32_t begin = islandStart_[island], end = islandStart_[island + 1];
  colourOf_.resize(end - begin);
  uint32_t used = 0;
  for (uint32_t j = begin; j < end; ++j) {
    const SolverContact& s = contacts_[islandContacts_[j]];
    uint64_t taken = 0;
    for (uint32_t x : {s.a, s.b})
      if (bodies_.motion[x] == MotionType::Dynamic) taken |= bodyColours_[x];
    const uint32_t colour = taken == ~uint64_t(0) ? kMaxColours : uint32_t(std::countr_one(taken));
    if (colour < kMaxColours)
      for (uint32_t x : {s.a, s.b})
        if (bodies_.motion[x] == MotionType::Dynamic) bodyColours_[x] |= uint64_t(1) << colour;
    colourOf_[j - begin] = colour;
    used = std::max(used, colour + 1);
  }
  // Counting sort into colour groups, island order kept within a group.
  colourStart_.assign(used + 1, 0);
  for (uint32_t c : colourOf_) ++colourStart_[c + 1];
  for (uint32_t c = 0; c < used; ++c) colourStart_[c + 1] += colourStart_[c];
  colourContacts_.resize(end - begin);
  std::vector<uint32_t>& fill = colourFill_;
  fill.assign(colourStart_.begin(), colourStart_.end() - 1);
  for (uint32_t j = begin; j < end; ++j) colourContacts_[fill[colourOf_[j - begin]]++] = islandContacts_[j];
  for (uint32_t j = begin; j < end; ++j) {
    const SolverContact& s = contacts_[islandContacts_[j]];
    bodyColours_[s.a] = bodyColours_[s.b] = 0;  // clean for the next island
  }
}

// One big island (a pile) on every thread: colour by colour, each colour's contacts in parallel.
// Iterations alternate the colour order like solveIsland alternates the contact order.
void World::solveIslandInColours(uint32_t island, bool relax) {
  colourIsland(island);
  const uint32_t colours = uint32_t(colourStart_.size() - 1);
  if (!relax)
    for (uint32_t c : colourContacts_) warmStart(contacts_[c]);
  const int iterations = relax ? scene_.settings.relaxIterations : scene_.settings.solverIterations;
  for (int it = 0; it < iterations; ++it) {
    for (uint32_t i = 0; i < colours; ++i) {
      const uint32_t c = (it & 1) ? colours - 1 - i : i;
      const uint32_t b = colourStart_[c], e = colourStart_[c + 1];
      if (c == kMaxColours) {  // the serial group: contacts may share bodies
        for (uint32_t j = b; j < e; ++j) solveContact(contacts_[colourContacts_[j]], relax);
        continue;
      }
      jobs_.parallelFor(b, e, kColourGrain, [&](uint32_t cb, uint32_t ce) {
        ProfileZone zone(profiler_, "colour", stage_ + (relax ? 5 : 3));
        for (uint32_t j = cb; j < ce; ++j) solveContact(contacts_[colourContacts_[j]], relax);
      });
    }
  }
  if (!relax && scene_.settings.shockPropagation) {  // one serial sweep over the whole pile
    std::vector<uint32_t> list(colourContacts_.begin(), colourContacts_.end());
    shockSweep(list);
  }
}

void World::solve(bool relax) {
  // Islands touch disjoint dynamic bodies: solving them in parallel is race-free and gives the
  // same result as solving them one by one. Islands above kSplitContacts are split by colour
  // instead (first, one at a time, each on every thread); which islands are split depends only
  // on their size, so the result does not depend on the thread count.
  const uint32_t islands = uint32_t(islandStart_.size() - 1);
  smallIslands_.clear();
  bodyColours_.resize(bodies_.size(), 0);  // colourIsland() leaves it all zero again
  if (!relax) stats_.largestIsland = 0;
  for (uint32_t i = 0; i < islands; ++i) {
    const uint32_t size = islandStart_[i + 1] - islandStart_[i];
    if (!relax) stats_.largestIsland = std::max(stats_.largestIsland, size);
    if (size > kSplitContacts) {
      solveIslandInColours(i, relax);
      if (!relax) ++stats_.splitIslands;
    } else {
      smallIslands_.push_back(i);
    }
  }
  jobs_.parallelFor(0, uint32_t(smallIslands_.size()), 1, [&](uint32_t b, uint32_t e) {
    ProfileZone zone(profiler_, relax ? "relax" : "island", stage_ + (relax ? 5 : 3));
    for (uint32_t i = b; i < e; ++i) solveIsland(smallIslands_[i], relax);
  });
  if (!relax) return;
  // The final impulses warm-start the next substep.
  nextCache_.clear();
  for (const SolverContact& s : contacts_) nextCache_.push_back({s.key, s.point, s.lambdaN, s.lambdaT1, s.lambdaT2});
  std::stable_sort(nextCache_.begin(), nextCache_.end(), [](const CachedImpulse& x, const CachedImpulse& y) { return x.key < y.key; });
  std::swap(cache_, nextCache_);
}

// Bodies that stay nearly still accumulate still time; an island sleeps when all of its bodies
// have been still for kSleepTime (so a resting pile sleeps together and wakes together).
void World::updateSleep(float dt) {
  if (!scene_.settings.sleeping) return;
  const uint32_t n = bodies_.size();
  for (uint32_t i = 0; i < n; ++i) {
    if (bodies_.motion[i] != MotionType::Dynamic || asleep_[i]) continue;
    const bool still = bodies_.linearVelocity[i].norm() < kSleepLinear && bodies_.angularVelocity[i].norm() < kSleepAngular;
    stillTime_[i] = still ? stillTime_[i] + dt : 0.f;
  }
  // An island may sleep only if every member is ready; islandOf_ holds this substep's roots.
  std::vector<uint8_t> blocked(n, 0);
  auto root = [&](uint32_t x) {
    while (islandOf_[x] != x) x = islandOf_[x];
    return x;
  };
  for (uint32_t i = 0; i < n; ++i)
    if (bodies_.motion[i] == MotionType::Dynamic && !asleep_[i] && stillTime_[i] < kSleepTime) blocked[root(i)] = 1;
  for (uint32_t i = 0; i < n; ++i) {
    if (bodies_.motion[i] != MotionType::Dynamic || asleep_[i] || blocked[root(i)]) continue;
    asleep_[i] = 1;
    bodies_.linearVelocity[i] = Vec3f::Zero();
    bodies_.angularVelocity[i] = Vec3f::Zero();
  }
}

void World::integrate(float dt) {
  for (uint32_t i = 0; i < bodies_.size(); ++i) {
    if (bodies_.motion[i] == MotionType::Static || asleep_[i]) continue;
    bodies_.position[i] += (bodies_.linearVelocity[i] * dt).cast<double>();
    const Vec3f w = bodies_.angularVelocity[i];
    const float angle = w.norm() * dt;
    if (angle > 0) bodies_.rotation[i] = (Quatf(Eigen::AngleAxisf(angle, w / w.norm())) * bodies_.rotation[i]).normalized();
  }
}

void World::substep(float dt, int index) {
  // Stages of successive substeps run one after another: distinct stage ids for work/span.
  // Serial stages record one zone; parallel stages one zone per chunk (the jobs).
  const int stage = index * kStagesPerSubstep;
  stage_ = stage;
  // Gravity on dynamic bodies first (semi-implicit Euler).
  const Vec3f g = scene_.settings.gravity.cast<float>();
  for (uint32_t i = 0; i < bodies_.size(); ++i)
    if (bodies_.motion[i] == MotionType::Dynamic && !asleep_[i]) bodies_.linearVelocity[i] += g * dt;
  auto t = Clock::now();
  {
    ProfileZone z(profiler_, "broadphase", stage + 0);
    computeBounds();
    broadphase_.update(bounds_, isStatic_, pairs_);
  }
  stats_.broadphaseMs += msSince(t);
  t = Clock::now();
  {
    ProfileZone z(profiler_, "contacts (stage)");
    generateContacts(dt);
    terrainPairs(dt);
    updatePairCache();
  }
  stats_.contactsMs += msSince(t);
  t = Clock::now();
  {
    {
      ProfileZone z(profiler_, "prepare solver", stage + 2);
      prepareSolver(dt);
      buildIslands();
    }
    ProfileZone z(profiler_, "solve (stage)");
    loadSolverBodies();
    solve(false);
    storeSolverBodies();
  }
  stats_.solverMs += msSince(t);
  t = Clock::now();
  {
    ProfileZone z(profiler_, "integrate", stage + 4);
    integrate(dt);
  }
  stats_.integrateMs += msSince(t);
  t = Clock::now();
  {
    // Positions moved with the push-out; relaxing the velocities now removes it from what the
    // bodies carry into the next substep.
    ProfileZone z(profiler_, "relax (stage)");
    solve(true);
    storeSolverBodies();
  }
  stats_.solverMs += msSince(t);
  updateSleep(dt);
  stats_.pairs += uint32_t(pairs_.size());
  stats_.contacts += uint32_t(contacts_.size());
  for (const ContactStats& s : pairStats_) {
    if (s.rawContacts == uint32_t(-1)) {
      ++stats_.pairsReused;
      continue;
    }
    stats_.boxTests += s.index.boxTests;
    stats_.narrowphase += s.bricksTested;
  }
}

// The scene's ray load: seeded rays between random points of the grids' bounds, each cast
// against every grid body (in the grid's frame) and keeping the closest hit. One slot per ray,
// so the result does not depend on the thread count. Rays read the world; they change nothing.
void World::fireRays() {
  const RayLoadDescription& load = scene_.rays;
  if (load.count == 0) return;
  const auto t = Clock::now();
  Vec3d lo = Vec3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  std::vector<uint32_t> gridBodies;
  for (uint32_t i = 0; i < bodies_.size(); ++i) {
    if (!bodies_.shape[i].isGrid() || bodies_.motion[i] == MotionType::Dynamic) continue;
    gridBodies.push_back(i);
    lo = lo.cwiseMin(bounds_[i].min);
    hi = hi.cwiseMax(bounds_[i].max);
  }
  if (gridBodies.empty()) return;
  rayHitT_.assign(load.count, std::numeric_limits<float>::infinity());
  rayStats_.assign(load.count, QueryStats{});
  const uint64_t seed = load.seed ^ (uint64_t(frame_) * 0x9E3779B97F4A7C15ull);
  const int stage = scene_.settings.substeps * kStagesPerSubstep;
  jobs_.parallelFor(0, load.count, 64, [&](uint32_t begin, uint32_t end) {
    ProfileZone zone(profiler_, "rays", stage);
    for (uint32_t k = begin; k < end; ++k) {
      SeededRandom r(seed + k);
      const Vec3d from(r.uniform(lo.x(), hi.x()), r.uniform(lo.y(), hi.y()), r.uniform(lo.z(), hi.z()));
      const Vec3d to(r.uniform(lo.x(), hi.x()), r.uniform(lo.y(), hi.y()), r.uniform(lo.z(), hi.z()));
      const double span = (to - from).norm();
      if (span == 0) continue;
      const Vec3d dir = (to - from) / span;
      const double length = load.length > 0 ? double(load.length) : (hi - lo).norm();
      for (uint32_t body : gridBodies) {
        const RigidTransform pose = bodies_.shapePose(body);
        const Ray ray = Ray::make(pose.pointToLocal(from), pose.directionToLocal(Vec3f(dir.cast<float>())),
                                  std::min(float(length), rayHitT_[k]));
        const GridRayHit hit = grids_[bodies_.shape[body].grid]->raycast(ray, ~0u, &rayStats_[k]);
        if (hit.hit()) rayHitT_[k] = hit.t;
      }
    }
  });
  stats_.rays = load.count;
  for (uint32_t k = 0; k < load.count; ++k) {
    stats_.rayHits += std::isfinite(rayHitT_[k]) ? 1u : 0u;
    stats_.rayBoxTests += rayStats_[k].boxTests;
  }
  stats_.raysMs = msSince(t);
}

// After grid edits: bodies resting on an edited grid wake up (a removed brick must let them
// fall), and the pair cache forgets every pair with an edited grid (its cached contacts may
// belong to a brick that is gone).
void World::applyGridEdits() {
  if (editedGrids_.empty()) return;
  std::vector<uint8_t> edited(grids_.size(), 0);
  for (uint32_t g : editedGrids_) edited[g] = 1;
  editedGrids_.clear();
  auto usesEdited = [&](uint32_t body) { return bodies_.shape[body].isGrid() && edited[bodies_.shape[body].grid]; };
  for (const BodyPair& p : pairs_) {
    if (!usesEdited(p.a) && !usesEdited(p.b)) continue;
    for (uint32_t x : {p.a, p.b}) {
      asleep_[x] = 0;
      stillTime_[x] = 0.f;
    }
  }
  std::erase_if(pairCache_, [&](const PairCacheEntry& e) { return usesEdited(e.pair.a) || usesEdited(e.pair.b); });
}

void World::step() {
  const auto t = Clock::now();
  stats_ = StepStats{};
  applyGridEdits();
  profiler_.beginFrame(frame_);
  const float dt = float(scene_.settings.timestep / scene_.settings.substeps);
  for (int s = 0; s < scene_.settings.substeps; ++s) substep(dt, s);
  {
    ProfileZone z(profiler_, "rays (stage)");
    fireRays();
  }
  profiler_.endFrame();
  stats_.totalMs = msSince(t);
  ++frame_;
}

uint64_t World::stateHash() const {
  uint64_t h = 0;
  for (uint32_t i = 0; i < bodies_.size(); ++i) {
    for (int k = 0; k < 3; ++k) h = hashCombine(h, bitsOf(bodies_.position[i][k]));
    for (int k = 0; k < 4; ++k) h = hashCombine(h, bitsOf(bodies_.rotation[i].coeffs()[k]));
    for (int k = 0; k < 3; ++k) h = hashCombine(hashCombine(h, bitsOf(bodies_.linearVelocity[i][k])), bitsOf(bodies_.angularVelocity[i][k]));
  }
  return h;
}

double World::energy() const {
  double e = 0;
  const Vec3d g = scene_.settings.gravity;
  for (uint32_t i = 0; i < bodies_.size(); ++i) {
    if (bodies_.motion[i] != MotionType::Dynamic) continue;
    const double m = 1.0 / bodies_.inverseMass[i];
    const Vec3f wl = bodies_.rotation[i].conjugate() * bodies_.angularVelocity[i];
    e += 0.5 * m * bodies_.linearVelocity[i].squaredNorm();
    e += 0.5 * double(wl.cwiseProduct(wl).dot(bodies_.inverseInertia[i].cwiseInverse()));
    e -= m * g.dot(bodies_.position[i]);
  }
  return e;
}

}  // namespace bw
