#include "world/bullet_baseline.h"

#include <BulletDynamics/ConstraintSolver/btContactSolverInfo.h>
#include <LinearMath/btTransformUtil.h>
#include <btBulletDynamicsCommon.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <vector>

#include "collision/bricks/bullet_brick_shapes.h"
#include "collision/bricks/bullet_chunked_grid.h"
#include "collision/core/errors.h"
#include "world/scene_file.h"
#include "world/world_tuning.h"

namespace bw {

const char* bulletSetupName(BulletSetup setup) { return setup == BulletSetup::Expert ? "expert" : "naive"; }

const char* kinematicGridsName(KinematicGrids k) {
  return k == KinematicGrids::Auto ? "auto" : k == KinematicGrids::Compound ? "compound" : "chunks";
}

KinematicGrids kinematicGridsFromName(const std::string& name) {
  if (name == "auto") return KinematicGrids::Auto;
  if (name == "compound") return KinematicGrids::Compound;
  if (name == "chunks") return KinematicGrids::ChunkBodies;
  throw InvalidInput("kinematic grids must be auto, compound or chunks (got '" + name + "')");
}

struct BulletBaseline::Impl {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &config};
  BulletBrickShapes brickShapes;                         // expert: shared per distinct brick
  std::vector<std::unique_ptr<BulletChunkedGrid>> grids; // expert: per World grid, shared by its bodies
  // Expert: what holds a grid's chunks. ObjectHolder: one object per chunk (null while the
  // chunk is empty or after an edit emptied it): static objects for a static grid body, kinematic
  // bodies moved with the grid's pose each frame for a kinematic one (KinematicGrids::ChunkBodies).
  // CompoundHolder: a body whose parent compound holds one child per non-empty chunk (slot -1:
  // none), for dynamic grids and compound kinematic ones.
  struct ObjectHolder {
    uint32_t grid;
    btTransform pose;                         // the grid's shape pose (kinematic: now)
    float friction;
    std::vector<btCollisionObject*> objects;  // per chunk
    bool kinematic = false;
    uint32_t body = 0;                        // kinematic: the World body, its pose and motion
    btTransform bodyPose, shapeFrame;
    btVector3 linearVelocity, angularVelocity;
  };
  struct CompoundHolder {
    uint32_t grid, body;
    btCompoundShape* parent;
    btTransform shapeFrame;
    std::vector<int> slot;
  };
  std::vector<ObjectHolder> objectHolders;
  std::vector<CompoundHolder> compoundHolders;
  std::vector<std::unique_ptr<btCollisionShape>> shapes; // primitives, naive boxes
  std::vector<std::unique_ptr<btCompoundShape>> compounds;
  std::vector<std::unique_ptr<btCollisionObject>> chunkObjects;  // expert: chunk objects and bodies (owned; in the world or not)
  float chunkSize = 16.f, restitution = 0.f;
  bool expert = true;
  uint32_t liveChunkObjects = 0;
  double editSeconds = 0;                                // the last applyEdits()
  uint32_t partsMade = 0;
  bool anyAsleep = false;                                // during applyEdits(): a dynamic body sleeps (else nothing to wake)
  KinematicGrids kinematicGrids = KinematicGrids::Compound;
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
    for (auto& o : chunkObjects)
      if (o->getBroadphaseHandle()) world.removeCollisionObject(o.get());
  }
  float friction(float f) const { return expert ? std::sqrt(f) : f; }  // Bullet multiplies the two objects' (world_tuning.h)
  void addChunkObject(ObjectHolder& h, uint32_t chunk);
  void refreshChunk(ObjectHolder& h, uint32_t chunk);
  void refreshChunk(CompoundHolder& h, uint32_t chunk);
  btCompoundShape* movingGridShape(uint32_t body, uint32_t grid, const btTransform& shapeFrame);
  btRigidBody* addBody(uint32_t body, btCollisionShape* shape, float mass, const btVector3& inertia, float friction,
                       const btTransform& pose);
  void wakeAround(const btVector3& lo, const btVector3& hi);
  static void setChildBox(btCompoundShape& parent, int slot, const btTransform& child);
  void growParentBox(btCompoundShape& parent, const std::vector<uint32_t>& touched, const CompoundHolder& h);
  void refreshGridBodyMass(CompoundHolder& h, const World& judge);
  void addPartBody(const World& judge, const SplitEdit& split);
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

void BulletBaseline::Impl::addChunkObject(ObjectHolder& h, uint32_t chunk) {
  const BulletBrickChunk& c = grids[h.grid]->chunks()[chunk];
  if (c.bricks == 0) return;
  const btTransform pose = h.pose * btTransform(btQuaternion::getIdentity(), bt(c.origin));
  std::unique_ptr<btCollisionObject> o;
  if (h.kinematic) {
    motionStates.push_back(std::make_unique<btDefaultMotionState>(pose));
    btRigidBody::btRigidBodyConstructionInfo ci(0.f, motionStates.back().get(), c.shape.get());
    auto body = std::make_unique<btRigidBody>(ci);
    body->setCollisionFlags(body->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
    body->setActivationState(DISABLE_DEACTIVATION);
    o = std::move(body);
  } else {
    o = std::make_unique<btCollisionObject>();
    o->setCollisionShape(c.shape.get());
    o->setWorldTransform(pose);
  }
  o->setFriction(h.friction);
  o->setRestitution(restitution);
  if (h.kinematic) world.addRigidBody(static_cast<btRigidBody*>(o.get()));  // in the static group, as any kinematic body
  else world.addCollisionObject(o.get(), btBroadphaseProxy::StaticFilter, btBroadphaseProxy::AllFilter ^ btBroadphaseProxy::StaticFilter);
  h.objects[chunk] = o.get();
  chunkObjects.push_back(std::move(o));
  ++liveChunkObjects;
}

btCompoundShape* BulletBaseline::Impl::movingGridShape(uint32_t body, uint32_t grid, const btTransform& shapeFrame) {
  // A moving grid: one body whose compound holds its chunk compounds.
  const std::vector<BulletBrickChunk>& chunks = grids[grid]->chunks();
  auto parent = std::make_unique<btCompoundShape>(true, int(chunks.size()));
  CompoundHolder h{grid, body, parent.get(), shapeFrame, std::vector<int>(chunks.size(), -1)};
  for (uint32_t c = 0; c < chunks.size(); ++c) {
    if (chunks[c].bricks == 0) continue;
    h.slot[c] = parent->getNumChildShapes();
    parent->addChildShape(shapeFrame * btTransform(btQuaternion::getIdentity(), bt(chunks[c].origin)), chunks[c].shape.get());
  }
  compoundHolders.push_back(std::move(h));
  compounds.push_back(std::move(parent));
  return compounds.back().get();
}

btRigidBody* BulletBaseline::Impl::addBody(uint32_t i, btCollisionShape* shape, float mass, const btVector3& inertia, float f,
                                           const btTransform& pose) {
  motionStates.push_back(std::make_unique<btDefaultMotionState>(pose));
  btRigidBody::btRigidBodyConstructionInfo ci(mass, motionStates.back().get(), shape, inertia);
  ci.m_friction = f;
  ci.m_restitution = restitution;
  if (bodies.size() <= i) bodies.resize(i + 1);
  bodies[i] = std::make_unique<btRigidBody>(ci);
  return bodies[i].get();
}

// An edited chunk held as an object of its own: a static object's broadphase box refreshed
// (Bullet keeps static boxes as they were; a kinematic body's is taken each step), the object
// taken out when the chunk emptied, made when it was new.
void BulletBaseline::Impl::refreshChunk(ObjectHolder& h, uint32_t chunk) {
  if (h.objects.size() <= chunk) h.objects.resize(grids[h.grid]->chunks().size(), nullptr);
  btCollisionObject* o = h.objects[chunk];
  const bool empty = grids[h.grid]->chunks()[chunk].bricks == 0;
  if (!o) {
    addChunkObject(h, chunk);
  } else if (empty) {
    world.removeCollisionObject(o);
    h.objects[chunk] = nullptr;
    --liveChunkObjects;
  } else if (!h.kinematic) {
    world.updateSingleAabb(o);  // (a kinematic body's box is taken each step)
  }
  if (btCollisionObject* now = h.objects[chunk] ? h.objects[chunk] : o; now && anyAsleep) {
    btVector3 lo, hi;
    now->getCollisionShape()->getAabb(now->getWorldTransform(), lo, hi);
    wakeAround(lo, hi);
  }
}

// An edited chunk of a moving grid: its child entry in the parent compound refreshed (the
// parent's tree holds the child's box), added when new, removed when the chunk emptied (Bullet
// moves the parent's last child into the slot).
void BulletBaseline::Impl::refreshChunk(CompoundHolder& h, uint32_t chunk) {
  const std::vector<BulletBrickChunk>& chunks = grids[h.grid]->chunks();
  if (h.slot.size() <= chunk) h.slot.resize(chunks.size(), -1);
  const BulletBrickChunk& c = chunks[chunk];
  const btTransform child = h.shapeFrame * btTransform(btQuaternion::getIdentity(), bt(c.origin));
  int& slot = h.slot[chunk];
  if (c.bricks == 0) {
    if (slot < 0) return;
    const int last = h.parent->getNumChildShapes() - 1;
    const auto* moved = static_cast<const btCompoundShape*>(h.parent->getChildShape(last));
    h.parent->removeChildShapeByIndex(slot);
    if (slot != last)
      for (uint32_t k = 0; k < chunks.size(); ++k)
        if (chunks[k].shape.get() == moved) h.slot[k] = slot;
    slot = -1;
  } else if (slot < 0) {
    slot = h.parent->getNumChildShapes();
    h.parent->addChildShape(child, c.shape.get());
  } else {
    setChildBox(*h.parent, slot, child);
  }
  if (!anyAsleep) return;
  btVector3 lo, hi;
  c.shape->getAabb(bodies[h.body]->getWorldTransform() * child, lo, hi);
  wakeAround(lo, hi);
}

// A parent compound's child moved or changed its box, its slot unchanged: its transform and its
// leaf in the parent's tree set, as updateChildTransform() does but without raising the
// compound's revision. note: a revision change makes every pair with the parent drop and remake
// its child algorithm per child (btCompoundCollisionAlgorithm), which for a 3000-chunk ship and
// 2000 crates is most of a frame; an expert edits the tree leaf alone, as the child's index
// (what the pair's algorithms are keyed by) has not changed.
void BulletBaseline::Impl::setChildBox(btCompoundShape& parent, int slot, const btTransform& child) {
  btCompoundShapeChild& entry = parent.getChildList()[slot];
  entry.m_transform = child;
  btVector3 lo, hi;
  entry.m_childShape->getAabb(child, lo, hi);
  btDbvtVolume box = btDbvtVolume::FromMM(lo, hi);
  parent.getDynamicAabbTree()->update(entry.m_node, box);
}

// The parent's own box again when a child's box left it (its growth is what the broadphase
// must see; a box that shrank inside it only stays loose).
void BulletBaseline::Impl::growParentBox(btCompoundShape& parent, const std::vector<uint32_t>& touched, const CompoundHolder& h) {
  btVector3 lo, hi;
  parent.getAabb(btTransform::getIdentity(), lo, hi);
  const std::vector<BulletBrickChunk>& chunks = grids[h.grid]->chunks();
  for (uint32_t c : touched) {
    if (h.slot[c] < 0) continue;
    btVector3 clo, chi;
    chunks[c].shape->getAabb(parent.getChildTransform(h.slot[c]), clo, chi);
    if (clo.x() < lo.x() || clo.y() < lo.y() || clo.z() < lo.z() || chi.x() > hi.x() || chi.y() > hi.y() || chi.z() > hi.z()) {
      parent.recalculateLocalAabb();
      return;
    }
  }
}

// Bodies whose broadphase box meets an edited chunk's wake up (a sleeping body resting on a
// removed brick must fall), as a Bullet user wakes them after editing a shape.
void BulletBaseline::Impl::wakeAround(const btVector3& lo, const btVector3& hi) {
  struct Wake : btBroadphaseAabbCallback {
    bool process(const btBroadphaseProxy* proxy) override {
      if (btRigidBody* b = btRigidBody::upcast(static_cast<btCollisionObject*>(proxy->m_clientObject)))
        if (!b->isStaticOrKinematicObject()) b->activate();
      return true;
    }
  } wake;
  broadphase.aabbTest(lo, hi, wake);
}

// A dynamic grid body after its grid was edited: mass, centre of mass and inertia as the judge
// computed them (exact, from the grid's running sums, as an expert keeps them too), the body
// frame moved to the new centre at that point's velocity, every chunk child moved with it.
void BulletBaseline::Impl::refreshGridBodyMass(CompoundHolder& h, const World& judge) {
  const BodyStore& b = judge.bodies();
  const uint32_t i = h.body;
  btRigidBody& body = *bodies[i];
  const btTransform pose(bt(b.rotation[i]), bt(b.position[i]));
  const btVector3 v = body.getVelocityInLocalPoint(pose.getOrigin() - body.getCenterOfMassPosition());
  h.shapeFrame = bt(b.shapeFromBody[i]);
  const std::vector<BulletBrickChunk>& chunks = grids[h.grid]->chunks();
  for (uint32_t c = 0; c < chunks.size(); ++c)
    if (h.slot[c] >= 0) setChildBox(*h.parent, h.slot[c], h.shapeFrame * btTransform(btQuaternion::getIdentity(), bt(chunks[c].origin)));
  h.parent->recalculateLocalAabb();
  body.setCenterOfMassTransform(pose);
  body.getMotionState()->setWorldTransform(pose);
  body.setMassProps(1.f / b.inverseMass[i], bt(Vec3f(b.inverseInertia[i].cwiseInverse())));
  body.updateInertiaTensor();
  body.setLinearVelocity(v);
  body.activate();
}

// A part split off a grid: its chunks built from the judge's new grid (as a Bullet user's own
// split would build them), a dynamic body with the judge's exact mass, moving as that point of
// the grid's body did (v + w x r; a static grid's parts start at rest).
void BulletBaseline::Impl::addPartBody(const World& judge, const SplitEdit& split) {
  const BodyStore& b = judge.bodies();
  const uint32_t i = split.body;
  if (grids.size() <= split.grid) grids.resize(split.grid + 1);
  grids[split.grid] = std::make_unique<BulletChunkedGrid>(judge.grid(split.grid), chunkSize, brickShapes);
  btVector3 v(0, 0, 0), w(0, 0, 0);
  for (const CompoundHolder& h : compoundHolders)
    if (h.grid == split.fromGrid) {
      const btRigidBody& from = *bodies[h.body];
      v = from.getVelocityInLocalPoint(bt(b.position[i]) - from.getCenterOfMassPosition());
      w = from.getAngularVelocity();
    }
  for (const ObjectHolder& h : objectHolders)
    if (h.kinematic && h.grid == split.fromGrid) {  // a kinematic grid turns about its origin, its position
      w = h.angularVelocity;
      v = h.linearVelocity + w.cross(bt(b.position[i]) - h.bodyPose.getOrigin());
    }
  if (bodies.size() <= i) bodies.resize(i + 1);
  const size_t n = b.size();
  staticPosition.resize(n, b.position[i]);
  staticRotation.resize(n, b.rotation[i]);
  dynamic.resize(n, 0);
  btCompoundShape* shape = movingGridShape(i, split.grid, bt(b.shapeFromBody[i]));
  btRigidBody* body = addBody(i, shape, 1.f / b.inverseMass[i], bt(Vec3f(b.inverseInertia[i].cwiseInverse())), friction(b.friction[i]),
                              btTransform(bt(b.rotation[i]), bt(b.position[i])));
  body->setLinearVelocity(v);
  body->setAngularVelocity(w);
  if (!judge.scene().settings.sleeping) body->setActivationState(DISABLE_DEACTIVATION);
  world.addRigidBody(body);
  dynamic[i] = 1;
  ++partsMade;
}

void BulletBaseline::requireMirrorable(const SceneDescription& scene, BulletSetup setup) {
  if (!scene.terrains.empty())
    throw SceneError(scene.source + ": the Bullet baseline mirrors grids and primitives, not voxel terrain ('" + scene.terrains[0].name +
                     "'); run this scene with --engine brickworld");
  const bool splits = std::any_of(scene.grids.begin(), scene.grids.end(), [](const GridDescription& g) { return g.split; });
  if (setup == BulletSetup::Naive && (!scene.edits.empty() || splits))
    throw SceneError(scene.source + ": the naive Bullet baseline (one compound per grid) does not mirror edits or splits; use --engine bullet");
}

BulletBaseline::BulletBaseline(const World& w, BulletSetup setup, float chunkSize, KinematicGrids kinematic)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  const SceneDescription& scene = w.scene();
  requireMirrorable(scene, setup);
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
  m.expert = expert;
  if (kinematic == KinematicGrids::Auto) {
    uint32_t dynamicBodies = 0;
    for (uint32_t i = 0; i < w.bodies().size(); ++i) dynamicBodies += w.bodies().motion[i] == MotionType::Dynamic ? 1u : 0u;
    kinematic = dynamicBodies >= kChunkBodiesFrom ? KinematicGrids::ChunkBodies : KinematicGrids::Compound;
  }
  m.kinematicGrids = kinematic;
  m.chunkSize = chunkSize;
  m.restitution = expert ? std::sqrt(tuning::kRestitution) : 0.f;
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
        if (m.grids.size() <= g) m.grids.resize(g + 1);
        if (!m.grids[g]) m.grids[g] = std::make_unique<BulletChunkedGrid>(w.grid(g), chunkSize, m.brickShapes);
        if (motion == MotionType::Static || (motion == MotionType::Kinematic && kinematic == KinematicGrids::ChunkBodies)) {
          // One object per chunk: a pair walks one chunk's children, not the grid's. A
          // kinematic grid's chunks as kinematic bodies moved together (KinematicGrids).
          Impl::ObjectHolder& h = m.objectHolders.emplace_back();
          h.grid = g;
          h.pose = bt(b.shapePose(i));
          h.friction = m.friction(b.friction[i]);
          if (motion == MotionType::Kinematic) {
            h.kinematic = true;
            h.body = i;
            h.bodyPose = btTransform(bt(b.rotation[i]), bt(b.position[i]));
            h.shapeFrame = shapeFrame;
            h.linearVelocity = bt(b.linearVelocity[i]);
            h.angularVelocity = bt(b.angularVelocity[i]);
          }
          h.objects.assign(m.grids[g]->chunks().size(), nullptr);
          for (uint32_t c = 0; c < h.objects.size(); ++c) m.addChunkObject(h, c);
          continue;
        }
        shape = m.movingGridShape(i, g, shapeFrame);
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
    btRigidBody* body = m.addBody(i, shape, mass, inertia, m.friction(b.friction[i]), btTransform(bt(b.rotation[i]), bt(b.position[i])));
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

void BulletBaseline::applyEdits(const World& judge) {
  Impl& m = *impl_;
  const EditLog& log = judge.lastEdits();
  m.editSeconds = 0;
  if (log.bricks.empty() && log.splits.empty()) return;
  if (!m.expert) throw SceneError(judge.scene().source + ": the naive Bullet baseline does not mirror edits; use --engine bullet");
  const auto t = std::chrono::steady_clock::now();
  // Waking is a broadphase query per edited chunk: skipped when no dynamic body sleeps.
  m.anyAsleep = false;
  for (uint32_t i = 0; i < m.bodies.size() && !m.anyAsleep; ++i)
    m.anyAsleep = m.dynamic[i] && m.bodies[i] && !m.bodies[i]->isActive();
  std::vector<uint32_t> edited;
  for (const BrickEdit& e : log.bricks) {
    if (e.grid >= m.grids.size() || !m.grids[e.grid])
      throw InvalidInput("BulletBaseline::applyEdits: grid " + std::to_string(e.grid) + " is not mirrored");
    BulletChunkedGrid& g = *m.grids[e.grid];
    if (e.placed) g.place(e.brick, e.value);
    else g.remove(e.brick);
    if (std::find(edited.begin(), edited.end(), e.grid) == edited.end()) edited.push_back(e.grid);
  }
  for (uint32_t g : edited) {
    const std::vector<uint32_t>& touched = m.grids[g]->finishEdits();
    for (Impl::ObjectHolder& h : m.objectHolders)
      if (h.grid == g)
        for (uint32_t c : touched) m.refreshChunk(h, c);
    for (Impl::CompoundHolder& h : m.compoundHolders) {
      if (h.grid != g) continue;
      for (uint32_t c : touched) m.refreshChunk(h, c);
      if (m.dynamic[h.body]) m.refreshGridBodyMass(h, judge);
      else m.growParentBox(*h.parent, touched, h);
    }
  }
  for (const SplitEdit& split : log.splits) m.addPartBody(judge, split);
  m.editSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

double BulletBaseline::lastEditSeconds() const { return impl_->editSeconds; }
uint32_t BulletBaseline::partsMade() const { return impl_->partsMade; }
KinematicGrids BulletBaseline::kinematicGrids() const { return impl_->kinematicGrids; }
uint64_t BulletBaseline::bricksMirrored(uint32_t grid) const {
  return grid < impl_->grids.size() && impl_->grids[grid] ? impl_->grids[grid]->brickCount() : 0;
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
  for (Impl::ObjectHolder& h : m.objectHolders) {
    if (!h.kinematic) continue;
    btTransform next;
    btTransformUtil::integrateTransform(h.bodyPose, h.linearVelocity, h.angularVelocity, btScalar(m.timestep), next);
    h.bodyPose = next;
    h.pose = next * h.shapeFrame;
    const std::vector<BulletBrickChunk>& chunks = m.grids[h.grid]->chunks();
    for (uint32_t c = 0; c < h.objects.size(); ++c)
      if (h.objects[c])
        static_cast<btRigidBody*>(h.objects[c])->getMotionState()->setWorldTransform(h.pose * btTransform(btQuaternion::getIdentity(), bt(chunks[c].origin)));
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

uint32_t BulletBaseline::chunkObjects() const { return impl_->liveChunkObjects; }
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
  for (const Impl::ObjectHolder& h : m.objectHolders) {
    if (!h.kinematic) continue;
    const btVector3& p = h.bodyPose.getOrigin();
    const btQuaternion q = h.bodyPose.getRotation();
    positions[h.body] = Vec3d(p.x(), p.y(), p.z());
    rotations[h.body] = Quatf(q.w(), q.x(), q.y(), q.z()).normalized();
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
