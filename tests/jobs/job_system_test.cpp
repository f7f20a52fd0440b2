// JobSystem: every item visited once, fixed chunking, bit-identical reductions per thread count.
#include <atomic>
#include <cmath>
#include <cstring>
#include <gtest/gtest.h>
#include <vector>

#include "collision/core/argument_checks.h"
#include "jobs/job_system.h"

namespace bw {
namespace {

// Sum of a float series done per chunk and merged in chunk order: identical for any thread count
// only if chunk boundaries do not depend on scheduling.
double chunkedSum(JobSystem& jobs, const std::vector<float>& v, uint32_t grain) {
  std::vector<float> partial(JobSystem::chunkCount(0, uint32_t(v.size()), grain), 0.f);
  jobs.parallelFor(0, uint32_t(v.size()), grain, [&](uint32_t b, uint32_t e) {
    float s = 0.f;
    for (uint32_t i = b; i < e; ++i) s += v[i];
    partial[b / grain] = s;
  });
  double total = 0;
  for (float p : partial) total += p;
  return total;
}

TEST(JobSystem, EveryItemOnceAndDeterministicAcrossThreadCounts) {
  std::vector<float> values(200'003);
  for (size_t i = 0; i < values.size(); ++i) values[i] = std::sin(float(i)) * 1e3f + 1e-3f * float(i % 7);
  double reference = 0;
  for (int threads : {1, 2, 4, 16}) {
    JobSystem jobs(threads);
    std::vector<std::atomic<int>> visits(values.size());
    jobs.parallelFor(0, uint32_t(values.size()), 97, [&](uint32_t b, uint32_t e) {
      EXPECT_EQ(b % 97, 0u) << "chunk boundaries are fixed multiples of the grain";
      for (uint32_t i = b; i < e; ++i) visits[i].fetch_add(1, std::memory_order_relaxed);
    });
    for (size_t i = 0; i < visits.size(); ++i) ASSERT_EQ(visits[i].load(), 1) << "item " << i;
    const double s = chunkedSum(jobs, values, 1000);
    if (threads == 1) reference = s;
    EXPECT_EQ(std::memcmp(&s, &reference, sizeof s), 0) << threads << " threads";
  }
}

TEST(JobSystem, EmptyRangesAndBadThreadCounts) {
  JobSystem jobs(2);
  int calls = 0;
  jobs.parallelFor(5, 5, 10, [&](uint32_t, uint32_t) { ++calls; });
  jobs.parallelFor(9, 3, 10, [&](uint32_t, uint32_t) { ++calls; });
  EXPECT_EQ(calls, 0);
  EXPECT_THROW(JobSystem(0), InvalidInput);
  EXPECT_THROW(JobSystem(-3), InvalidInput);
}

}  // namespace
}  // namespace bw
