// bench_world: the world's body-level broadphase, justified by measurement.
//
//   build/release/bin/bench_world --benchmark_counters_tabular=true
//
// Split_CutInTwo/<bricks>/<threads>: issue 18's cut: a static slab of cubes in two equal halves
//   joined by one brick, split on; World::removeBricks of that brick, timed from the removal to
//   the detached half's dynamic body made (connectivity search, its grid built in one pass, the
//   bricks taken out of the old grid, the body added), on a world of 1 or 2 threads (the build
//   and the removal run at once on two). Counters: parts, detached_bricks, search_ms (the
//   removal and the connectivity search), move_ms (the part's grid and body made: gather, index
//   build, bulk removal, mass, links), means over the cuts.
// Broadphase/<method>/<n>/iterations:<frames>/manual_time: issue 17's question, which
// broadphase at 1k, 10k, 100k and 1M bodies. n moving 0.5 m boxes fall onto huge static grids
// (400 x 400 x 40 m boxes, the shape of the shipped scenes), moved every frame (velocities flip
// every 120 frames), pairs recomputed every frame. The region is 500 m * sqrt(n / 5000) square
// with 4 grids per 500 x 500 m (at least 4): z stays 0-60 m, so the area follows n and the
// density stays constant. Every method runs the same frames (600, 120, 24, 12 at 1k-1M); its
// time is the pair finding alone (manual time: moving the bodies is left out):
//   IncrementalBroadphase - the world's choice, given a JobSystem(1): its parallel path (chunks,
//                       job-system sorts and merges, the tree's bulk builds) on one thread;
//                       pairs kept over fat boxes, found anew for bodies that left theirs
//   SweepAndPrune     - the world's broadphase until session 17 (every pair found every frame),
//                       on JobSystem(1)
//   btDbvtBroadphase  - Bullet's default broadphase as an expert sets it up for many moving
//                       bodies: proxies created once (statics in group StaticFilter, so no
//                       static-static pairs), setAabb for every moved proxy, then
//                       calculateOverlappingPairs and the pairs read from its pair cache;
//                       velocity prediction 2, the fastest of the settings tried (below)
//   btAxisSweep3      - Bullet's incremental sweep and prune, bt32BitAxisSweep3 (room for every
//                       proxy), world box 50 m around the scene, no raycast accelerator (it
//                       would mirror every proxy into a dbvt). Up to 10k only: creating a
//                       proxy sorts its edges in from the end of each axis, so the first frame
//                       is quadratic (10k: ~1 s; 100k, run once: 152 s for the first frame,
//                       then 268 ms a frame, 9x SweepAndPrune; 1M: hours)
//   OctoBVH           - our OctoBVH over all bodies, bulk-loaded, then every frame each moving
//                       body updated, then each queried
//   BruteForce        - all pairs, up to 10k (the floor any method must beat)
// Counters:
//   pairs          - overlapping pairs per frame (static-static ones excepted; Bullet's boxes
//                    are enlarged, so its cached pairs go through the exact box test, timed).
//                    Checked against SweepAndPrune's serial path (no job system) run outside
//                    the timing: the count every frame, the pairs themselves at the first and
//                    last frames. A row whose pairs differ fails (SkipWithError, an error line,
//                    and bench_world exits 1).
//   tests          - interval and box comparisons per frame (nan: Bullet does not count them)
//   cache_pairs    - pairs kept before the exact test: Bullet's cache, IncrementalBroadphase's
//                    fat-box pairs (nan for the others)
//   moved          - IncrementalBroadphase: bodies that left their fat boxes per frame
//   first_frame_ms - the first frame from a fresh structure (every proxy created or loaded,
//                    the pairs found), measured once before the timed frames; issue 17's goal:
//                    100k <= 100 ms, 1M <= 1.5 s on one thread
// Only our two sort their pairs (their determinism contract); the others leave theirs in their
// own order. The summary prints, per n, each method's frame and first-frame times and their
// ratios to IncrementalBroadphase's.
//
// BulletDbvtSettings/<setting>/<n> (10k and 100k; not matched by --benchmark_filter=Broadphase):
// the btDbvtBroadphase settings tried, same workload and counters. static-filter is the base
// (no-static-filter puts statics in DefaultFilter); deferred-collide sets m_deferedcollide (pairs
// found tree against tree in collide() instead of per updated proxy); optimize calls optimize()
// after creating the proxies; dupdates-1 re-inserts 1% of the moving tree per frame
// (m_dupdates); prediction-<p> is setVelocityPrediction(p) (leaves enlarged by p half-extents
// in the direction of motion, so a moving box leaves its leaf less often).
//
// WorldFrame/<engine>/<scene>: the shipped scene (crates_on_grid, city_rain, lighthouse) for
// its own frame count (300: landing and rest) on one thread, from the same initial state for
// every engine:
//   brickworld         - our World (its ray load included)
//   btCompoundChunked  - Bullet as an expert sets it up (world/bullet_baseline.h): static grids
//                        as 16 m chunk compounds, CCD, split impulse, the same ray load
//   btCompoundNaive    - each grid one btCompoundShape of one box per brick, no CCD (the
//                        article's "compounds" point; not run on city_rain: ~1 s a frame)
// Counters: median and p95 frame time (ms), contacts per frame; the summary prints the
// ratios, expert first. The scenes' render attachments are left out here (Bullet has no render
// side): these rows compare physics with physics.
//
// WorldRender/<mode>/<scene>: the world's frame steps 5-7 (transform update of the moved
// bodies' attachments, submission, commit to the render thread) in each submission mode, from
// the same initial state, on one thread:
//   Batched              - one atomic-append batch (a fetch_add per block of records), one commit
//   PerObjectMutex       - one command per record into a mutex-guarded queue (like for like:
//                          no light-radius refresh)
//   PerObjectConcurrent  - the same into oneTBB's lock-free concurrent_queue
// Counters: submission + commit ms per frame (measured, and predicted at 16 threads from the
// run's work/span with the mutex pushes serial), transform update ms, records per frame; the
// summary prints per-object / batched.
#include <benchmark/benchmark.h>

#include <btBulletCollisionCommon.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <span>
#include <string>

#include "collision/core/seeded_random.h"
#include "collision/index/octobvh.h"
#include "world/broadphase.h"
#include "world/incremental_broadphase.h"
#include "world/bullet_baseline.h"
#include "world/scene_file.h"
#include "world/world.h"

namespace {

using namespace bw;

// ---------------------------------------------------------------- broadphase at 1k-1M bodies

// The workload: n small moving boxes (0.5 m) falling onto huge static grids (400 x 400 x 40 m
// boxes), the shape of the shipped scenes. The region grows with n at constant density: x and
// y span side = 500 m * sqrt(n / 5000) (z stays 0-60 m, so the area, not the volume, follows
// n), and there are 4 grids per 500 x 500 m (at least 4). Proxies 0..grids-1 are the grids.
struct Bodies {
  std::vector<WorldAabb> bounds;
  std::vector<uint8_t> isStatic;
  std::vector<Vec3d> velocity;
  uint32_t grids = 0;
  uint64_t frame = 0;
  // Bodies move back and forth (velocities flip every 120 frames) so every benchmark, whatever
  // its iteration count, averages over the same distribution of positions.
  void step() {
    if (++frame % 120 == 0)
      for (Vec3d& v : velocity) v = -v;
    for (size_t i = 0; i < bounds.size(); ++i) {
      bounds[i].min += velocity[i] * (1.0 / 60);
      bounds[i].max += velocity[i] * (1.0 / 60);
    }
  }
};

Bodies makeBodies(uint32_t n) {
  SeededRandom r(1);
  Bodies b;
  const double side = 500.0 * std::sqrt(double(n) / 5000.0);
  b.grids = std::max<uint32_t>(4, uint32_t(std::lround(4.0 * side * side / (500.0 * 500.0))));
  for (uint32_t i = 0; i < b.grids + n; ++i) {
    const bool grid = i < b.grids;
    const double cx = r.uniform(0, side), cy = r.uniform(0, side), cz = grid ? 10 : r.uniform(0, 60);  // in this order
    const Vec3d c(cx, cy, cz);
    const Vec3d h = grid ? Vec3d(200, 200, 20) : Vec3d::Constant(0.25);
    b.bounds.push_back({c - h, c + h});
    b.isStatic.push_back(grid);
    if (grid) {
      b.velocity.push_back(Vec3d::Zero());
    } else {
      const double vx = r.normal(), vy = r.normal(), vz = -r.uniform(0, 5);  // in this order
      b.velocity.push_back(Vec3d(vx, vy, vz));
    }
  }
  return b;
}

const uint32_t kBroadphaseCounts[] = {1000, 10000, 100000, 1000000};
// Frames per row (the benchmark's iterations): every method runs the same frames of the same
// motion, so the rows average over identical work.
int64_t framesFor(uint32_t n) { return n <= 1000 ? 600 : n <= 10000 ? 120 : n <= 100000 ? 24 : 12; }

// The reference: SweepAndPrune's serial path (no job system), run once per n outside every
// timing, pair count per frame (frame 0 = the initial bounds, frame k = after k steps) and the
// pairs of frame 0 and of the last frame a row runs. Every row's pairs are checked against it.
struct Reference {
  Bodies bodies;
  SweepAndPrune sap;
  std::vector<uint64_t> counts;
  std::vector<BodyPair> first, last;
  uint64_t lastFrame = 0;
};

Reference& reference(uint32_t n, uint64_t frames) {
  static std::map<uint32_t, std::unique_ptr<Reference>> refs;
  std::unique_ptr<Reference>& ref = refs[n];
  if (!ref || ref->counts.size() > frames + 1) ref.reset();
  if (!ref) {
    ref = std::make_unique<Reference>();
    ref->bodies = makeBodies(n);
  }
  std::vector<BodyPair> pairs;
  while (ref->counts.size() <= frames) {
    if (!ref->counts.empty()) ref->bodies.step();
    ref->sap.update(ref->bodies.bounds, ref->bodies.isStatic, pairs);
    if (ref->counts.empty()) ref->first = pairs;
    ref->counts.push_back(pairs.size());
    ref->last = pairs;
    ref->lastFrame = ref->counts.size() - 1;
  }
  return *ref;
}

bool& broadphaseMismatch() {
  static bool any = false;
  return any;
}

// The pairs a method found for a frame, as the reference has them (sorted, a < b).
bool samePairs(std::vector<BodyPair> got, const std::vector<BodyPair>& want) {
  std::sort(got.begin(), got.end());
  return got == want;
}

struct BroadphaseFigures {
  double frameMs = 0, firstMs = 0, pairs = 0;
};
std::map<std::string, BroadphaseFigures>& broadphaseFigures() {  // "<method>/<n>" -> figures
  static std::map<std::string, BroadphaseFigures> m;
  return m;
}

double msSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

// One JobSystem(1) for the process (a JobSystem sets oneTBB's process-wide limit; the World
// rows make their own of the same thread count).
JobSystem& oneThread() {
  static JobSystem jobs(1);
  return jobs;
}

// A broadphase method under test: first(bodies, pairs) builds from scratch and finds frame 0's
// pairs; frame(bodies, pairs) finds the pairs after the bodies moved. Both replace `pairs` with
// every pair of overlapping bounds not both static, each once, a < b, in any order. tests()
// is the comparisons of the last call (NaN where the method does not count them), cachePairs()
// the pairs the method keeps before the exact test (NaN where it keeps none).
template <class Method>
void runBroadphase(benchmark::State& state, const char* name) {
  const uint32_t n = uint32_t(state.range(0));
  const uint64_t frames = uint64_t(state.max_iterations);
  const Reference& ref = reference(n, frames);
  Bodies b = makeBodies(n);
  std::vector<BodyPair> pairs;
  const auto fail = [&](const std::string& what) {
    broadphaseMismatch() = true;
    std::fprintf(stderr, "Broadphase/%s/%u: %s\n", name, n, what.c_str());
    state.SkipWithError(what.c_str());
  };
  oneThread();  // created (oneTBB's arena started) before any timing
  Method method;
  const auto t0 = std::chrono::steady_clock::now();
  method.first(b, pairs);
  const double firstMs = msSince(t0);
  if (!samePairs(pairs, ref.first)) {
    fail("frame 0: " + std::to_string(pairs.size()) + " pairs, SweepAndPrune has " + std::to_string(ref.first.size()));
    return;
  }
  double found = 0, tests = 0, cache = 0, moved = 0, totalMs = 0;
  bool ok = true;
  for (auto _ : state) {
    b.step();
    const auto t = std::chrono::steady_clock::now();
    method.frame(b, pairs);
    const double ms = msSince(t);
    state.SetIterationTime(ms / 1000);
    totalMs += ms;
    found += double(pairs.size());
    tests += method.tests();
    cache += method.cachePairs();
    if constexpr (requires { method.moved(); }) moved += method.moved();
    if (pairs.size() != ref.counts[b.frame]) {
      fail("frame " + std::to_string(b.frame) + ": " + std::to_string(pairs.size()) + " pairs, SweepAndPrune has " +
           std::to_string(ref.counts[b.frame]));
      ok = false;
      break;
    }
  }
  if (!ok) return;
  if (b.frame == ref.lastFrame && !samePairs(pairs, ref.last)) {
    fail("frame " + std::to_string(b.frame) + ": other pairs than SweepAndPrune's (same count)");
    return;
  }
  const double iters = double(std::max<int64_t>(1, state.iterations()));
  state.counters["pairs"] = found / iters;
  state.counters["tests"] = tests / iters;
  state.counters["cache_pairs"] = cache / iters;
  if constexpr (requires(Method m) { m.moved(); }) state.counters["moved"] = moved / iters;
  state.counters["first_frame_ms"] = firstMs;
  broadphaseFigures()[std::string(name) + "/" + std::to_string(n)] = {totalMs / iters, firstMs, found / iters};
}

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Ours: IncrementalBroadphase (the world's) on JobSystem(1), so the parallel code path (chunks,
// the job-system sample sorts, the tree's bulk build) runs, on one thread.
struct OurIncremental {
  IncrementalBroadphase bp;
  void first(const Bodies& b, std::vector<BodyPair>& pairs) { bp.update(b.bounds, b.isStatic, pairs, &oneThread()); }
  void frame(const Bodies& b, std::vector<BodyPair>& pairs) { bp.update(b.bounds, b.isStatic, pairs, &oneThread()); }
  double tests() const { return double(bp.lastTests()); }
  double cachePairs() const { return double(bp.fatPairs()); }
  double moved() const { return double(bp.lastMoved()); }
};

// The previous world broadphase: SweepAndPrune on JobSystem(1), every pair found every frame.
struct OurSweepAndPrune {
  SweepAndPrune sap;
  void first(const Bodies& b, std::vector<BodyPair>& pairs) { sap.update(b.bounds, b.isStatic, pairs, &oneThread()); }
  void frame(const Bodies& b, std::vector<BodyPair>& pairs) { sap.update(b.bounds, b.isStatic, pairs, &oneThread()); }
  double tests() const { return double(sap.lastTests()); }
  double cachePairs() const { return kNaN; }
};

btVector3 bt(const Vec3d& v) { return btVector3(btScalar(v.x()), btScalar(v.y()), btScalar(v.z())); }

// Bullet's pair cache, read as a user reads it: every cached pair whose proxies' current boxes
// overlap (Bullet keeps pairs of its enlarged boxes, and drops stale ones a share per frame;
// rounding to float only widens, so the cache holds every overlapping pair). Proxy user
// pointers are body index + 1.
void readBulletPairs(btOverlappingPairCache& cache, const Bodies& b, std::vector<BodyPair>& pairs) {
  pairs.clear();
  const int count = cache.getNumOverlappingPairs();
  const btBroadphasePair* p = cache.getOverlappingPairArrayPtr();
  for (int k = 0; k < count; ++k) {
    const uint32_t i = uint32_t(reinterpret_cast<uintptr_t>(p[k].m_pProxy0->m_clientObject) - 1);
    const uint32_t j = uint32_t(reinterpret_cast<uintptr_t>(p[k].m_pProxy1->m_clientObject) - 1);
    if ((b.isStatic[i] && b.isStatic[j]) || !b.bounds[i].overlaps(b.bounds[j])) continue;
    pairs.push_back(i < j ? BodyPair{i, j} : BodyPair{j, i});
  }
}

// Collision filters as Bullet sets them for static objects: static proxies in group
// StaticFilter with every group but StaticFilter in their mask, so static-static pairs never
// enter the cache; with staticFilter off, every proxy is in DefaultFilter with mask AllFilter.
void bulletFilter(const Bodies& b, uint32_t i, bool staticFilter, int& group, int& mask) {
  const bool s = staticFilter && b.isStatic[i];
  group = s ? int(btBroadphaseProxy::StaticFilter) : int(btBroadphaseProxy::DefaultFilter);
  mask = s ? int(btBroadphaseProxy::AllFilter ^ btBroadphaseProxy::StaticFilter) : int(btBroadphaseProxy::AllFilter);
}

// btDbvtBroadphase settings tried (BulletDbvtSettings/* rows; the Broadphase/btDbvtBroadphase
// rows use kDbvtChosen).
struct DbvtSettings {
  bool staticFilter = true;   // static proxies in StaticFilter (static-static pairs skipped)
  bool deferred = false;      // m_deferedcollide: pairs found by tree-vs-tree in collide()
  bool optimize = false;      // optimize() (top-down rebuild of both trees) after the proxies are created
  int dupdates = 0;           // m_dupdates: % of the moving tree re-inserted per frame
  float prediction = 0;       // setVelocityPrediction
};

// What both Bullet rows share: the dispatcher calculateOverlappingPairs needs, one proxy per
// body (client object = index + 1), every moving proxy moved each frame, pairs read from the
// cache through the exact box test.
template <class Broadphase>
struct BulletBroadphaseRow {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  std::unique_ptr<Broadphase> bp;
  std::vector<btBroadphaseProxy*> proxies;
  double cached = 0;
  void createProxies(const Bodies& b, bool staticFilter) {
    proxies.resize(b.bounds.size());
    for (uint32_t i = 0; i < b.bounds.size(); ++i) {
      int group, mask;
      bulletFilter(b, i, staticFilter, group, mask);
      proxies[i] = bp->createProxy(bt(b.bounds[i].min), bt(b.bounds[i].max), BOX_SHAPE_PROXYTYPE,
                                   reinterpret_cast<void*>(uintptr_t(i) + 1), group, mask, &dispatcher);
    }
  }
  void frame(const Bodies& b, std::vector<BodyPair>& pairs) {
    for (uint32_t i = b.grids; i < b.bounds.size(); ++i)  // the moving proxies: every one moved
      bp->setAabb(proxies[i], bt(b.bounds[i].min), bt(b.bounds[i].max), &dispatcher);
    findPairs(b, pairs);
  }
  void findPairs(const Bodies& b, std::vector<BodyPair>& pairs) {
    bp->calculateOverlappingPairs(&dispatcher);
    cached = bp->getOverlappingPairCache()->getNumOverlappingPairs();
    readBulletPairs(*bp->getOverlappingPairCache(), b, pairs);
  }
  double tests() const { return kNaN; }
  double cachePairs() const { return cached; }
};

template <const DbvtSettings& S>
struct BulletDbvt : BulletBroadphaseRow<btDbvtBroadphase> {
  void first(const Bodies& b, std::vector<BodyPair>& pairs) {
    bp = std::make_unique<btDbvtBroadphase>();
    bp->m_deferedcollide = S.deferred;
    bp->m_dupdates = S.dupdates;
    bp->setVelocityPrediction(S.prediction);
    createProxies(b, S.staticFilter);
    if (S.optimize) bp->optimize();
    findPairs(b, pairs);
  }
};

constexpr DbvtSettings kDbvtNoFilter{.staticFilter = false};
constexpr DbvtSettings kDbvtStatic{};
constexpr DbvtSettings kDbvtDeferred{.deferred = true};
constexpr DbvtSettings kDbvtOptimize{.optimize = true};
constexpr DbvtSettings kDbvtDupdates{.dupdates = 1};
constexpr DbvtSettings kDbvtPrediction{.prediction = 0.5f};
constexpr DbvtSettings kDbvtDeferredOptimize{.deferred = true, .optimize = true};
constexpr DbvtSettings kDbvtPrediction1{.prediction = 1};
constexpr DbvtSettings kDbvtPrediction2{.prediction = 2};
constexpr DbvtSettings kDbvtPrediction4{.prediction = 4};
constexpr DbvtSettings kDbvtDeferredPrediction05{.deferred = true, .prediction = 0.5f};
constexpr DbvtSettings kDbvtDeferredPrediction1{.deferred = true, .prediction = 1};
constexpr DbvtSettings kDbvtDeferredPrediction2{.deferred = true, .prediction = 2};
constexpr const DbvtSettings& kDbvtChosen = kDbvtPrediction2;

// bt32BitAxisSweep3: Bullet's incremental sweep and prune (32-bit quantized edges, so it holds
// far more than 1M handles), the world box 50 m around the scene, no raycast accelerator (it
// would mirror every proxy into a second, dbvt, broadphase; nothing here casts rays).
struct BulletAxisSweep : BulletBroadphaseRow<bt32BitAxisSweep3> {
  void first(const Bodies& b, std::vector<BodyPair>& pairs) {
    Vec3d lo = b.bounds[0].min, hi = b.bounds[0].max;
    for (const WorldAabb& w : b.bounds) {
      lo = lo.cwiseMin(w.min);
      hi = hi.cwiseMax(w.max);
    }
    bp = std::make_unique<bt32BitAxisSweep3>(bt(lo - Vec3d::Constant(50)), bt(hi + Vec3d::Constant(50)),
                                             unsigned(b.bounds.size() + 1), nullptr, true);
    createProxies(b, true);
    findPairs(b, pairs);
  }
};

// Our OctoBVH over all bodies (statics filter 2, moving 1): built in bulk, then every frame
// each moving body updated, then each queried. Float boxes rounded outwards, candidates kept
// by the exact double test.
struct OctoBvhPerBody {
  std::unique_ptr<OctoBvh> tree;
  std::vector<uint32_t> handles;
  QueryStats st;
  static Aabb local(const WorldAabb& w) {
    Aabb a;
    for (int k = 0; k < 3; ++k) {
      float lo = float(w.min[k]), hi = float(w.max[k]);
      if (double(lo) > w.min[k]) lo = std::nextafter(lo, -std::numeric_limits<float>::infinity());
      if (double(hi) < w.max[k]) hi = std::nextafter(hi, std::numeric_limits<float>::infinity());
      a.min[k] = lo;
      a.max[k] = hi;
    }
    return a;
  }
  void first(const Bodies& b, std::vector<BodyPair>& pairs) {
    tree = std::make_unique<OctoBvh>(OctoBvh::Config{uint32_t(b.bounds.size() + 64)});
    std::vector<Aabb> boxes;
    std::vector<uint32_t> filters, payloads;
    for (uint32_t i = 0; i < b.bounds.size(); ++i) {
      boxes.push_back(local(b.bounds[i]));
      filters.push_back(b.isStatic[i] ? 2 : 1);
      payloads.push_back(i);
    }
    handles = tree->bulkLoad(boxes, filters, payloads);
    query(b, pairs);
  }
  void frame(const Bodies& b, std::vector<BodyPair>& pairs) {
    for (uint32_t i = b.grids; i < b.bounds.size(); ++i) tree->update(handles[i], local(b.bounds[i]), 1);
    query(b, pairs);
  }
  void query(const Bodies& b, std::vector<BodyPair>& pairs) {
    st = {};
    pairs.clear();
    for (uint32_t i = 0; i < b.bounds.size(); ++i) {
      if (b.isStatic[i]) continue;
      tree->overlap(local(b.bounds[i]), 3, [&](uint32_t h) {
        const uint32_t j = tree->payload(h);
        if (j != i && (b.isStatic[j] || j > i) && b.bounds[i].overlaps(b.bounds[j])) pairs.push_back(i < j ? BodyPair{i, j} : BodyPair{j, i});
      }, &st);
    }
  }
  double tests() const { return double(st.boxTests); }
  double cachePairs() const { return kNaN; }
};

// All pairs (the floor any method must beat).
struct BruteForce {
  uint64_t n = 0;
  void first(const Bodies& b, std::vector<BodyPair>& pairs) { frame(b, pairs); }
  void frame(const Bodies& b, std::vector<BodyPair>& pairs) {
    pairs.clear();
    n = b.bounds.size();
    for (uint32_t i = 0; i < n; ++i)
      for (uint32_t j = i + 1; j < n; ++j)
        if (!(b.isStatic[i] && b.isStatic[j]) && b.bounds[i].overlaps(b.bounds[j])) pairs.push_back({i, j});
  }
  double tests() const { return double(n) * double(n - 1) / 2; }
  double cachePairs() const { return kNaN; }
};

void printBroadphaseRatios() {
  const auto& m = broadphaseFigures();
  const auto key = [](const char* method, uint32_t n) { return std::string(method) + '/' + std::to_string(n); };
  for (uint32_t n : kBroadphaseCounts) {
    if (!m.count(key("IncrementalBroadphase", n))) continue;
    const BroadphaseFigures& ours = m.at(key("IncrementalBroadphase", n));
    std::printf("broadphase, %u moving bodies (%.0f pairs): IncrementalBroadphase %.3f ms a frame, first frame %.1f ms", n, ours.pairs,
                ours.frameMs, ours.firstMs);
    for (const char* other : {"SweepAndPrune", "btDbvtBroadphase", "btAxisSweep3", "OctoBVH", "BruteForce"}) {
      if (!m.count(key(other, n))) continue;
      const BroadphaseFigures& f = m.at(key(other, n));
      std::printf("; %s %.3f ms (%.1fx), first %.1f ms (%.1fx)", other, f.frameMs, f.frameMs / std::max(ours.frameMs, 1e-9), f.firstMs,
                  f.firstMs / std::max(ours.firstMs, 1e-9));
    }
    std::printf("\n");
  }
  if (broadphaseMismatch()) std::printf("broadphase: a method's pairs differ from SweepAndPrune's (see the errors above)\n");
}


// ---------------------------------------------------------------- whole frames vs Bullet

const char* const kScenes[] = {"crates_on_grid", "city_rain", "lighthouse"};
enum Engine { kBrickworld = 0, kBulletChunked = 1, kBulletNaive = 2 };
const char* const kEngineNames[] = {"brickworld", "btCompoundChunked", "btCompoundNaive"};

std::map<std::string, double>& medians() {  // "<engine>/<scene>" -> median frame ms
  static std::map<std::string, double> m;
  return m;
}

double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[std::min(v.size() - 1, size_t(q * double(v.size() - 1) + 0.5))];
}

void WorldFrame(benchmark::State& state, Engine engine, const char* scene) {
  SceneDescription description = loadScene(std::string(BW_SOURCE_DIR) + "/profiles/scenes/" + scene + ".json");
  description.attachments = AttachmentsDescription{};  // physics against physics
  std::vector<double> frameMs;
  uint64_t contacts = 0;
  for (auto _ : state) {
    World world(description, 1);
    std::unique_ptr<BulletBaseline> bullet;
    if (engine != kBrickworld)
      bullet = std::make_unique<BulletBaseline>(world, engine == kBulletChunked ? BulletSetup::Expert : BulletSetup::Naive);
    for (uint32_t f = 0; f < description.settings.frames; ++f) {
      const auto t = std::chrono::steady_clock::now();
      if (bullet) bullet->step();
      else world.step();
      frameMs.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count());
      contacts += bullet ? bullet->lastFrame().contacts : world.lastStats().contacts;
    }
  }
  const double median = quantile(frameMs, 0.5);
  medians()[std::string(kEngineNames[engine]) + "/" + scene] = median;
  state.counters["frame_ms_median"] = median;
  state.counters["frame_ms_p95"] = quantile(frameMs, 0.95);
  state.counters["contacts_per_frame"] = double(contacts) / double(frameMs.size());
}

// ---------------------------------------------------------------- the render frame per mode

const char* const kRenderScenes[] = {"crates_on_grid", "carrier_fleet"};
const SubmissionMode kRenderModes[] = {SubmissionMode::Batched, SubmissionMode::PerObjectMutexNoRadius,
                                       SubmissionMode::PerObjectConcurrentNoRadius};
const char* renderModeName(SubmissionMode m) {
  return m == SubmissionMode::Batched ? "Batched" : m == SubmissionMode::PerObjectMutexNoRadius ? "PerObjectMutex" : "PerObjectConcurrent";
}

std::map<std::string, std::pair<double, double>>& renderFigures() {  // "<mode>/<scene>" -> (measured, predicted at 16) ms
  static std::map<std::string, std::pair<double, double>> m;
  return m;
}

void WorldRenderFrame(benchmark::State& state, SubmissionMode mode, const char* scene) {
  const SceneDescription description = loadScene(std::string(BW_SOURCE_DIR) + "/profiles/scenes/" + scene + ".json");
  constexpr uint32_t kFrames = 60;
  double submitCommit = 0, update = 0, predicted16 = 0;
  uint64_t records = 0;
  for (auto _ : state) {
    World world(description, 1, mode);
    for (uint32_t f = 0; f < kFrames; ++f) {
      world.step();
      const RenderStageStats& r = world.lastStats().render;
      submitCommit += r.submissionMs + r.commitMs;
      update += r.updateMs;
      records += r.primitives + r.lights;
    }
    world.renderScene();
    // Submission + commit at 16 threads: per stage max(work / 16, span); the mutex queue's
    // pushes are serial zones, all in the span.
    for (const WorkSpan& ws : world.profiler().workSpans(kFrames)) predicted16 += predictedRenderMs(ws, world.renderStage(), 16);
  }
  const double frames = double(kFrames) * double(state.iterations());
  renderFigures()[std::string(renderModeName(mode)) + "/" + scene] = {submitCommit / frames, predicted16 / frames};
  state.counters["submit_commit_ms"] = submitCommit / frames;
  state.counters["submit_commit_ms_16thr"] = predicted16 / frames;
  state.counters["update_ms"] = update / frames;
  state.counters["records_per_frame"] = double(records) / frames;
}

void printRenderRatios() {
  const auto& m = renderFigures();
  for (const char* scene : kRenderScenes) {
    const std::string b = std::string("Batched/") + scene;
    if (!m.count(b)) continue;
    std::printf("%s: batched submission + commit %.3f ms a frame (%.3f predicted at 16 threads)", scene, m.at(b).first, m.at(b).second);
    for (const char* other : {"PerObjectMutex", "PerObjectConcurrent"}) {
      const std::string k = std::string(other) + "/" + scene;
      if (m.count(k))
        std::printf("; %s %.1fx (%.1fx at 16)", other, m.at(k).first / std::max(m.at(b).first, 1e-9),
                    m.at(k).second / std::max(m.at(b).second, 1e-9));
    }
    std::printf("\n");
  }
}

void printWorldRatios() {
  const auto& m = medians();
  for (const char* scene : kScenes) {
    const std::string s = scene;
    if (!m.count("brickworld/" + s)) continue;
    const double ours = std::max(m.at("brickworld/" + s), 1e-9);
    std::printf("%s: brickworld %.3f ms a frame (median)", scene, ours);
    if (m.count("btCompoundChunked/" + s))
      std::printf("; Bullet as an expert sets it up %.3f ms (%.1fx)", m.at("btCompoundChunked/" + s), m.at("btCompoundChunked/" + s) / ours);
    if (m.count("btCompoundNaive/" + s))
      std::printf("; naive single compound %.3f ms (%.1fx)", m.at("btCompoundNaive/" + s), m.at("btCompoundNaive/" + s) / ours);
    std::printf("\n");
  }
}


void Split_CutInTwo(benchmark::State& state) {
  const int side = int(std::sqrt(double(state.range(0)) / 2.0));
  SceneDescription scene;
  scene.name = "cut";
  GridDescription slab;
  slab.name = "slab";
  slab.split = true;
  for (int half = 0; half < 2; ++half)
    for (int x = 0; x < side; ++x)
      for (int y = 0; y < side; ++y) slab.bricks.push_back(Brick::box(Vec3f(float(x + half * (side + 1)), float(y), 0), Vec3f::Constant(0.5f)));
  slab.bricks.push_back(Brick::box(Vec3f(float(side), float(side / 2), 0), Vec3f::Constant(0.5f)));  // the joint, last
  scene.grids = {slab};
  uint32_t parts = 0, detached = 0;
  double searchMs = 0, moveMs = 0;
  for (auto _ : state) {
    World world(scene, int(state.range(1)));  // each cut needs the slab whole again (not timed)
    const uint32_t joint = uint32_t(slab.bricks.size() - 1);
    if (!world.grid(0).hasBrick(joint) || world.grid(0).brick(joint).position != slab.bricks.back().position) {
      state.SkipWithError("the joint's brick id is not the last one");
      return;
    }
    const World::RemovalResult r = world.removeBricks(0, std::span<const uint32_t>(&joint, 1));
    state.SetIterationTime(r.ms * 1e-3);
    searchMs += r.ms - r.partBodiesMs;
    moveMs += r.partBodiesMs;
    parts = r.parts;
    detached = world.bodies().size() > 1 ? world.grid(1).brickCount() : 0;
  }
  state.counters["bricks"] = double(slab.bricks.size());
  state.counters["parts"] = parts;
  state.counters["detached_bricks"] = detached;
  const double cuts = double(std::max<int64_t>(1, state.iterations()));
  state.counters["search_ms"] = searchMs / cuts;
  state.counters["move_ms"] = moveMs / cuts;
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::RegisterBenchmark("Split_CutInTwo", Split_CutInTwo)
      ->ArgNames({"", "threads"})
      ->Args({100'000, 1})
      ->Args({100'000, 2})
      ->Iterations(5)->UseManualTime()->Unit(benchmark::kMillisecond);
  // Broadphase rows: per method, every body count; the same frames (iterations) for every method.
  const auto add = [](const std::string& name, uint32_t n, void (*fn)(benchmark::State&)) {
    benchmark::RegisterBenchmark(name.c_str(), fn)->Arg(n)->Iterations(framesFor(n))->UseManualTime()->Unit(benchmark::kMillisecond);
  };
  for (uint32_t n : kBroadphaseCounts)
    add("Broadphase/IncrementalBroadphase", n, [](benchmark::State& s) { runBroadphase<OurIncremental>(s, "IncrementalBroadphase"); });
  for (uint32_t n : kBroadphaseCounts)
    add("Broadphase/SweepAndPrune", n, [](benchmark::State& s) { runBroadphase<OurSweepAndPrune>(s, "SweepAndPrune"); });
  for (uint32_t n : kBroadphaseCounts)
    add("Broadphase/btDbvtBroadphase", n, [](benchmark::State& s) { runBroadphase<BulletDbvt<kDbvtChosen>>(s, "btDbvtBroadphase"); });
  for (uint32_t n : kBroadphaseCounts)
    if (n <= 10000) add("Broadphase/btAxisSweep3", n, [](benchmark::State& s) { runBroadphase<BulletAxisSweep>(s, "btAxisSweep3"); });
  for (uint32_t n : kBroadphaseCounts)
    add("Broadphase/OctoBVH", n, [](benchmark::State& s) { runBroadphase<OctoBvhPerBody>(s, "OctoBVH"); });
  for (uint32_t n : kBroadphaseCounts)
    if (n <= 10000) add("Broadphase/BruteForce", n, [](benchmark::State& s) { runBroadphase<BruteForce>(s, "BruteForce"); });
  // The btDbvtBroadphase settings tried (not matched by --benchmark_filter=Broadphase).
  for (uint32_t n : {10000u, 100000u}) {
    add("BulletDbvtSettings/no-static-filter", n, [](benchmark::State& s) { runBroadphase<BulletDbvt<kDbvtNoFilter>>(s, "dbvt-no-static-filter"); });
    add("BulletDbvtSettings/static-filter", n, [](benchmark::State& s) { runBroadphase<BulletDbvt<kDbvtStatic>>(s, "dbvt-static-filter"); });
    add("BulletDbvtSettings/deferred-collide", n, [](benchmark::State& s) { runBroadphase<BulletDbvt<kDbvtDeferred>>(s, "dbvt-deferred"); });
    add("BulletDbvtSettings/optimize", n, [](benchmark::State& s) { runBroadphase<BulletDbvt<kDbvtOptimize>>(s, "dbvt-optimize"); });
    add("BulletDbvtSettings/deferred-optimize", n,
        [](benchmark::State& s) { runBroadphase<BulletDbvt<kDbvtDeferredOptimize>>(s, "dbvt-deferred-optimize"); });
    add("BulletDbvtSettings/dupdates-1", n, [](benchmark::State& s) { runBroadphase<BulletDbvt<kDbvtDupdates>>(s, "dbvt-dupdates"); });
    add("BulletDbvtSettings/prediction-0.5", n, [](benchmark::State& s) { runBroadphase<BulletDbvt<kDbvtPrediction>>(s, "dbvt-prediction"); });
    add("BulletDbvtSettings/prediction-1", n, [](benchmark::State& s) { runBroadphase<BulletDbvt<kDbvtPrediction1>>(s, "dbvt-prediction-1"); });
    add("BulletDbvtSettings/prediction-2", n, [](benchmark::State& s) { runBroadphase<BulletDbvt<kDbvtPrediction2>>(s, "dbvt-prediction-2"); });
    add("BulletDbvtSettings/prediction-4", n, [](benchmark::State& s) { runBroadphase<BulletDbvt<kDbvtPrediction4>>(s, "dbvt-prediction-4"); });
    add("BulletDbvtSettings/deferred-prediction-0.5", n,
        [](benchmark::State& s) { runBroadphase<BulletDbvt<kDbvtDeferredPrediction05>>(s, "dbvt-deferred-prediction-0.5"); });
    add("BulletDbvtSettings/deferred-prediction-1", n,
        [](benchmark::State& s) { runBroadphase<BulletDbvt<kDbvtDeferredPrediction1>>(s, "dbvt-deferred-prediction-1"); });
    add("BulletDbvtSettings/deferred-prediction-2", n,
        [](benchmark::State& s) { runBroadphase<BulletDbvt<kDbvtDeferredPrediction2>>(s, "dbvt-deferred-prediction-2"); });
  }
  for (const char* scene : kScenes)
    for (Engine e : {kBrickworld, kBulletChunked, kBulletNaive}) {
      if (e == kBulletNaive && std::string(scene) == "city_rain") continue;
      benchmark::RegisterBenchmark((std::string("WorldFrame/") + kEngineNames[e] + "/" + scene).c_str(), WorldFrame, e, scene)
          ->Iterations(1)
          ->Unit(benchmark::kMillisecond);
    }
  for (const char* scene : kRenderScenes)
    for (SubmissionMode mode : kRenderModes)
      benchmark::RegisterBenchmark((std::string("WorldRender/") + renderModeName(mode) + "/" + scene).c_str(), WorldRenderFrame, mode,
                                   scene)
          ->Iterations(1)
          ->Unit(benchmark::kMillisecond);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  printBroadphaseRatios();
  printWorldRatios();
  printRenderRatios();
  return broadphaseMismatch() ? 1 : 0;
}
