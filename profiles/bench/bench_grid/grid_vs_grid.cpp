// bench_grid, grid against grid (issue 19): a 10.5k-brick truck (truck generator at scale 4)
// sunk 5 cm into a 12.7k-brick city block (city_block at its smallest scale), at 64 poses (a
// random street or roof spot found by raycasting, random yaw), contacts in the city's frame.
//
// GridVsGrid_TwoWay/<lod 0|1>: collideGridPair, both OctoBVHs traversed together (LOD off, or
//   1/16 of the other side's current node): time per query, contacts, brick_pairs (narrowphase
//   calls), item_pairs (node and brick pairs tested), lod_boxes; with the LOD on, its error
//   against LOD off: deepest_diff_max (m) and missed (poses where LOD off finds a penetration
//   and LOD on none).
// GridVsGrid_Convex: the one-way path (collideGrids: the truck's convex approximation, depth
//   3, against the city's bricks): time, contacts, deepest_diff_max against the two-way exact
//   answer (the hull closes the truck's open bed and its wheel arches).
// GridVsGrid_btCompound: Bullet as its experts set up grid against grid: the city in 8 m chunk
//   compounds of shared exact shapes in a btCollisionWorld (as btCompoundChunked), the truck
//   one btCompoundShape of its bricks' exact shapes with its dynamic AABB tree, queried with
//   contactTest (Bullet's compound-compound algorithm walks both trees per chunk): time,
//   contacts, contacts_pen, deepest_diff_max against our exact answer.
// GridVsGrid_btCompoundPersistent: the same, the truck kept in the world and each query a
//   performDiscreteCollisionDetection() (Bullet's algorithms and manifolds cached between
//   queries, as in a simulation): time, manifold points, deepest_diff_max.
#include <algorithm>
#include <benchmark/benchmark.h>
#include <btBulletCollisionCommon.h>
#include <chrono>
#include <memory>

#include "collision/bricks/brick_grid.h"
#include "collision/bricks/bullet_brick_shapes.h"
#include "collision/bricks/brick_grid.h"
#include "collision/bricks/grid_pair.h"
#include "collision/content/build_generators.h"
#include "collision/core/seeded_random.h"

namespace {

using namespace bw;
using Clock = std::chrono::steady_clock;

constexpr int kPoses = 64;
constexpr float kSink = 0.05f;

std::unique_ptr<BrickGrid> gridOf(const GeneratedBuild& b) {
  auto g = std::make_unique<BrickGrid>(BrickGrid::Config(uint32_t(b.bricks.size() + 1024)));
  g->placeBricks(b.bricks);
  return g;
}

struct Scene {
  std::unique_ptr<BrickGrid> city, truck;
  std::vector<LocalPose> truckInCity;  // the truck's pose in the city's frame
  std::vector<float> exactDeepest;     // per pose, the two-way answer with the LOD off
};

Scene& scene() {
  static Scene s = [] {
    Scene sc;
    sc.city = gridOf(generateBuild("city_block", 7, 0.005f));
    sc.truck = gridOf(generateBuild("truck", 5, 4.f));
    SeededRandom r(9);
    const Aabb cb = sc.city->bounds(), tb = sc.truck->bounds();
    while (int(sc.truckInCity.size()) < kPoses) {
      const float x = float(r.uniform(cb.min.x(), cb.max.x())), y = float(r.uniform(cb.min.y(), cb.max.y()));  // in this order
      const GridRayHit h = sc.city->raycast(Ray::make(Vec3f(x, y, cb.max.z() + 5.f), Vec3f(0, 0, -1)), ~0u);
      if (!h.hit() || h.normal.z() < 0.9f) continue;
      const Quatf yaw(Eigen::AngleAxisf(float(r.uniform(0, 6.28)), Vec3f::UnitZ()));
      // the truck's bottom centre onto the hit point, kSink below it
      const Vec3f bottom(tb.center().x(), tb.center().y(), tb.min.z());
      const Vec3f at(x, y, cb.max.z() + 5.f - h.t - kSink);
      sc.truckInCity.push_back({at - yaw * bottom, yaw});
    }
    GridPairParams exact;
    exact.lodFraction = 0.f;
    GridPairScratch scratch;
    std::vector<GridPairContact> out;
    for (const LocalPose& p : sc.truckInCity) {
      out.clear();
      collideGridPair(*sc.truck, *sc.city, p, exact, scratch, out);
      float d = 0;
      for (const GridPairContact& c : out) d = std::max(d, c.depth);
      sc.exactDeepest.push_back(d);
    }
    return sc;
  }();
  return s;
}

void GridVsGrid_TwoWay(benchmark::State& state) {
  Scene& s = scene();
  GridPairParams params;
  params.lodFraction = state.range(0) ? 1.f / 16 : 0.f;
  GridPairScratch scratch;
  std::vector<GridPairContact> out;
  GridPairStats stats;
  uint64_t contacts = 0, q = 0;
  for (auto _ : state) {
    out.clear();
    collideGridPair(*s.truck, *s.city, s.truckInCity[q++ % kPoses], params, scratch, out, &stats);
    contacts += out.size();
  }
  const double it = double(state.iterations());
  double diffMax = 0;
  uint32_t missed = 0;
  for (int p = 0; p < kPoses; ++p) {  // untimed: the LOD's error against LOD off
    out.clear();
    collideGridPair(*s.truck, *s.city, s.truckInCity[size_t(p)], params, scratch, out);
    float d = 0;
    for (const GridPairContact& c : out) d = std::max(d, c.depth);
    diffMax = std::max(diffMax, double(std::abs(d - s.exactDeepest[size_t(p)])));
    missed += s.exactDeepest[size_t(p)] > 0 && d <= 0;
  }
  state.counters["contacts"] = double(contacts) / it;
  state.counters["brick_pairs"] = double(stats.brickPairs) / it;
  state.counters["item_pairs"] = double(stats.itemPairs) / it;
  state.counters["lod_boxes"] = double(stats.lodBoxes) / it;
  state.counters["deepest_diff_max"] = diffMax;
  state.counters["missed"] = missed;
  state.counters["bricks_a"] = s.truck->brickCount();
  state.counters["bricks_b"] = s.city->brickCount();
}

void GridVsGrid_Convex(benchmark::State& state) {
  Scene& s = scene();
  ContactParams params;
  ContactScratch scratch;
  std::vector<Contact> out;
  int smaller = 0;
  s.truck->convexApproximation(3);  // built once, outside the timing (as the world caches it)
  uint64_t contacts = 0, q = 0;
  for (auto _ : state) {
    const LocalPose& p = s.truckInCity[q++ % kPoses];
    out.clear();
    collideGrids(*s.truck, RigidTransform{p.position.cast<double>(), p.rotation}, *s.city, RigidTransform{}, 3, params, scratch,
                 out, smaller);
    contacts += out.size();
  }
  double diffMax = 0;
  for (int p = 0; p < kPoses; ++p) {
    const LocalPose& pose = s.truckInCity[size_t(p)];
    out.clear();
    collideGrids(*s.truck, RigidTransform{pose.position.cast<double>(), pose.rotation}, *s.city, RigidTransform{}, 3, params,
                 scratch, out, smaller);
    float d = 0;
    for (const Contact& c : out) d = std::max(d, c.depth);
    diffMax = std::max(diffMax, double(std::abs(d - s.exactDeepest[size_t(p)])));
  }
  state.counters["contacts"] = double(contacts) / double(state.iterations());
  state.counters["deepest_diff_max"] = diffMax;
}

btTransform toBullet(const LocalPose& p) {
  return btTransform(btQuaternion(p.rotation.x(), p.rotation.y(), p.rotation.z(), p.rotation.w()),
                     btVector3(p.position.x(), p.position.y(), p.position.z()));
}

struct DeepestCounter : btCollisionWorld::ContactResultCallback {
  uint64_t all = 0, penetrating = 0;
  float deepest = 0;
  btScalar addSingleResult(btManifoldPoint& cp, const btCollisionObjectWrapper*, int, int, const btCollisionObjectWrapper*, int,
                           int) override {
    ++all;
    penetrating += cp.getDistance() < 0;
    deepest = std::max(deepest, -float(cp.getDistance()));
    return 0;
  }
};

// The rival as its experts set it up: the city as static 8 m chunk compounds in a world with an
// optimised dbvt broadphase; the truck one compound of its bricks' exact shapes (its dynamic
// AABB tree on, optimised as the chunks' trees are), children relative to the truck's frame.
struct BulletCityAndTruck {
  BulletBrickShapes shapes;
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btCollisionWorld world{&dispatcher, &broadphase, &config};
  std::vector<BulletBrickChunk> chunks;
  std::vector<std::unique_ptr<btCollisionObject>> objects;
  btCompoundShape truck;
  btCollisionObject query;

  explicit BulletCityAndTruck(const Scene& s) : truck(true, int(s.truck->brickCount())) {
    chunks = buildBulletChunks(*s.city, 8.f, shapes);
    for (const BulletBrickChunk& c : chunks) {
      auto o = std::make_unique<btCollisionObject>();
      o->setCollisionShape(c.shape.get());
      o->setWorldTransform(btTransform(btQuaternion::getIdentity(), btVector3(c.origin.x(), c.origin.y(), c.origin.z())));
      o->setCollisionFlags(o->getCollisionFlags() | btCollisionObject::CF_STATIC_OBJECT);
      world.addCollisionObject(o.get(), int(btBroadphaseProxy::StaticFilter),
                               int(btBroadphaseProxy::AllFilter ^ btBroadphaseProxy::StaticFilter));
      objects.push_back(std::move(o));
    }
    broadphase.optimize();
    s.truck->forEachBrick([&](uint32_t id) {
      const Brick& b = s.truck->brick(id);
      truck.addChildShape(BulletBrickShapes::childTransform(b, Vec3f::Zero()), shapes.shapeFor(b));
    });
    truck.getDynamicAabbTree()->optimizeTopDown();  // as the chunks' trees (buildBulletChunks)
    query.setCollisionShape(&truck);
  }
};

void GridVsGrid_btCompound(benchmark::State& state) {
  Scene& s = scene();
  BulletCityAndTruck bt(s);
  btCollisionWorld& world = bt.world;
  btCollisionObject& query = bt.query;
  const std::vector<BulletBrickChunk>& chunks = bt.chunks;
  DeepestCounter cb;
  uint64_t q = 0;
  for (auto _ : state) {
    query.setWorldTransform(toBullet(s.truckInCity[q++ % kPoses]));
    world.contactTest(&query, cb);
  }
  const double it = double(state.iterations());
  double diffMax = 0;
  for (int p = 0; p < kPoses; ++p) {
    DeepestCounter d;
    query.setWorldTransform(toBullet(s.truckInCity[size_t(p)]));
    world.contactTest(&query, d);
    diffMax = std::max(diffMax, double(std::abs(d.deepest - s.exactDeepest[size_t(p)])));
  }
  state.counters["contacts"] = double(cb.all) / it;
  state.counters["contacts_pen"] = double(cb.penetrating) / it;
  state.counters["deepest_diff_max"] = diffMax;
  state.counters["chunks"] = double(chunks.size());
}

// The obvious improvement to the rival: the truck kept in the world as an object, each query a
// performDiscreteCollisionDetection(), so Bullet keeps its compound-compound algorithms and their
// child-pair manifolds from one query to the next (as a simulation does), instead of building
// them per contactTest. Contacts are the manifolds' points.
void GridVsGrid_btCompoundPersistent(benchmark::State& state) {
  Scene& s = scene();
  BulletCityAndTruck bt(s);
  btCollisionWorld& world = bt.world;
  btCollisionDispatcher& dispatcher = bt.dispatcher;
  btCollisionObject& query = bt.query;
  query.setCollisionFlags(query.getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
  world.addCollisionObject(&query, int(btBroadphaseProxy::DefaultFilter), int(btBroadphaseProxy::AllFilter));
  auto manifoldPoints = [&](float* deepest) {
    uint64_t n = 0;
    for (int m = 0; m < dispatcher.getNumManifolds(); ++m) {
      const btPersistentManifold* pm = dispatcher.getManifoldByIndexInternal(m);
      for (int i = 0; i < pm->getNumContacts(); ++i) {
        ++n;
        if (deepest) *deepest = std::max(*deepest, -float(pm->getContactPoint(i).getDistance()));
      }
    }
    return n;
  };
  uint64_t contacts = 0, q = 0;
  for (auto _ : state) {
    query.setWorldTransform(toBullet(s.truckInCity[q++ % kPoses]));
    world.performDiscreteCollisionDetection();
    contacts += manifoldPoints(nullptr);
  }
  double diffMax = 0;
  for (int p = 0; p < kPoses; ++p) {
    query.setWorldTransform(toBullet(s.truckInCity[size_t(p)]));
    world.performDiscreteCollisionDetection();
    float d = 0;
    manifoldPoints(&d);
    diffMax = std::max(diffMax, double(std::abs(d - s.exactDeepest[size_t(p)])));
  }
  world.removeCollisionObject(&query);
  state.counters["contacts"] = double(contacts) / double(state.iterations());
  state.counters["deepest_diff_max"] = diffMax;
}

BENCHMARK(GridVsGrid_TwoWay)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK(GridVsGrid_Convex)->Unit(benchmark::kMicrosecond);
BENCHMARK(GridVsGrid_btCompound)->Unit(benchmark::kMicrosecond);
BENCHMARK(GridVsGrid_btCompoundPersistent)->Unit(benchmark::kMicrosecond);

}  // namespace
