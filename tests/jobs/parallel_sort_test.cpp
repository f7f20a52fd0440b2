// The job system's sample sort against std::sort (+ std::unique) on seeded inputs with many
// repeats, all equal, sorted, reversed, and sizes on both sides of the serial threshold, at 1, 2,
// 4 and 16 threads: the same output for every thread count. Labelled `concurrency`.
#include <gtest/gtest.h>

#include <algorithm>
#include <utility>

#include "collision/core/seeded_random.h"
#include "jobs/parallel_sort.h"

namespace bw {
namespace {

using Item = std::pair<uint32_t, uint32_t>;

std::vector<Item> makeInput(SeededRandom& r, uint32_t n, int kind) {
  std::vector<Item> v(n);
  for (uint32_t i = 0; i < n; ++i) {
    switch (kind) {
      case 0: v[i] = {uint32_t(r.uniform(0, 1e9)), uint32_t(r.uniform(0, 1e9))}; break;  // distinct (almost)
      case 1: v[i] = {uint32_t(r.uniform(0, 30)), uint32_t(r.uniform(0, 3))}; break;     // many repeats
      case 2: v[i] = {7, 7}; break;                                                       // all equal
      case 3: v[i] = {i / 3, i % 3}; break;                                               // sorted
      default: v[i] = {n - i, 0}; break;                                                  // reversed
    }
  }
  return v;
}

TEST(ParallelSort, EqualsStdSortForAnyThreadCount) {
  SeededRandom r(3);
  const int threadCounts[] = {1, 2, 4, 16};
  std::vector<std::unique_ptr<JobSystem>> systems;
  for (int t : threadCounts) systems.push_back(std::make_unique<JobSystem>(t));
  ParallelSorter<Item> sorter;  // reused across sizes: the scratch must not leak between calls
  for (const uint32_t n : {0u, 1u, 511u, 512u, 513u, 5000u, 70000u}) {
    for (int kind = 0; kind < 5; ++kind) {
      const std::vector<Item> input = makeInput(r, n, kind);
      for (const bool unique : {false, true}) {
        std::vector<Item> expected = input;
        std::sort(expected.begin(), expected.end());
        if (unique) expected.erase(std::unique(expected.begin(), expected.end()), expected.end());
        for (size_t t = 0; t < systems.size(); ++t) {
          std::vector<Item> v = input;
          Profiler profiler;
          sorter.sort(v, unique, *systems[t], &profiler, "sort", 10);
          ASSERT_EQ(v, expected) << "n " << n << " kind " << kind << " unique " << unique << " threads " << threadCounts[t];
          for (const ProfileEvent& e : profiler.events()) {
            EXPECT_GE(e.stage, 10);
            EXPECT_LE(e.stage, 13);
          }
        }
      }
    }
  }
}

TEST(ParallelSort, CustomOrder) {
  SeededRandom r(4);
  JobSystem jobs(4);
  std::vector<double> v(20000);
  for (double& x : v) x = r.normal();
  std::vector<double> expected = v;
  std::sort(expected.begin(), expected.end(), std::greater<double>());
  ParallelSorter<double, std::greater<double>> sorter;
  sorter.sort(v, false, jobs, nullptr, "sort", 0);
  EXPECT_EQ(v, expected);
}

}  // namespace
}  // namespace bw
