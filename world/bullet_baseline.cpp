#include "world/bullet_baseline.h"

#include <btBulletDynamicsCommon.h>
#include <chrono>
#include <limits>
#include <vector>

namespace bw {

struct BulletBaseline::Impl {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &config};
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btCompoundShape>> compounds;  // one per World grid, shared by copies
  std::vector<std::unique_ptr<btDefaultMotionState>> motionStates;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::vector<uint8_t> dynamic;
  double timestep = 1.0 / 60;
  int substeps = 1;
  ~Impl() {
    for (auto& b : bodies) world.removeRigidBody(b.get());
  }
};

namespace {
btVector3 bt(const Vec3f& v) { return {v.x(), v.y(), v.z()}; }
btVector3 bt(const Vec3d& v) { return {btScalar(v.x()), btScalar(v.y()), btScalar(v.z())}; }
btQuaternion bt(const Quatf& q) { return {q.x(), q.y(), q.z(), q.w()}; }
}  // namespace

BulletBaseline::BulletBaseline(const World& w) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  const SceneSettings& s = w.scene().settings;
  m.world.setGravity(bt(s.gravity));
  m.world.getSolverInfo().m_numIterations = s.solverIterations;
  m.timestep = s.timestep;
  m.substeps = s.substeps;
  const BodyStore& b = w.bodies();
  const auto t = std::chrono::steady_clock::now();
  std::vector<btCompoundShape*> gridShape;
  for (uint32_t i = 0; i < b.size(); ++i) {
    btCollisionShape* shape = nullptr;
    btTransform shapeFrame = btTransform::getIdentity();
    if (b.shape[i].isGrid()) {
      const uint32_t g = b.shape[i].grid;
      if (gridShape.size() <= g) gridShape.resize(g + 1, nullptr);
      if (!gridShape[g]) {
        const BrickGrid& grid = w.grid(g);
        auto compound = std::make_unique<btCompoundShape>(true, int(grid.brickCount()));
        grid.forEachBrick([&](uint32_t id) {
          const Brick& br = grid.brick(id);
          m.shapes.push_back(std::make_unique<btBoxShape>(bt(br.rotation.applyToExtent(br.halfSize))));
          compound->addChildShape(btTransform(btQuaternion::getIdentity(), bt(br.position)), m.shapes.back().get());
        });
        gridShape[g] = compound.get();
        m.compounds.push_back(std::move(compound));
      }
      shape = gridShape[g];
      const RigidTransform& f = b.shapeFromBody[i];
      shapeFrame = btTransform(bt(f.rotation), bt(f.translation));
    } else {
      const QueryShape& q = b.shape[i].primitive;
      if (q.kind == QueryShape::Kind::Sphere) m.shapes.push_back(std::make_unique<btSphereShape>(q.radius));
      else if (q.kind == QueryShape::Kind::Capsule) m.shapes.push_back(std::make_unique<btCapsuleShapeZ>(q.radius, 2 * q.halfHeight));
      else m.shapes.push_back(std::make_unique<btBoxShape>(bt(q.halfExtents)));
      shape = m.shapes.back().get();
    }
    if (b.shape[i].isGrid() && !shapeFrame.getOrigin().isZero()) {
      // Dynamic grids: the body frame is the centre of mass; wrap the compound at its offset.
      auto wrapper = std::make_unique<btCompoundShape>(false, 1);
      wrapper->addChildShape(shapeFrame, shape);
      shape = wrapper.get();
      m.compounds.push_back(std::move(wrapper));
    }
    const bool dyn = b.motion[i] == MotionType::Dynamic;
    const float mass = dyn ? 1.f / b.inverseMass[i] : 0.f;
    const btVector3 inertia = dyn ? bt(Vec3f(b.inverseInertia[i].cwiseInverse())) : btVector3(0, 0, 0);
    m.motionStates.push_back(std::make_unique<btDefaultMotionState>(btTransform(bt(b.rotation[i]), bt(b.position[i]))));
    btRigidBody::btRigidBodyConstructionInfo info(mass, m.motionStates.back().get(), shape, inertia);
    info.m_friction = b.friction[i];
    m.bodies.push_back(std::make_unique<btRigidBody>(info));
    btRigidBody* body = m.bodies.back().get();
    body->setLinearVelocity(bt(b.linearVelocity[i]));
    body->setAngularVelocity(bt(b.angularVelocity[i]));
    if (b.motion[i] == MotionType::Kinematic) {
      body->setCollisionFlags(body->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
      body->setActivationState(DISABLE_DEACTIVATION);
    }
    m.world.addRigidBody(body);
    m.dynamic.push_back(dyn);
  }
  buildSeconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

BulletBaseline::~BulletBaseline() = default;

void BulletBaseline::step() {
  impl_->world.stepSimulation(btScalar(impl_->timestep), impl_->substeps, btScalar(impl_->timestep / impl_->substeps));
}

uint32_t BulletBaseline::contactCount() const {
  uint32_t n = 0;
  btDispatcher* d = impl_->world.getDispatcher();
  for (int i = 0; i < d->getNumManifolds(); ++i) n += uint32_t(d->getManifoldByIndexInternal(i)->getNumContacts());
  return n;
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
