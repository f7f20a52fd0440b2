// The sweep and prune with its sorted copy and sweep in chunks on a JobSystem: the same pairs and
// the same test count as the serial sweep and brute force, for 1, 2, 4 and 16 threads, on dense
// clusters, huge static boxes and bodies that jump (the bulk sort). Labelled `concurrency`.
#include <gtest/gtest.h>

#include "collision/core/seeded_random.h"
#include "world/broadphase.h"

namespace bw {
namespace {

TEST(SweepAndPrune, ChunkedOnAnyThreadCountEqualsSerial) {
  SeededRandom r(8);
  const uint32_t n = 6000;  // several sweep chunks
  std::vector<WorldAabb> b(n);
  std::vector<uint8_t> st(n, 0);
  auto place = [&](uint32_t i) {
    const bool cluster = i % 3 == 0;  // a dense pile: long runs of overlapping intervals
    const Vec3d c = cluster ? Vec3d(r.uniform(0, 6), r.uniform(0, 6), r.uniform(0, 6))
                            : Vec3d(r.uniform(-300, 300), r.uniform(-300, 300), r.uniform(0, 50));
    const Vec3d h = i % 500 == 0 ? Vec3d(100, 100, 3) : Vec3d::Constant(r.logUniform(0.1, 2));
    b[i] = {c - h, c + h};
    st[i] = i % 500 == 0 || i % 11 == 0;
  };
  for (uint32_t i = 0; i < n; ++i) place(i);
  SweepAndPrune serial;
  std::vector<SweepAndPrune> parallel(4);
  const int threadCounts[] = {1, 2, 4, 16};
  for (int frame = 0; frame < 4; ++frame) {
    std::vector<BodyPair> expected;
    serial.update(b, st, expected);
    ASSERT_GT(expected.size(), 1000u);
    for (int k = 0; k < 4; ++k) {
      JobSystem jobs(threadCounts[k]);
      Profiler profiler;
      std::vector<BodyPair> pairs;
      parallel[k].update(b, st, pairs, &jobs, &profiler, 0);
      ASSERT_EQ(pairs, expected) << threadCounts[k] << " threads, frame " << frame;
      EXPECT_EQ(parallel[k].lastTests(), serial.lastTests());
    }
    for (uint32_t i = frame % 2; i < n; i += 2) place(i);  // half jump: the bulk sort
  }
}

}  // namespace
}  // namespace bw
