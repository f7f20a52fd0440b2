#include "world/bullet_baseline.h"

#include <BulletDynamics/ConstraintSolver/btContactSolverInfo.h>
#include <LinearMath/btTransformUtil.h>
#include <btBulletDynamicsCommon.h>
#include <chrono>
#include <cmath>
#include <limits>
#include <vector>

#include "collision/bricks/bullet_brick_shapes.h"
#include "collision/core/errors.h"
#include "world/scene_file.h"
#include "world/world_tuning.h"

namespace bw {

const char* bulletSetupName(BulletSetup setup) { return setup == BulletSetup::Expert ? "expert" : "naive"; }

struct BulletBaseline::Impl {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &config};
  BulletBrickShapes brickShapes;                         // expert: shared per distinct brick
  std::vector<std::vector<BulletBrickChunk>> gridChunks; // expert: per World grid, shared by its bodies
  std::vector<std::unique_ptr<btCollisionShape>> shapes; // primitives, naive boxes
  std::vector<std::unique_ptr<btCompoundShape>> compounds;
  std::vector<std::unique_ptr<btCollisionObject>> chunkObjects;  // expert: static grids' chunks
  std::vector<std::unique_ptr<btDefaultMotionState>> motionStates;
  std::vector<std::unique_ptr<btRigidBody>> bodies;      // per World body; null for a static chunked grid
  std::vector<Vec3d> staticPosition;                     // per World body: where a static one stays
  std::vector<Quatf> staticRotation;
  std::vector<uint8_t> dynamic;
  std::vector<uint32_t> kinematic;                       // World ids of kinematic bodies
  RayLoadDescription rays;
  Vec3d rayLo = Vec3d::Zero(), rayHi = Vec3d::Zero();
  uint32_t frame = 0, lastRayHits = 0;
  double timestep = 1.0 / 60;
  int substeps = 1;
  ~Impl() {
    for (auto& b : bodies)
      if (b) world.removeRigidBody(b.get());
    for (auto& o : chunkObjects) world.removeCollisionObject(o.get());
  }
};

namespace {
btVector3 bt(const Vec3f& v) { return {v.x(), v.y(), v.z()}; }
btVector3 bt(const Vec3d& v) { return {btScalar(v.x()), btScalar(v.y()), btScalar(v.z())}; }
btQuaternion bt(const Quatf& q) { return {q.x(), q.y(), q.z(), q.w()}; }
btTransform bt(const RigidTransform& t) { return btTransform(bt(t.rotation), bt(t.translation)); }

/// One btCompoundShape of every brick as its box (the naive setup).
std::unique_ptr<btCompoundShape> naiveCompound(const BrickGrid& grid, std::vector<std::unique_ptr<btCollisionShape>>& shapes) {
  auto compound = std::make_unique<btCompoundShape>(true, int(grid.brickCount()));
  grid.forEachBrick([&](uint32_t id) {
    const Brick& br = grid.brick(id);
    shapes.push_back(std::make_unique<btBoxShape>(bt(br.rotation.applyToExtent(br.halfSize))));
    compound->addChildShape(btTransform(btQuaternion::getIdentity(), bt(br.position)), shapes.back().get());
  });
  return compound;
}
}  // namespace

void BulletBaseline::requireMirrorable(const SceneDescription& scene) {
  if (!scene.terrains.empty())
    throw SceneError(scene.source + ": the Bullet baseline mirrors grids and primitives, not voxel terrain ('" + scene.terrains[0].name +
                     "'); run this scene with --engine brickworld");
}

BulletBaseline::BulletBaseline(const World& w, BulletSetup setup, float chunkSize) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  const SceneDescription& scene = w.scene();
  requireMirrorable(scene);
  if (!(chunkSize > 0) || !std::isfinite(chunkSize))
    throw InvalidInput("BulletBaseline: chunk size must be positive and finite (got " + std::to_string(chunkSize) + ")");
  const bool expert = setup == BulletSetup::Expert;
  const SceneSettings& s = scene.settings;
  m.world.setGravity(bt(s.gravity));
  btContactSolverInfo& info = m.world.getSolverInfo();
  info.m_numIterations = s.solverIterations;
  if (expert) {
    info.m_splitImpulse = 1;
    info.m_restitutionVelocityThreshold = tuning::kBounceThreshold;
    m.world.setForceUpdateAllAabbs(false);  // static chunks' boxes are never recomputed
  }
  m.timestep = s.timestep;
  m.substeps = s.substeps;
  m.rays = scene.rays;
  const BodyStore& b = w.bodies();
  const auto t = std::chrono::steady_clock::now();
  // Bullet multiplies the two objects' coefficients; ours is sqrt(fa fb) (world_tuning.h).
  auto friction = [&](float f) { return expert ? std::sqrt(f) : f; };
  const float restitution = expert ? std::sqrt(tuning::kRestitution) : 0.f;
  std::vector<btCollisionShape*> naiveShape;
  m.bodies.resize(b.size());
  m.dynamic.assign(b.size(), 0);
  m.staticPosition = b.position;
  m.staticRotation = b.rotation;
  bool anyRayGrid = false;
  m.rayLo = Vec3d::Constant(std::numeric_limits<double>::infinity());
  m.rayHi = -m.rayLo;
  for (uint32_t i = 0; i < b.size(); ++i) {
    const Depenetration* out = w.depenetration(i);  // mirrored as the dynamic body it was spawned as
    const MotionType motion = out ? MotionType::Dynamic : b.motion[i];
    const bool isGrid = b.shape[i].isGrid();
    if (isGrid && motion != MotionType::Dynamic) {
      // The ray load spans the static and kinematic grids' broadphase boxes (ray_load.h).
      const WorldAabb box = w.broadphaseBounds(i);
      m.rayLo = m.rayLo.cwiseMin(box.min);
      m.rayHi = m.rayHi.cwiseMax(box.max);
      anyRayGrid = true;
    }
    btCollisionShape* shape = nullptr;
    if (isGrid) {
      const uint32_t g = b.shape[i].grid;
      const btTransform shapeFrame = bt(b.shapeFromBody[i]);
      if (expert) {
        if (m.gridChunks.size() <= g) m.gridChunks.resize(g + 1);
        if (m.gridChunks[g].empty()) m.gridChunks[g] = buildBulletChunks(w.grid(g), chunkSize, m.brickShapes);
        if (motion == MotionType::Static) {
          // One static object per chunk: a pair walks one chunk's children, not the grid's.
          const btTransform pose = bt(b.shapePose(i));
          for (const BulletBrickChunk& c : m.gridChunks[g]) {
            auto o = std::make_unique<btCollisionObject>();
            o->setCollisionShape(c.shape.get());
            o->setWorldTransform(pose * btTransform(btQuaternion::getIdentity(), bt(c.origin)));
            o->setFriction(friction(b.friction[i]));
            o->setRestitution(restitution);
            m.world.addCollisionObject(o.get(), btBroadphaseProxy::StaticFilter, btBroadphaseProxy::AllFilter ^ btBroadphaseProxy::StaticFilter);
            m.chunkObjects.push_back(std::move(o));
          }
          continue;
        }
        // A moving grid: one body whose compound holds its chunk compounds.
        auto parent = std::make_unique<btCompoundShape>(true, int(m.gridChunks[g].size()));
        for (const BulletBrickChunk& c : m.gridChunks[g])
          parent->addChildShape(shapeFrame * btTransform(btQuaternion::getIdentity(), bt(c.origin)), c.shape.get());
        shape = parent.get();
        m.compounds.push_back(std::move(parent));
      } else {
        if (naiveShape.size() <= g) naiveShape.resize(g + 1, nullptr);
        if (!naiveShape[g]) {
          m.compounds.push_back(naiveCompound(w.grid(g), m.shapes));
          naiveShape[g] = m.compounds.back().get();
        }
        shape = naiveShape[g];
        if (!shapeFrame.getOrigin().isZero() || shapeFrame.getRotation() != btQuaternion::getIdentity()) {
          // Dynamic grids: the body frame is the centre of mass; wrap the compound at its offset.
          auto wrapper = std::make_unique<btCompoundShape>(false, 1);
          wrapper->addChildShape(shapeFrame, shape);
          shape = wrapper.get();
          m.compounds.push_back(std::move(wrapper));
        }
      }
    } else {
      const QueryShape& q = b.shape[i].primitive;
      if (q.kind == QueryShape::Kind::Sphere) m.shapes.push_back(std::make_unique<btSphereShape>(q.radius));
      else if (q.kind == QueryShape::Kind::Capsule) m.shapes.push_back(std::make_unique<btCapsuleShapeZ>(q.radius, 2 * q.halfHeight));
      else m.shapes.push_back(std::make_unique<btBoxShape>(bt(q.halfExtents)));
      shape = m.shapes.back().get();
    }
    const bool dyn = motion == MotionType::Dynamic;
    const float inverseMass = out ? out->inverseMass : b.inverseMass[i];
    const Vec3f inverseInertia = out ? out->inverseInertia : b.inverseInertia[i];
    const float mass = dyn ? 1.f / inverseMass : 0.f;
    const btVector3 inertia = dyn ? bt(Vec3f(inverseInertia.cwiseInverse())) : btVector3(0, 0, 0);
    m.motionStates.push_back(std::make_unique<btDefaultMotionState>(btTransform(bt(b.rotation[i]), bt(b.position[i]))));
    btRigidBody::btRigidBodyConstructionInfo ci(mass, m.motionStates.back().get(), shape, inertia);
    ci.m_friction = friction(b.friction[i]);
    ci.m_restitution = restitution;
    m.bodies[i] = std::make_unique<btRigidBody>(ci);
    btRigidBody* body = m.bodies[i].get();
    body->setLinearVelocity(bt(out ? out->baseVelocity : b.linearVelocity[i]));
    body->setAngularVelocity(bt(b.angularVelocity[i]));
    if (motion == MotionType::Kinematic) {
      body->setCollisionFlags(body->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
      body->setActivationState(DISABLE_DEACTIVATION);
      m.kinematic.push_back(i);
    }
    if (dyn && !s.sleeping) body->setActivationState(DISABLE_DEACTIVATION);
    if (dyn && expert && !isGrid) {
      const QueryShape& q = b.shape[i].primitive;
      const float smallest = q.kind == QueryShape::Kind::Box ? q.halfExtents.minCoeff() : q.radius;
      body->setCcdMotionThreshold(smallest);
      body->setCcdSweptSphereRadius(0.4f * smallest);
      if (q.kind != QueryShape::Kind::Box)
        // Bullet's limit is rolling x the other's friction x the normal impulse; ours is
        // rollingResistance x radius x the normal impulse against bricks of default friction.
        body->setRollingFriction(s.rollingResistance * q.radius / std::sqrt(tuning::kDefaultFriction));
    }
    m.world.addRigidBody(body);
    m.dynamic[i] = dyn;
  }
  m.broadphase.optimize();  // the static chunks' tree built top-down once, as a user does after loading
  if (!anyRayGrid) m.rays.count = 0;
  buildSeconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

BulletBaseline::~BulletBaseline() = default;

void BulletBaseline::step() {
  Impl& m = *impl_;
  // Kinematic bodies: their end-of-frame pose through the motion state, as a Bullet user moves
  // them (Bullet derives their velocity from it for the contacts).
  for (uint32_t i : m.kinematic) {
    btRigidBody& body = *m.bodies[i];
    btTransform next;
    btTransformUtil::integrateTransform(body.getWorldTransform(), body.getLinearVelocity(), body.getAngularVelocity(),
                                        btScalar(m.timestep), next);
    static_cast<btDefaultMotionState*>(body.getMotionState())->setWorldTransform(next);
  }
  m.world.stepSimulation(btScalar(m.timestep), m.substeps, btScalar(m.timestep / m.substeps));
  m.lastRayHits = 0;
  for (uint32_t k = 0; k < m.rays.count; ++k) {
    const LoadRay r = RayLoad::makeRay(m.rays, m.frame, k, m.rayLo, m.rayHi);
    if (r.length == 0) continue;
    const btVector3 from = bt(r.from), to = bt(Vec3d(r.from + r.direction * r.length));
    btCollisionWorld::ClosestRayResultCallback hit(from, to);
    hit.m_collisionFilterMask = btBroadphaseProxy::StaticFilter;  // the static and kinematic grids, as ours
    m.world.rayTest(from, to, hit);
    m.lastRayHits += hit.hasHit() ? 1u : 0u;
  }
  ++m.frame;
}

BulletFrame BulletBaseline::lastFrame() const {
  BulletFrame f;
  btDispatcher* d = impl_->world.getDispatcher();
  for (int i = 0; i < d->getNumManifolds(); ++i) {
    const btPersistentManifold* pm = d->getManifoldByIndexInternal(i);
    f.contacts += uint32_t(pm->getNumContacts());
    for (int k = 0; k < pm->getNumContacts(); ++k) f.deepest = std::max(f.deepest, -float(pm->getContactPoint(k).getDistance()));
  }
  f.rays = impl_->rays.count;
  f.rayHits = impl_->lastRayHits;
  return f;
}

uint32_t BulletBaseline::chunkObjects() const { return uint32_t(impl_->chunkObjects.size()); }
size_t BulletBaseline::distinctBrickShapes() const { return impl_->brickShapes.distinctShapes(); }

void BulletBaseline::poses(std::vector<Vec3d>& positions, std::vector<Quatf>& rotations) const {
  const Impl& m = *impl_;
  positions = m.staticPosition;
  rotations = m.staticRotation;
  for (size_t i = 0; i < m.bodies.size(); ++i) {
    if (!m.bodies[i]) continue;
    const btTransform& t = m.bodies[i]->getWorldTransform();
    const btVector3& p = t.getOrigin();
    const btQuaternion q = t.getRotation();
    positions[i] = Vec3d(p.x(), p.y(), p.z());
    rotations[i] = Quatf(q.w(), q.x(), q.y(), q.z()).normalized();
  }
}

void BulletBaseline::restingReport(uint32_t& resting, uint32_t& moving, double& lowestZ) const {
  resting = moving = 0;
  lowestZ = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < impl_->bodies.size(); ++i) {
    if (!impl_->dynamic[i]) continue;
    const btRigidBody& b = *impl_->bodies[i];
    (b.getLinearVelocity().length() < 0.05f ? resting : moving)++;
    lowestZ = std::min(lowestZ, double(b.getWorldTransform().getOrigin().z()));
  }
}

}  // namespace bw
