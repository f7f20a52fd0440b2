// bench_grid: brick grids vs Bullet 3.24 on the same bricks, Bullet set up as its experts would
// (chunk compounds of shared exact shapes in a persistent world) and, as a labelled second row,
// naively (one compound of every brick).
//
//   build/release/bin/bench_grid --benchmark_counters_tabular=true
//
// Query shapes <shape>: 0 = a 0.5 m box, 1 = a capsule (radius 0.25, core 0.5 along z, 1 m
// tall), 2 = an 8 m box, resting on a city-block grid (poses found by raycasting onto its
// surface, random yaw; the same 1024 poses for our rows and the Bullet rows of a shape).
//
// GridContact/<shape>/<bricks>/<lod 0|1>: our grid (exact brick shapes): time per contact query,
//   contacts (after reduction to 4), raw contacts, narrowphase calls, box tests, and with LOD
//   the depth error against LOD off.
// GridEdit/<bricks>: place + remove one brick including index and mass properties.
// GridBuild/<bricks>: build time and bytes per brick.
// Connectivity_RemoveNoSplit/<bricks>: one random brick of the city block removed and the grid's
//   connectivity checked (BrickConnectivity: unlink, remove, detached()), then put back
//   (untimed): time per removal with its distribution over the run (p50_us, p99_us, max_us),
//   bricks visited per removal, and pieces found (removals that do split off a part count too).
// Connectivity_CutInTwo/<bricks>: a slab of cubes in two equal halves joined by one brick:
//   removing it detaches the half it walks; time and bricks visited per cut.
// ConvexApprox/<build>/<depth>: hull build time, hull volume / brick volume, box or not.
// btCompoundChunked/<shape>/<bricks>/<chunk_m>: Bullet as an expert sets it up: the grid cut
//   into chunk_m cubes by buildBulletChunks (one shared btBoxShape / btCylinderShapeZ /
//   btConvexHullShape per distinct brick, exact rotations), each chunk's compound tree rebuilt
//   with optimizeTopDown(), one static btCollisionObject per chunk compound in a persistent
//   btCollisionWorld (btDbvtBroadphase, optimised once after adding), queried with
//   btCollisionWorld::contactTest of a query object of the same shape. Chunk sizes 2..32 m at
//   100k bricks, 8 m at 10k. 8 m is the comparison's chunk size: in the sweep (2026-11-23) 2..16 m
//   were within a few percent of each other for the 0.5 m box and the capsule, 4 m was 4-14%
//   faster than 8 m for the 8 m box and 32 m was slowest for all three; the summary also prints
//   the sweep's fastest size beside 8 m. Counters: contacts (every point Bullet
//   reports: box-box manifolds, and for GJK pairs gaps up to both margins + the breaking
//   threshold too), contacts_pen (points with distance < 0), us_per_query, bytes_per_element (child
//   records, compound trees, chunk objects and broadphase nodes, shared shapes; per brick),
//   chunks, chunks_per_query (broadphase hits of the query's AABB), build_ms; accuracy beside
//   speed, untimed over the same poses: depth_diff_max / depth_diff_mean (Bullet's deepest
//   penetration vs ours, LOD off) and only_bullet / only_ours (poses where one side alone finds
//   a penetration).
// btCompoundTree/<shape>/<bricks>: Bullet's fastest direct path a user could write on the same
//   8 m chunks: chunks whose AABB overlaps the query's (a btDbvt of chunk AABBs, optimised),
//   then btDbvt::collideTV of the query's AABB (in the chunk's frame) against the chunk
//   compound's own getDynamicAabbTree(), then per overlapping child btBoxBoxDetector for box vs
//   box children (up to 4 points per pair, what contactTest's per-child box-box algorithm runs)
//   and btGjkPairDetector (GJK + EPA, what the dispatcher's convex-convex algorithm runs, with its
//   distance cut: both margins + the manifold's breaking threshold) for every other pair. No
//   per-query allocation once warm.
//   Counters: contacts, contacts_pen, narrowphase (children tested), chunks_per_query.
// btCompoundNaive/<bricks>: the naive setup, kept as a labelled second baseline: one
//   btCompoundShape of every brick (a btBoxShape of each brick's bounds), contactPairTest of the
//   0.5 m box, which builds a compound algorithm (O(bricks) bookkeeping) per query.
// The summary prints our grid (LOD off) against btCompoundChunked at 8 m, the best chunk size of
// the sweep, btCompoundTree and the naive row, per shape.
#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <BulletCollision/CollisionDispatch/btBoxBoxDetector.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkPairDetector.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>
#include <algorithm>
#include <benchmark/benchmark.h>
#include <btBulletCollisionCommon.h>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>

#include "collision/bricks/brick_connectivity.h"
#include "collision/bricks/brick_geometry.h"
#include "collision/bricks/brick_grid.h"
#include "collision/bricks/bullet_brick_shapes.h"
#include "collision/content/build_generators.h"
#include "collision/core/seeded_random.h"

namespace {

using namespace bw;
using Clock = std::chrono::steady_clock;

std::map<std::string, double>& summary() {
  static std::map<std::string, double> s;
  return s;
}

float cityScaleFor(uint32_t bricks) { return float(bricks) / 2.0e6f; }

const GeneratedBuild& city(uint32_t bricks) {
  static std::map<uint32_t, GeneratedBuild> cache;
  auto it = cache.find(bricks);
  if (it == cache.end()) it = cache.emplace(bricks, generateCityBlock(7, cityScaleFor(bricks))).first;
  return it->second;
}

BrickGrid& grid(uint32_t bricks) {
  static std::map<uint32_t, std::unique_ptr<BrickGrid>> cache;
  auto& g = cache[bricks];
  if (!g) {
    const GeneratedBuild& b = city(bricks);
    g = std::make_unique<BrickGrid>(BrickGrid::Config(uint32_t(b.bricks.size() + 1024)));
    for (const Brick& br : b.bricks) g->placeBrick(br);
  }
  return *g;
}

// Resting poses: drop a ray from above onto the build, put the shape's bottom 0.01 into the hit.
std::vector<RigidTransform> restingPoses(const BrickGrid& g, float halfHeight, uint32_t count, uint64_t seed) {
  SeededRandom r(seed);
  std::vector<RigidTransform> out;
  const Aabb b = g.bounds();
  while (out.size() < count) {
    const float ox = float(r.uniform(b.min.x(), b.max.x())), oy = float(r.uniform(b.min.y(), b.max.y()));  // in this order
    const Vec3f o(ox, oy, b.max.z() + 5.f);
    const GridRayHit h = g.raycast(Ray::make(o, Vec3f(0, 0, -1)), ~0u);
    if (!h.hit() || h.normal.z() < 0.9f) continue;
    const Vec3f p = o + Vec3f(0, 0, -h.t + halfHeight - 0.01f);
    out.push_back({p.cast<double>(), Quatf(Eigen::AngleAxisf(float(r.uniform(0, 6.28)), Vec3f::UnitZ()))});
  }
  return out;
}

// 0: a 0.5 m crate, 1: a capsule, 2: an 8 m container (its LOD threshold, 1/16, is 0.5 m: whole
// bricks and microbrick patches collapse into boxes).
QueryShape shapeNamed(int kind) {
  if (kind == 2) return QueryShape::box(Vec3f::Constant(4.f));
  return kind == 0 ? QueryShape::box(Vec3f::Constant(0.25f)) : QueryShape::capsule(0.25f, 0.25f);
}
float halfHeightOf(int kind) { return kind == 2 ? 4.f : kind == 0 ? 0.25f : 0.5f; }

void GridContact(benchmark::State& state) {
  const int kind = int(state.range(0));
  const uint32_t bricks = uint32_t(state.range(1));
  const bool lod = state.range(2) != 0;
  const BrickGrid& g = grid(bricks);
  const QueryShape shape = shapeNamed(kind);
  const auto poses = restingPoses(g, halfHeightOf(kind), 1024, 3);
  ContactParams params;
  params.lodFraction = lod ? 1.f / 16 : 0.f;
  ContactScratch scratch;
  std::vector<Contact> out;
  ContactStats st;
  uint64_t contacts = 0, q = 0;
  const auto t0 = Clock::now();
  for (auto _ : state) {
    out.clear();
    contacts += g.collide(RigidTransform{}, shape, poses[q++ & 1023], params, scratch, out, &st);
  }
  const double it = double(state.iterations());
  summary()["grid_us_" + std::to_string(kind) + "_" + std::to_string(bricks) + (lod ? "_lod" : "")] =
      std::chrono::duration<double, std::micro>(Clock::now() - t0).count() / it;
  state.counters["contacts"] = double(contacts) / it;
  state.counters["raw_contacts"] = st.rawContacts / it;
  state.counters["narrowphase"] = st.bricksTested / it;
  state.counters["lod_boxes"] = st.lodBoxes / it;
  state.counters["box_tests"] = double(st.index.boxTests) / it;
  state.counters["bricks"] = double(g.brickCount());
  if (lod) {
    // Depth error LOD introduces: deepest contact per pose, LOD on vs off.
    ContactParams off = params;
    off.lodFraction = 0.f;
    double maxErr = 0, sumErr = 0;
    for (const RigidTransform& p : poses) {
      std::vector<Contact> a, b;
      g.collide(RigidTransform{}, shape, p, params, scratch, a);
      g.collide(RigidTransform{}, shape, p, off, scratch, b);
      float da = 0, db = 0;
      for (auto& c : a) da = std::max(da, c.depth);
      for (auto& c : b) db = std::max(db, c.depth);
      maxErr = std::max(maxErr, double(std::abs(da - db)));
      sumErr += std::abs(da - db);
    }
    state.counters["depth_err_max"] = maxErr;
    state.counters["depth_err_mean"] = sumErr / poses.size();
  }
}

void GridEdit(benchmark::State& state) {
  BrickGrid& g = grid(uint32_t(state.range(0)));
  SeededRandom r(5);
  const Aabb b = g.bounds();
  for (auto _ : state) {
    Vec3f p;
    for (int a = 0; a < 3; ++a) p[a] = float(r.uniform(b.min[a], b.max[a]));  // one draw per statement
    const uint32_t id = g.placeBrick(Brick::box(p, Vec3f(0.2f, 0.2f, 0.24f)));
    g.removeBrick(id);
  }
  state.counters["us_per_edit"] = benchmark::Counter(2.0 * double(state.iterations()), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void Connectivity_RemoveNoSplit(benchmark::State& state) {
  // Its own copy of the city (the removals are put back, but ids may change).
  const GeneratedBuild& b = city(uint32_t(state.range(0)));
  BrickGrid g(BrickGrid::Config(uint32_t(b.bricks.size() + 1024)));
  for (const Brick& br : b.bricks) g.placeBrick(br);
  BrickConnectivity links(g);
  std::vector<uint32_t> ids;
  g.forEachBrick([&](uint32_t id) { ids.push_back(id); });
  SeededRandom r(9);
  std::vector<uint32_t> seeds;
  std::vector<std::vector<uint32_t>> pieces;
  std::vector<double> us;
  uint64_t visited = 0, piecesFound = 0;
  for (auto _ : state) {
    const uint32_t slot = uint32_t(r.uniform(0, double(ids.size()) - 1e-9));
    const Brick brick = g.brick(ids[slot]);
    const auto t0 = Clock::now();
    seeds.clear();
    links.removing(ids[slot], seeds);
    g.removeBrick(ids[slot]);
    pieces.clear();
    ConnectivityStats st;
    links.detached(seeds, pieces, &st);
    const double t = std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
    state.SetIterationTime(t * 1e-6);
    us.push_back(t);
    visited += st.visited;
    piecesFound += st.pieces;
    // Put it back (a piece that fell off stays in the grid here: the next removals see it).
    ids[slot] = g.placeBrick(brick);
    links.placed(g, ids[slot]);
  }
  std::sort(us.begin(), us.end());
  auto at = [&](double q) { return us.empty() ? 0.0 : us[size_t(q * double(us.size() - 1))]; };
  state.counters["p50_us"] = at(0.5);
  state.counters["p99_us"] = at(0.99);
  state.counters["max_us"] = us.empty() ? 0.0 : us.back();
  state.counters["visited_per_removal"] = double(visited) / double(std::max<int64_t>(1, state.iterations()));
  state.counters["pieces_per_removal"] = double(piecesFound) / double(std::max<int64_t>(1, state.iterations()));
}

void Connectivity_CutInTwo(benchmark::State& state) {
  const int side = int(std::sqrt(double(state.range(0)) / 2.0));  // two side x side halves
  BrickGrid g(BrickGrid::Config(uint32_t(2 * side * side + 1024)));
  for (int half = 0; half < 2; ++half)
    for (int x = 0; x < side; ++x)
      for (int y = 0; y < side; ++y) g.placeBrick(Brick::box(Vec3f(float(x + half * (side + 1)), float(y), 0), Vec3f::Constant(0.5f)));
  const Brick bar = Brick::box(Vec3f(float(side), float(side / 2), 0), Vec3f::Constant(0.5f));
  uint32_t barId = g.placeBrick(bar);
  BrickConnectivity links(g);
  std::vector<uint32_t> seeds;
  std::vector<std::vector<uint32_t>> pieces;
  uint64_t visited = 0, detached = 0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    seeds.clear();
    links.removing(barId, seeds);
    g.removeBrick(barId);
    pieces.clear();
    ConnectivityStats st;
    links.detached(seeds, pieces, &st);
    state.SetIterationTime(std::chrono::duration<double>(Clock::now() - t0).count());
    visited += st.visited;
    detached += pieces.empty() ? 0 : pieces[0].size();
    barId = g.placeBrick(bar);
    links.placed(g, barId);
  }
  state.counters["bricks"] = double(g.brickCount());
  state.counters["visited_per_cut"] = double(visited) / double(std::max<int64_t>(1, state.iterations()));
  state.counters["detached_bricks"] = double(detached) / double(std::max<int64_t>(1, state.iterations()));
}

void ConvexApprox(benchmark::State& state) {
  const std::vector<std::string> names = buildNames();
  const std::string name = names[size_t(state.range(0))];
  const int depth = int(state.range(1));
  static std::map<std::string, std::unique_ptr<BrickGrid>> grids;
  auto& g = grids[name];
  if (!g) {
    const GeneratedBuild b = generateBuild(name, 11, name == "city_block" ? 0.01f : 1.f);
    g = std::make_unique<BrickGrid>(BrickGrid::Config(uint32_t(b.bricks.size() + 1024)));
    for (const Brick& br : b.bricks) g->placeBrick(br);
  }
  ConvexApproximation a;
  for (auto _ : state) a = g->buildConvexApproximation(depth);
  state.SetLabel(name);
  state.counters["bricks"] = double(g->brickCount());
  state.counters["hull_over_volume"] = a.hullVolume / g->massProperties().mass;  // density 1
  state.counters["hull_vertices"] = double(a.vertices.size());
  state.counters["input_points"] = double(a.inputPoints);
  state.counters["is_box"] = a.isBox ? 1 : 0;
}

// ---------------------------------------------------------------- Bullet: naive compound (second baseline)

// The naive setup: one btCompoundShape of every brick, each a btBoxShape of the brick's bounds.
// Kept beside the expert rows below, labelled naive: contactPairTest builds a compound algorithm
// per query, whose bookkeeping is O(children) before the tree is walked.

struct CompoundBuild {
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::unique_ptr<btCompoundShape> compound;
  double buildSeconds = 0;
  double bytesPerBrick = 0;
};

CompoundBuild& compound(uint32_t bricks) {
  static std::map<uint32_t, std::unique_ptr<CompoundBuild>> cache;
  auto& c = cache[bricks];
  if (!c) {
    c = std::make_unique<CompoundBuild>();
    const GeneratedBuild& b = city(bricks);
    const auto t = Clock::now();
    c->compound = std::make_unique<btCompoundShape>(true, int(b.bricks.size()));
    for (const Brick& br : b.bricks) {
      // Each brick a child box of its bounds (the compound baseline in the article).
      const Vec3f e = br.rotation.applyToExtent(br.halfSize);
      c->shapes.push_back(std::make_unique<btBoxShape>(btVector3(e.x(), e.y(), e.z())));
      c->compound->addChildShape(btTransform(btQuaternion::getIdentity(), btVector3(br.position.x(), br.position.y(), br.position.z())),
                                 c->shapes.back().get());
    }
    c->buildSeconds = std::chrono::duration<double>(Clock::now() - t).count();
    // Child record + the child's btBoxShape + two btDbvt nodes per child in the compound's tree.
    c->bytesPerBrick = double(sizeof(btCompoundShapeChild) + sizeof(btBoxShape) + 2 * sizeof(btDbvtNode));
  }
  return *c;
}

struct CountContacts : btCollisionWorld::ContactResultCallback {
  uint64_t n = 0;
  btScalar addSingleResult(btManifoldPoint&, const btCollisionObjectWrapper*, int, int, const btCollisionObjectWrapper*, int, int) override {
    ++n;
    return 0;
  }
};

void btCompoundNaive(benchmark::State& state) {
  const uint32_t bricks = uint32_t(state.range(0));
  CompoundBuild& c = compound(bricks);
  const auto poses = restingPoses(grid(bricks), 0.25f, 256, 3);
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  btDbvtBroadphase broadphase;
  btCollisionWorld world(&dispatcher, &broadphase, &config);
  btCollisionObject gridObject, boxObject;
  gridObject.setCollisionShape(c.compound.get());
  btBoxShape box(btVector3(0.25f, 0.25f, 0.25f));
  boxObject.setCollisionShape(&box);
  CountContacts cb;
  uint64_t q = 0;
  const auto t0 = Clock::now();
  for (auto _ : state) {
    const RigidTransform& p = poses[q++ & 255];
    boxObject.setWorldTransform(btTransform(btQuaternion(p.rotation.x(), p.rotation.y(), p.rotation.z(), p.rotation.w()),
                                            btVector3(btScalar(p.translation.x()), btScalar(p.translation.y()), btScalar(p.translation.z()))));
    world.contactPairTest(&boxObject, &gridObject, cb);
  }
  summary()["bt_us_" + std::to_string(bricks)] =
      std::chrono::duration<double, std::micro>(Clock::now() - t0).count() / double(state.iterations());
  state.counters["contacts"] = double(cb.n) / double(state.iterations());
  state.counters["build_ms"] = c.buildSeconds * 1e3;
  state.counters["bytes_per_brick"] = c.bytesPerBrick;
  state.counters["bricks"] = double(city(bricks).bricks.size());
}

// ---------------------------------------------------------------- Bullet as an expert sets it up

// Chunk edge (m) of the comparison and of btCompoundTree (the 100k sweep: see the header).
constexpr int kChosenChunkM = 8;

btTransform toBullet(const RigidTransform& p) {
  return btTransform(btQuaternion(p.rotation.x(), p.rotation.y(), p.rotation.z(), p.rotation.w()),
                     btVector3(btScalar(p.translation.x()), btScalar(p.translation.y()), btScalar(p.translation.z())));
}

// The query shapes of shapeNamed() in Bullet. Both keep their margin inside the shape (a box's
// inside its half extents, a capsule's is its radius), so they are exact.
std::unique_ptr<btConvexShape> bulletQueryShape(int kind) {
  if (kind == 1) return std::make_unique<btCapsuleShapeZ>(0.25f, 0.5f);  // radius, core length (2 x halfHeight)
  const float h = kind == 2 ? 4.f : 0.25f;
  return std::make_unique<btBoxShape>(btVector3(h, h, h));
}

// A grid as chunk compounds in a persistent world, plus a btDbvt of the chunks' world AABBs for
// the direct path (leaf data = chunk index). The grid pose is identity, as in GridContact, so a
// chunk object sits at gridPose * chunk origin = its origin.
struct ChunkedWorld {
  BulletBrickShapes shapes;
  std::vector<BulletBrickChunk> chunks;
  std::vector<std::unique_ptr<btCollisionObject>> objects;
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btCollisionWorld world{&dispatcher, &broadphase, &config};  // note: destroyed before the objects it holds
  btDbvt chunkTree;
  double buildSeconds = 0;
  double bytesPerBrick = 0;
};

ChunkedWorld& chunkedWorld(uint32_t bricks, int chunkM) {
  static std::map<std::pair<uint32_t, int>, std::unique_ptr<ChunkedWorld>> cache;
  auto& w = cache[{bricks, chunkM}];
  if (!w) {
    w = std::make_unique<ChunkedWorld>();
    const BrickGrid& g = grid(bricks);
    const RigidTransform gridPose{};
    const auto t = Clock::now();
    w->chunks = buildBulletChunks(g, float(chunkM), w->shapes);
    for (size_t i = 0; i < w->chunks.size(); ++i) {
      const BulletBrickChunk& c = w->chunks[i];
      auto o = std::make_unique<btCollisionObject>();
      o->setCollisionShape(c.shape.get());
      o->setWorldTransform(toBullet(gridPose) * btTransform(btQuaternion::getIdentity(), btVector3(c.origin.x(), c.origin.y(), c.origin.z())));
      o->setCollisionFlags(o->getCollisionFlags() | btCollisionObject::CF_STATIC_OBJECT);
      w->world.addCollisionObject(o.get(), int(btBroadphaseProxy::StaticFilter),
                                  int(btBroadphaseProxy::AllFilter ^ btBroadphaseProxy::StaticFilter));
      btVector3 mn, mx;
      c.shape->getAabb(o->getWorldTransform(), mn, mx);
      w->chunkTree.insert(btDbvtVolume::FromMM(mn, mx), reinterpret_cast<void*>(i));
      w->objects.push_back(std::move(o));
    }
    w->broadphase.optimize();    // static chunks: build the broadphase tree top-down once
    w->chunkTree.optimizeTopDown();
    w->buildSeconds = std::chrono::duration<double>(Clock::now() - t).count();
    // Per brick: its child record and two compound-tree nodes; per chunk: the compound, its tree,
    // its object, its broadphase proxy and two broadphase-tree nodes; the shared shapes once.
    const size_t perChunk = sizeof(btCompoundShape) + sizeof(btDbvt) + sizeof(btCollisionObject) + sizeof(btDbvtProxy) +
                            2 * sizeof(btDbvtNode);
    const size_t total = size_t(g.brickCount()) * kBulletCompoundChildBytes + w->chunks.size() * perChunk + w->shapes.bytes();
    w->bytesPerBrick = double(total) / double(g.brickCount());
  }
  return *w;
}

// Counts every point Bullet reports and those with a negative distance (penetrating).
struct ContactCounter : btCollisionWorld::ContactResultCallback {
  uint64_t all = 0, penetrating = 0;
  btScalar addSingleResult(btManifoldPoint& cp, const btCollisionObjectWrapper*, int, int, const btCollisionObjectWrapper*, int,
                           int) override {
    ++all;
    penetrating += cp.getDistance() < 0;
    return 0;
  }
};

// The deepest penetration among the points Bullet reports (0 when none penetrates).
struct DeepestPenetration : btCollisionWorld::ContactResultCallback {
  float deepest = 0;
  btScalar addSingleResult(btManifoldPoint& cp, const btCollisionObjectWrapper*, int, int, const btCollisionObjectWrapper*, int,
                           int) override {
    deepest = std::max(deepest, float(-cp.getDistance()));
    return 0;
  }
};

// Counts broadphase proxies whose AABB overlaps (chunks a query reaches).
struct ProxyCounter : btBroadphaseAabbCallback {
  uint64_t n = 0;
  bool process(const btBroadphaseProxy*) override {
    ++n;
    return true;
  }
};

void btCompoundChunked(benchmark::State& state) {
  const int kind = int(state.range(0));
  const uint32_t bricks = uint32_t(state.range(1));
  const int chunkM = int(state.range(2));
  ChunkedWorld& w = chunkedWorld(bricks, chunkM);
  const auto poses = restingPoses(grid(bricks), halfHeightOf(kind), 1024, 3);
  const std::unique_ptr<btConvexShape> shape = bulletQueryShape(kind);
  btCollisionObject query;
  query.setCollisionShape(shape.get());
  ContactCounter cb;
  uint64_t q = 0;
  const auto t0 = Clock::now();
  for (auto _ : state) {
    query.setWorldTransform(toBullet(poses[q++ & 1023]));
    w.world.contactTest(&query, cb);
  }
  const double it = double(state.iterations());
  const double us = std::chrono::duration<double, std::micro>(Clock::now() - t0).count() / it;
  ProxyCounter reached;  // untimed: chunks per query over the 1024 poses
  for (const RigidTransform& p : poses) {
    btVector3 mn, mx;
    shape->getAabb(toBullet(p), mn, mx);
    w.broadphase.aabbTest(mn, mx, reached);
  }
  // Accuracy beside speed (untimed): per pose, Bullet's deepest penetration against our grid's
  // (LOD off, raw contacts), and the poses where only one side finds a penetration.
  const BrickGrid& g = grid(bricks);
  const QueryShape ours = shapeNamed(kind);
  ContactParams exact;
  exact.lodFraction = 0.f;
  std::vector<LocalContact> raw;
  double diffMax = 0, diffSum = 0;
  uint32_t onlyBullet = 0, onlyOurs = 0;
  for (const RigidTransform& p : poses) {
    DeepestPenetration d;
    query.setWorldTransform(toBullet(p));
    w.world.contactTest(&query, d);
    raw.clear();
    g.collideLocal(ours, LocalPose{p.translation.cast<float>(), p.rotation}, exact, raw);
    float deepest = 0;
    for (const LocalContact& c : raw) deepest = std::max(deepest, c.depth);
    diffMax = std::max(diffMax, double(std::abs(d.deepest - deepest)));
    diffSum += std::abs(d.deepest - deepest);
    onlyBullet += d.deepest > 0 && deepest <= 0;
    onlyOurs += deepest > 0 && d.deepest <= 0;
  }
  summary()["chunked_us_" + std::to_string(kind) + "_" + std::to_string(bricks) + "_" + std::to_string(chunkM)] = us;
  state.counters["depth_diff_max"] = diffMax;
  state.counters["depth_diff_mean"] = diffSum / double(poses.size());
  state.counters["only_bullet"] = onlyBullet;
  state.counters["only_ours"] = onlyOurs;
  state.counters["contacts"] = double(cb.all) / it;
  state.counters["contacts_pen"] = double(cb.penetrating) / it;
  state.counters["us_per_query"] = us;
  state.counters["bytes_per_element"] = w.bytesPerBrick;
  state.counters["chunks"] = double(w.chunks.size());
  state.counters["chunks_per_query"] = double(reached.n) / double(poses.size());
  state.counters["build_ms"] = w.buildSeconds * 1e3;
  state.counters["bricks"] = double(g.brickCount());
}

// Leaf collector for collideTV: the leaves' data as indices (chunk index or compound child index).
struct LeafIndices : btDbvt::ICollide {
  std::vector<int>* out = nullptr;
  void Process(const btDbvtNode* leaf) override { out->push_back(leaf->dataAsInt); }
};

// Counts the points a detector reports (Bullet's sign: negative distance = penetration).
struct PointCounter : btDiscreteCollisionDetectorInterface::Result {
  uint64_t all = 0, penetrating = 0;
  void setShapeIdentifiersA(int, int) override {}
  void setShapeIdentifiersB(int, int) override {}
  void addContactPoint(const btVector3&, const btVector3&, btScalar depth) override {
    ++all;
    penetrating += depth < 0;
  }
};

void btCompoundTree(benchmark::State& state) {
  const int kind = int(state.range(0));
  const uint32_t bricks = uint32_t(state.range(1));
  ChunkedWorld& w = chunkedWorld(bricks, kChosenChunkM);
  const auto poses = restingPoses(grid(bricks), halfHeightOf(kind), 1024, 3);
  const std::unique_ptr<btConvexShape> shape = bulletQueryShape(kind);
  const btBoxShape* queryBox = kind == 1 ? nullptr : static_cast<const btBoxShape*>(shape.get());
  btVoronoiSimplexSolver simplex;
  btGjkEpaPenetrationDepthSolver epa;
  std::vector<int> chunkHits, childHits;
  chunkHits.reserve(1024);
  childHits.reserve(4096);
  LeafIndices chunkCollector, childCollector;
  chunkCollector.out = &chunkHits;
  childCollector.out = &childHits;
  PointCounter points;
  uint64_t q = 0, narrowphase = 0, chunksReached = 0;
  // The breaking threshold the dispatcher gives a manifold of the query and a chunk (relative to
  // shape sizes when CD_USE_RELATIVE_CONTACT_BREAKING_THRESHOLD is on, Bullet's default).
  const bool relative = (w.dispatcher.getDispatcherFlags() & btCollisionDispatcher::CD_USE_RELATIVE_CONTACT_BREAKING_THRESHOLD) != 0;
  auto breakingFor = [&](const btCompoundShape& c) {
    return relative ? std::min(shape->getContactBreakingThreshold(gContactBreakingThreshold),
                               c.getContactBreakingThreshold(gContactBreakingThreshold))
                    : gContactBreakingThreshold;
  };
  const auto t0 = Clock::now();
  for (auto _ : state) {
    const btTransform queryXf = toBullet(poses[q++ & 1023]);
    btVector3 mn, mx;
    shape->getAabb(queryXf, mn, mx);
    chunkHits.clear();
    w.chunkTree.collideTV(w.chunkTree.m_root, btDbvtVolume::FromMM(mn, mx), chunkCollector);
    chunksReached += chunkHits.size();
    for (int ci : chunkHits) {
      const btCollisionObject& chunkObject = *w.objects[size_t(ci)];
      const btCompoundShape& compound = *w.chunks[size_t(ci)].shape;
      const btTransform& chunkXf = chunkObject.getWorldTransform();
      const btScalar breaking = breakingFor(compound);
      // The query's AABB in the chunk's frame, as btCompoundCollisionAlgorithm computes it.
      shape->getAabb(chunkXf.inverseTimes(queryXf), mn, mx);
      childHits.clear();
      compound.getDynamicAabbTree()->collideTV(compound.getDynamicAabbTree()->m_root, btDbvtVolume::FromMM(mn, mx), childCollector);
      narrowphase += childHits.size();
      for (int child : childHits) {
        const btCollisionShape* childShape = compound.getChildShape(child);
        btDiscreteCollisionDetectorInterface::ClosestPointInput input;
        input.m_transformA = queryXf;
        input.m_transformB = chunkXf * compound.getChildTransform(child);
        if (queryBox && childShape->getShapeType() == BOX_SHAPE_PROXYTYPE) {
          btBoxBoxDetector detector(queryBox, static_cast<const btBoxShape*>(childShape));
          detector.getClosestPoints(input, points, nullptr);
        } else {
          const btConvexShape* convex = static_cast<const btConvexShape*>(childShape);
          // The distance cut btConvexConvexAlgorithm uses: both margins + the manifold's breaking threshold.
          const btScalar cut = shape->getMargin() + convex->getMargin() + breaking;
          input.m_maximumDistanceSquared = cut * cut;
          btGjkPairDetector gjk(shape.get(), convex, &simplex, &epa);
          gjk.getClosestPoints(input, points, nullptr);
        }
      }
    }
  }
  const double it = double(state.iterations());
  const double us = std::chrono::duration<double, std::micro>(Clock::now() - t0).count() / it;
  summary()["tree_us_" + std::to_string(kind) + "_" + std::to_string(bricks)] = us;
  state.counters["contacts"] = double(points.all) / it;
  state.counters["contacts_pen"] = double(points.penetrating) / it;
  state.counters["narrowphase"] = double(narrowphase) / it;
  state.counters["chunks_per_query"] = double(chunksReached) / it;
  state.counters["us_per_query"] = us;
  state.counters["bricks"] = double(grid(bricks).brickCount());
}

void GridBuild(benchmark::State& state) {
  const GeneratedBuild& b = city(uint32_t(state.range(0)));
  for (auto _ : state) {
    BrickGrid g(BrickGrid::Config(uint32_t(b.bricks.size() + 1024)));
    const auto t = Clock::now();
    for (const Brick& br : b.bricks) g.placeBrick(br);
    state.counters["build_ms"] = std::chrono::duration<double, std::milli>(Clock::now() - t).count();
    const auto m = g.index().memoryStats();
    state.counters["bytes_per_brick"] = double(m.totalBytes() + b.bricks.size() * (sizeof(Brick) + 4)) / double(b.bricks.size());
    state.counters["bricks"] = double(b.bricks.size());
  }
}

}  // namespace

BENCHMARK(GridContact)->ArgsProduct({{0, 1, 2}, {10'000, 100'000, 2'000'000}, {0, 1}})->Unit(benchmark::kMicrosecond);
BENCHMARK(GridEdit)->Arg(100'000)->Unit(benchmark::kMicrosecond);
BENCHMARK(Connectivity_RemoveNoSplit)->Arg(100'000)->Arg(1'000'000)->UseManualTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(Connectivity_CutInTwo)->Arg(100'000)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(GridBuild)->Arg(10'000)->Arg(100'000)->Arg(2'000'000)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(btCompoundNaive)->Arg(10'000)->Arg(100'000)->Unit(benchmark::kMicrosecond);
// Chunk-size sweep at 100k (2..32 m), the chosen 8 m at 10k.
BENCHMARK(btCompoundChunked)->ArgsProduct({{0, 1, 2}, {100'000}, {2, 4, 8, 16, 32}})->Unit(benchmark::kMicrosecond);
BENCHMARK(btCompoundChunked)->ArgsProduct({{0, 1, 2}, {10'000}, {kChosenChunkM}})->Unit(benchmark::kMicrosecond);
BENCHMARK(btCompoundTree)->ArgsProduct({{0, 1, 2}, {10'000, 100'000}})->Unit(benchmark::kMicrosecond);
BENCHMARK(ConvexApprox)->ArgsProduct({{0, 1, 2, 3, 4, 5}, {1, 2, 3, 4, 5}})->Unit(benchmark::kMicrosecond);

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  auto& s = summary();
  auto has = [&](const std::string& k) { return s.count(k) != 0; };
  // "x faster" when our time is lower, "x slower" when it is higher.
  auto verdict = [](double ours, double theirs) {
    char buf[48];
    if (ours <= theirs)
      std::snprintf(buf, sizeof buf, "grid %.2fx faster", theirs / ours);
    else
      std::snprintf(buf, sizeof buf, "grid %.2fx slower", ours / theirs);
    return std::string(buf);
  };
  const char* shapeNames[] = {"0.5 m box", "capsule", "8 m box"};
  std::printf("\n== Comparisons (same run; our grid with LOD off, exact shapes, vs Bullet 3.24)\n");
  for (uint32_t n : {10'000u, 100'000u}) {
    const std::string nk = std::to_string(n);
    for (int kind = 0; kind < 3; ++kind) {
      const std::string g = "grid_us_" + std::to_string(kind) + "_" + nk;
      if (!has(g)) continue;
      const double ours = s[g];
      std::printf("%-9s %6u bricks: grid %.2f us", shapeNames[kind], n, ours);
      const std::string c8 = "chunked_us_" + std::to_string(kind) + "_" + nk + "_" + std::to_string(kChosenChunkM);
      if (has(c8)) std::printf(" | btCompoundChunked %d m %.2f us: %s", kChosenChunkM, s[c8], verdict(ours, s[c8]).c_str());
      // The sweep's fastest chunk size for this shape, if another size won.
      int bestM = 0;
      for (int m : {2, 4, 8, 16, 32}) {
        const std::string k = "chunked_us_" + std::to_string(kind) + "_" + nk + "_" + std::to_string(m);
        if (has(k) && (!bestM || s[k] < s["chunked_us_" + std::to_string(kind) + "_" + nk + "_" + std::to_string(bestM)])) bestM = m;
      }
      if (bestM && bestM != kChosenChunkM) {
        const double b = s["chunked_us_" + std::to_string(kind) + "_" + nk + "_" + std::to_string(bestM)];
        std::printf(" | best chunk %d m %.2f us: %s", bestM, b, verdict(ours, b).c_str());
      }
      const std::string tr = "tree_us_" + std::to_string(kind) + "_" + nk;
      if (has(tr)) std::printf(" | btCompoundTree %.2f us: %s", s[tr], verdict(ours, s[tr]).c_str());
      if (kind == 0 && has("bt_us_" + nk))
        std::printf(" | naive btCompound (one compound, bounds boxes) %.1f us: %s", s["bt_us_" + nk], verdict(ours, s["bt_us_" + nk]).c_str());
      if (has(g + "_lod")) std::printf(" | grid LOD on %.2f us", s[g + "_lod"]);
      std::printf("\n");
    }
  }
  return 0;
}
