// JobSystem: every item visited once, fixed chunking, bit-identical reductions per thread count.
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <gtest/gtest.h>
#include <stdexcept>
#include <thread>
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

// parallelWaves: wave w's chunks split row w+1 and read row w anywhere (each slot from two of
// the wave before, one of them another chunk's), as a colour reads the bodies the colour before
// moved: a wave that started early, or a write not yet visible, changes the rows. Waves of 0,
// 1 and many chunks; 1 to 16 threads against a serial reference; every chunk run once.
TEST(JobSystem, WavesRunInOrderAndSeeTheWaveBefore) {
  constexpr uint32_t kSlots = 96;
  std::vector<uint32_t> chunksOf;
  for (uint32_t w = 0; w < 300; ++w) chunksOf.push_back(w % 7 == 3 ? 0u : w % 5 == 0 ? 1u : 1u + (w * 13) % 12);
  const uint32_t waves = uint32_t(chunksOf.size());
  const auto step = [&](const std::vector<uint64_t>& row, std::vector<uint64_t>& into, uint32_t w, uint32_t c) {
    const uint32_t n = chunksOf[w];
    for (uint32_t i = kSlots * c / n; i < kSlots * (c + 1) / n; ++i)
      into[i] = row[i] * 6364136223846793005ull + row[(i + 1 + 7 * w) % kSlots] + w;
  };
  std::vector<std::vector<uint64_t>> expected(waves + 1, std::vector<uint64_t>(kSlots, 0));
  for (uint32_t i = 0; i < kSlots; ++i) expected[0][i] = i * 2654435761ull;
  for (uint32_t w = 0; w < waves; ++w)
    for (uint32_t c = 0; c < chunksOf[w]; ++c) step(expected[w], expected[w + 1], w, c);
  std::vector<uint32_t> firstChunk(waves + 1, 0);
  for (uint32_t w = 0; w < waves; ++w) firstChunk[w + 1] = firstChunk[w] + chunksOf[w];
  for (int threads : {1, 2, 4, 16}) {
    JobSystem jobs(threads);
    for (int repeat = 0; repeat < 5; ++repeat) {
      std::vector<std::vector<uint64_t>> rows(waves + 1, std::vector<uint64_t>(kSlots, 0));
      rows[0] = expected[0];
      std::vector<std::atomic<uint32_t>> runs(firstChunk[waves]);
      jobs.parallelWaves(chunksOf, [&](uint32_t w, uint32_t c) {
        runs[firstChunk[w] + c].fetch_add(1, std::memory_order_relaxed);
        step(rows[w], rows[w + 1], w, c);
      });
      for (uint32_t k = 0; k < firstChunk[waves]; ++k) ASSERT_EQ(runs[k].load(), 1u) << threads << " threads, chunk " << k;
      ASSERT_EQ(rows, expected) << threads << " threads";
    }
  }
  JobSystem jobs(4);
  jobs.parallelWaves({}, [](uint32_t, uint32_t) { FAIL() << "no waves, no chunks"; });
  jobs.parallelWaves({0, 0, 0}, [](uint32_t, uint32_t) { FAIL() << "empty waves, no chunks"; });
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

// Waits up to 10 s for flag (a beside job that never sees its caller go on fails, not hangs).
bool awaitFlag(const std::atomic<bool>& flag) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!flag.load(std::memory_order_acquire))
    if (std::chrono::steady_clock::now() > until) return false;
  return true;
}

TEST(JobSystem, BesideJobsRunWhileTheCallerGoesOnAndJoinWaitsForThem) {
  for (int threads : {2, 4, 16}) {
    JobSystem jobs(threads);
    for (int round = 0; round < 20; ++round) {
      // The job waits for what the caller does after runBeside returned, and the caller for
      // what the job does before it ends: run on the caller, either would wait forever.
      std::atomic<bool> callerWentOn{false}, jobStarted{false}, sawCaller{false};
      std::atomic<int> finished{0};
      jobs.runBeside([&] {
        jobStarted.store(true, std::memory_order_release);
        sawCaller.store(awaitFlag(callerWentOn), std::memory_order_relaxed);
        std::this_thread::sleep_for(std::chrono::microseconds(200));
        finished.fetch_add(1, std::memory_order_release);
      });
      callerWentOn.store(true, std::memory_order_release);
      ASSERT_TRUE(awaitFlag(jobStarted)) << threads << " threads: the beside job never started";
      // Parallel work goes on meanwhile, as a frame's stages do.
      std::vector<uint32_t> hits(1000, 0);
      jobs.parallelFor(0, 1000, 10, [&](uint32_t b, uint32_t e) {
        for (uint32_t i = b; i < e; ++i) ++hits[i];
      });
      for (uint32_t h : hits) ASSERT_EQ(h, 1u);
      jobs.joinBeside();
      EXPECT_EQ(finished.load(std::memory_order_acquire), 1) << "joinBeside returned before its job finished";
      EXPECT_TRUE(sawCaller.load()) << threads << " threads: the beside job ran on its caller";
    }
  }
}

TEST(JobSystem, BesideJobsWithOneThreadRunAtOnceAndTheirErrorsWaitForTheJoin) {
  for (int threads : {1, 2}) {
    std::atomic<int> ran{0};  // declared first: the destructor's join below still sees it
    {
      JobSystem jobs(threads);
      jobs.runBeside([&] { ran.fetch_add(1); });
      if (threads == 1) {
        EXPECT_EQ(ran.load(), 1) << "one thread: at once, on the caller";
      }
      jobs.runBeside([] { throw std::runtime_error("beside failed"); });
      jobs.runBeside([&] { ran.fetch_add(1); });
      EXPECT_THROW(jobs.joinBeside(), std::runtime_error) << threads << " threads";
      EXPECT_EQ(ran.load(), 2) << "the other jobs ran";
      EXPECT_NO_THROW(jobs.joinBeside()) << "an error is reported once";
      jobs.runBeside([&] { ran.fetch_add(1); });  // left for the destructor to join
    }
    EXPECT_EQ(ran.load(), 3) << "the destructor joined the last job";
  }
}

}  // namespace
}  // namespace bw
