// The job system's merge (merge path) against std::merge on seeded sorted inputs with many ties
// (told apart by a tag the order ignores, so a's elements must come first on ties as in
// std::merge), empty and lopsided sides, and sizes on both sides of the serial threshold, at 1,
// 2, 4 and 16 threads. Labelled `concurrency`.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <utility>

#include "collision/core/seeded_random.h"
#include "jobs/parallel_merge.h"

namespace bw {
namespace {

using Item = std::pair<uint32_t, uint32_t>;  // (value, tag)
struct ByValue {
  bool operator()(const Item& x, const Item& y) const { return x.first < y.first; }
};

std::vector<Item> sortedInput(SeededRandom& r, uint32_t n, uint32_t range, uint32_t tag) {
  std::vector<Item> v(n);
  for (uint32_t i = 0; i < n; ++i) v[i] = {uint32_t(r.uniform(0, range)), tag + i};
  std::stable_sort(v.begin(), v.end(), ByValue{});
  return v;
}

TEST(ParallelMerge, EqualsStdMergeForAnyThreadCount) {
  SeededRandom r(5);
  const int threadCounts[] = {1, 2, 4, 16};
  std::vector<std::unique_ptr<JobSystem>> systems;
  for (int t : threadCounts) systems.push_back(std::make_unique<JobSystem>(t));
  const std::pair<uint32_t, uint32_t> sizes[] = {{0, 0}, {0, 5000}, {7000, 0}, {1, 1}, {2000, 2095}, {100000, 3}, {40000, 90000}};
  for (const auto& [na, nb] : sizes)
    for (const uint32_t range : {3u, 1000u, 1000000000u}) {  // mostly ties, some, almost none
      const std::vector<Item> a = sortedInput(r, na, range, 0), b = sortedInput(r, nb, range, 1u << 31);
      std::vector<Item> expected(na + nb);
      std::merge(a.begin(), a.end(), b.begin(), b.end(), expected.begin(), ByValue{});
      std::vector<Item> serial;
      parallelMerge(a, b, serial, nullptr, nullptr, "merge", 0, ByValue{});
      ASSERT_EQ(serial, expected) << na << " + " << nb << ", values below " << range;
      for (auto& jobs : systems) {
        Profiler profiler;
        std::vector<Item> out{{1, 1}};  // replaced whatever it held
        parallelMerge(a, b, out, jobs.get(), &profiler, "merge", 0, ByValue{});
        ASSERT_EQ(out, expected) << na << " + " << nb << ", values below " << range << ", " << jobs->threadCount() << " threads";
      }
    }
}

}  // namespace
}  // namespace bw
