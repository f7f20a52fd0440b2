// bench_grid: brick grids vs Bullet's btCompoundShape of the same bricks.
//
//   build/release/bin/bench_grid --benchmark_counters_tabular=true
//
// GridContact/<shape>/<bricks>/lod:<0|1>: a 0.5 m box (0), a capsule (1) or an 8 m box (2) resting on a city-block grid
//   (poses found by raycasting onto its surface), time per contact query, contacts, narrowphase
//   calls, box tests, and with LOD the depth error against LOD off.
// GridEdit/<bricks>: place + remove one brick including index and mass properties.
// ConvexApprox/<build>/<depth>: hull build time, hull volume / brick volume, box or not.
// btCompound/<bricks>: the same bricks as a btCompoundShape: build time, bytes per brick,
//   contactPairTest time for the same poses. The summary prints the ratios.
#include <benchmark/benchmark.h>
#include <btBulletCollisionCommon.h>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>

#include "collision/bricks/brick_grid.h"
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

// ---------------------------------------------------------------- Bullet compound baseline

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

void btCompound(benchmark::State& state) {
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
  state.counters["bricks"] = double(bricks);
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
BENCHMARK(GridBuild)->Arg(10'000)->Arg(100'000)->Arg(2'000'000)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(btCompound)->Arg(10'000)->Arg(100'000)->Unit(benchmark::kMicrosecond);
BENCHMARK(ConvexApprox)->ArgsProduct({{0, 1, 2, 3, 4, 5}, {1, 2, 3, 4, 5}})->Unit(benchmark::kMicrosecond);

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  auto& s = summary();
  std::printf("\n== Comparisons (same run)\n");
  for (uint32_t n : {10'000u, 100'000u}) {
    const std::string k = std::to_string(n);
    if (s.count("bt_us_" + k) && s.count("grid_us_0_" + k))
      std::printf("box contact query, %u bricks: btCompoundShape %.1f us, grid %.2f us (LOD off), %.2f us (LOD on): %.0fx faster\n",
                  n, s["bt_us_" + k], s["grid_us_0_" + k], s["grid_us_0_" + k + "_lod"], s["bt_us_" + k] / s["grid_us_0_" + k]);
  }
  return 0;
}
