// bench_world: the world's body-level broadphase, justified by measurement.
//
//   build/release/bin/bench_world --benchmark_counters_tabular=true
//
// Broadphase/<method>/<bodies>: bodies falling onto a few huge static grids (the shape of the
// shipped scenes), moved every frame, pairs recomputed every frame:
//   SweepAndPrune  - the world's choice (sorted order kept between frames)
//   OctoBVH        - our OctoBVH over the bodies, every body updated then queried each frame
//   BruteForce     - all pairs (the floor any method must beat)
// Counters: pairs per frame, interval/box tests per frame.
#include <benchmark/benchmark.h>

#include "collision/core/seeded_random.h"
#include "collision/index/octobvh.h"
#include "world/broadphase.h"

namespace {

using namespace bw;

struct Bodies {
  std::vector<WorldAabb> bounds;
  std::vector<uint8_t> isStatic;
  std::vector<Vec3d> velocity;
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
  for (uint32_t i = 0; i < n; ++i) {
    const bool grid = i < 4;  // four large static grids
    const double cx = r.uniform(0, 500), cy = r.uniform(0, 500), cz = grid ? 10 : r.uniform(0, 60);  // in this order
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

void Broadphase_SweepAndPrune(benchmark::State& state) {
  Bodies b = makeBodies(uint32_t(state.range(0)));
  SweepAndPrune sap;
  std::vector<BodyPair> pairs;
  uint64_t tests = 0, found = 0;
  for (auto _ : state) {
    b.step();
    sap.update(b.bounds, b.isStatic, pairs);
    tests += sap.lastTests();
    found += pairs.size();
  }
  state.counters["pairs"] = benchmark::Counter(double(found), benchmark::Counter::kAvgIterations);
  state.counters["tests"] = benchmark::Counter(double(tests), benchmark::Counter::kAvgIterations);
}

void Broadphase_OctoBVH(benchmark::State& state) {
  Bodies b = makeBodies(uint32_t(state.range(0)));
  OctoBvh tree(OctoBvh::Config{uint32_t(b.bounds.size() + 64)});
  std::vector<uint32_t> handles;
  auto local = [](const WorldAabb& w) { return Aabb{w.min.cast<float>(), w.max.cast<float>()}; };
  for (uint32_t i = 0; i < b.bounds.size(); ++i) handles.push_back(tree.insert(local(b.bounds[i]), 1, i));
  std::vector<BodyPair> pairs;
  uint64_t found = 0;
  QueryStats st;
  for (auto _ : state) {
    b.step();
    for (uint32_t i = 0; i < b.bounds.size(); ++i)
      if (!b.isStatic[i]) tree.update(handles[i], local(b.bounds[i]), 1);
    pairs.clear();
    for (uint32_t i = 0; i < b.bounds.size(); ++i) {
      if (b.isStatic[i]) continue;
      tree.overlap(local(b.bounds[i]), 1, [&](uint32_t h) {
        const uint32_t j = tree.payload(h);
        if (j != i && (b.isStatic[j] || j > i)) pairs.push_back(i < j ? BodyPair{i, j} : BodyPair{j, i});
      }, &st);
    }
    std::sort(pairs.begin(), pairs.end());
    found += pairs.size();
  }
  state.counters["pairs"] = benchmark::Counter(double(found), benchmark::Counter::kAvgIterations);
  state.counters["tests"] = benchmark::Counter(double(st.boxTests), benchmark::Counter::kAvgIterations);
}

void Broadphase_BruteForce(benchmark::State& state) {
  Bodies b = makeBodies(uint32_t(state.range(0)));
  std::vector<BodyPair> pairs;
  uint64_t found = 0;
  for (auto _ : state) {
    b.step();
    pairs.clear();
    const uint32_t n = uint32_t(b.bounds.size());
    for (uint32_t i = 0; i < n; ++i)
      for (uint32_t j = i + 1; j < n; ++j)
        if (!(b.isStatic[i] && b.isStatic[j]) && b.bounds[i].overlaps(b.bounds[j])) pairs.push_back({i, j});
    found += pairs.size();
  }
  state.counters["pairs"] = benchmark::Counter(double(found), benchmark::Counter::kAvgIterations);
  state.counters["tests"] = double(state.range(0)) * double(state.range(0) - 1) / 2;
}

}  // namespace

BENCHMARK(Broadphase_SweepAndPrune)->Arg(1000)->Arg(2000)->Arg(5000)->Unit(benchmark::kMicrosecond);
BENCHMARK(Broadphase_OctoBVH)->Arg(1000)->Arg(2000)->Arg(5000)->Unit(benchmark::kMicrosecond);
BENCHMARK(Broadphase_BruteForce)->Arg(1000)->Arg(2000)->Arg(5000)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
