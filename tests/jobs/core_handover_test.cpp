// measureCoreHandover: the figure a scaling run reports beside its measured speedup.
#include <cmath>
#include <gtest/gtest.h>
#include <sched.h>
#include <string>
#include <thread>

#include "collision/core/argument_checks.h"
#include "jobs/core_handover.h"

namespace bw {
namespace {

TEST(CoreHandover, ZeroBatchesOrRoundTripsAreRefusedByName) {
  for (auto [batches, trips] : {std::pair{0u, 10u}, std::pair{3u, 0u}}) {
    try {
      measureCoreHandover(batches, trips);
      FAIL() << "accepted batches " << batches << ", roundTrips " << trips;
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find("batches is " + std::to_string(batches) + " and roundTrips " + std::to_string(trips)),
                std::string::npos)
          << e.what();
    }
  }
}

// Whether a measurement found the two threads on different CPUs at all (ctest runs other
// suites on the other cores: the warm-up may never see them apart, which is not this code's fault).
bool ranApart(const CoreHandover& h) { return h.batches + h.stalledBatches > 0; }

TEST(CoreHandover, MeasuresEveryBatchWithinItsLimit) {
  if (std::thread::hardware_concurrency() < 2) GTEST_SKIP() << "one hardware thread: nothing to hand over between";
  // A generous limit (a sanitizer build or a loaded machine hands over slowly); a few attempts,
  // since a loaded machine may stall a batch or never run the two apart.
  constexpr uint32_t kBatches = 5, kTrips = 500;
  constexpr double kLimitMs = 200.0;
  CoreHandover h;
  bool apart = false;
  for (int attempt = 0; attempt < 8 && !h.measured; ++attempt) {
    h = measureCoreHandover(kBatches, kTrips, kLimitMs);
    apart = apart || ranApart(h);
    // Unmeasured yet run apart: only kMaxStalledBatches stalls may end a measurement.
    if (!h.measured && ranApart(h)) {
      EXPECT_EQ(h.stalledBatches, kMaxStalledBatches);
    }
  }
  if (!apart) GTEST_SKIP() << "the two threads never ran on different CPUs (a busy machine)";
  ASSERT_TRUE(h.measured);
  // Every batch ran: the finished ones, and any a stopped vCPU stalled (fewer than the limit of those).
  EXPECT_EQ(h.batches + h.stalledBatches, kBatches);
  EXPECT_LT(h.stalledBatches, kMaxStalledBatches);
  EXPECT_GE(h.batches, 1u);
  EXPECT_TRUE(std::isfinite(h.medianNs));
  EXPECT_GT(h.minNs, 0.0);
  EXPECT_LE(h.minNs, h.medianNs);
  // Every timed batch finished inside its limit: a hand-over is at most the limit over the hand-overs.
  EXPECT_LE(h.medianNs, kLimitMs * 1e6 / (2.0 * kTrips));
}

TEST(CoreHandover, StopsUnmeasuredAfterTheStalledBatchesAndReturns) {
  if (std::thread::hardware_concurrency() < 2) GTEST_SKIP() << "one hardware thread: measured at once as unmeasured";
  // 64 round trips take far longer than 100 ns on any machine: every batch runs over its limit
  // at the first check; the third ends the measurement, and the partner thread is stopped and
  // joined (the call returns: nothing is left running).
  CoreHandover h;
  for (int attempt = 0; attempt < 8 && !ranApart(h); ++attempt) {
    h = measureCoreHandover(9, 100'000, 1e-4);
    EXPECT_FALSE(h.measured);
    EXPECT_EQ(h.batches, 0u);
    EXPECT_EQ(h.medianNs, 0.0);
  }
  if (!ranApart(h)) GTEST_SKIP() << "the two threads never ran on different CPUs (a busy machine)";
  EXPECT_EQ(h.stalledBatches, kMaxStalledBatches);
}

TEST(CoreHandover, TwoThreadsThatCannotRunApartAreNotTimed) {
  // Pinned to one CPU (the partner inherits the mask), the two never run on different CPUs: the
  // warm-up gives up and nothing is timed, instead of reporting a time slice as a hand-over.
  cpu_set_t old;
  ASSERT_EQ(sched_getaffinity(0, sizeof old, &old), 0);
  int first = -1;
  for (int c = 0; c < CPU_SETSIZE && first < 0; ++c)
    if (CPU_ISSET(c, &old)) first = c;
  ASSERT_GE(first, 0);
  cpu_set_t one;
  CPU_ZERO(&one);
  CPU_SET(first, &one);
  ASSERT_EQ(sched_setaffinity(0, sizeof one, &one), 0);
  const CoreHandover h = measureCoreHandover();
  ASSERT_EQ(sched_setaffinity(0, sizeof old, &old), 0);
  EXPECT_FALSE(h.measured);
  EXPECT_EQ(h.batches, 0u);
  EXPECT_EQ(h.stalledBatches, 0u);
}

}  // namespace
}  // namespace bw
