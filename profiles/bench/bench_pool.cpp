// bench_pool: VirtualPool vs std::vector — growth cost, worst single push ("no hitch"), churn.
//
//   build/release/bin/bench_pool --benchmark_counters_tabular=true
//
// Counters: ns_per_op (mean), worst_push_us (the slowest single push of the run: for
// std::vector this is the reallocation that copies every element), resident_MiB.
#include <algorithm>
#include <benchmark/benchmark.h>
#include <chrono>
#include <random>
#include <vector>

#include "collision/core/virtual_pool.h"

namespace {

struct Brick32 {  // the size of a compact brick record
  float data[8];
};

using Clock = std::chrono::steady_clock;

template <class PushFn>
void timeGrowth(benchmark::State& state, PushFn&& push, uint32_t n) {
  double worst = 0, total = 0;
  for (uint32_t i = 0; i < n; ++i) {
    const auto a = Clock::now();
    push(i);
    const double ns = std::chrono::duration<double, std::nano>(Clock::now() - a).count();
    total += ns;
    worst = std::max(worst, ns);
  }
  state.counters["ns_per_op"] = total / n;
  state.counters["worst_push_us"] = worst / 1000;
}

void PoolGrow_VirtualPool(benchmark::State& state) {
  const uint32_t n = uint32_t(state.range(0));
  for (auto _ : state) {
    bw::VirtualPool<Brick32> pool(n, "bench");
    timeGrowth(state, [&](uint32_t i) { pool[pool.allocate()].data[0] = float(i); }, n);
    state.counters["resident_MiB"] = double(pool.residentBytes()) / 1048576.0;
    benchmark::DoNotOptimize(pool[n / 2]);
  }
}

void PoolGrow_StdVector(benchmark::State& state) {
  const uint32_t n = uint32_t(state.range(0));
  for (auto _ : state) {
    std::vector<Brick32> v;
    timeGrowth(state, [&](uint32_t i) { v.push_back(Brick32{{float(i)}}); }, n);
    state.counters["resident_MiB"] = double(v.capacity() * sizeof(Brick32)) / 1048576.0;
    benchmark::DoNotOptimize(v[n / 2]);
  }
}

// Steady state: `live` elements, then random free + allocate pairs (a player editing a build).
// Time per iteration is one free plus one allocate.
void PoolChurn_VirtualPool(benchmark::State& state) {
  const uint32_t live = uint32_t(state.range(0));
  bw::VirtualPool<Brick32> pool(live * 2, "bench");
  std::vector<uint32_t> ids(live);
  for (auto& id : ids) id = pool.allocate();
  std::mt19937 rng(1);
  for (auto _ : state) {
    const uint32_t k = rng() % live;
    pool.free(ids[k]);
    ids[k] = pool.allocate();
    pool[ids[k]].data[0] = 1.f;
  }
}

// Baseline: std::vector with an index free list (the usual hand-rolled slot map).
void PoolChurn_StdVectorFreeList(benchmark::State& state) {
  const uint32_t live = uint32_t(state.range(0));
  std::vector<Brick32> v(live);
  std::vector<uint32_t> freeList;
  std::vector<uint32_t> ids(live);
  for (uint32_t i = 0; i < live; ++i) ids[i] = i;
  std::mt19937 rng(1);
  for (auto _ : state) {
    const uint32_t k = rng() % live;
    freeList.push_back(ids[k]);
    ids[k] = freeList.back();
    freeList.pop_back();
    v[ids[k]].data[0] = 1.f;
  }
}

}  // namespace

BENCHMARK(PoolGrow_VirtualPool)->Arg(1'000'000)->Arg(10'000'000)->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(false)->Unit(benchmark::kMillisecond);
BENCHMARK(PoolGrow_StdVector)->Arg(1'000'000)->Arg(10'000'000)->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(false)->Unit(benchmark::kMillisecond);
BENCHMARK(PoolChurn_VirtualPool)->Arg(1'000'000);
BENCHMARK(PoolChurn_StdVectorFreeList)->Arg(1'000'000);

BENCHMARK_MAIN();
