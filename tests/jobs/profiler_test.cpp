// Profiler: work/span figures, per-thread recording, Chrome trace output.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <map>
#include <set>
#include <thread>

#include "jobs/job_system.h"
#include "jobs/profiler.h"

namespace bw {
namespace {

thread_local double benchmarkSink;  // keeps the busy loops from being optimised away

TEST(Profiler, WorkSpanAndSpeedupBoundsFromStageStructure) {
  Profiler p;
  p.beginFrame(3);
  const int64_t ms = 1'000'000;
  // Stage 0: four independent 2 ms jobs. Stage 1: one 1 ms job. A zone outside the stages.
  for (int i = 0; i < 4; ++i) p.record("job", i * 2 * ms, (i + 1) * 2 * ms, 0);
  p.record("serial", 8 * ms, 9 * ms, 1);
  p.record("frame", 0, 9 * ms, -1);
  const WorkSpan ws = p.workSpan(3);
  EXPECT_EQ(ws.stages, 2);
  EXPECT_DOUBLE_EQ(ws.workMs, 9.0);
  EXPECT_DOUBLE_EQ(ws.spanMs, 3.0);
  EXPECT_DOUBLE_EQ(ws.boundMs(1), 9.0);
  EXPECT_DOUBLE_EQ(ws.boundMs(2), 4.0 + 1.0);
  EXPECT_DOUBLE_EQ(ws.boundMs(16), 2.0 + 1.0);
  EXPECT_DOUBLE_EQ(ws.speedupBound(16), 3.0);
  EXPECT_EQ(p.workSpan(4).workMs, 0.0) << "other frames are separate";
}

TEST(Profiler, TheBoundWithHandOversChargesOnlyStagesOfSeveralJobs) {
  Profiler p;
  p.beginFrame(0);
  const int64_t ms = 1'000'000;
  // Stage 0: four 2 ms jobs (a fork and a join); stage 1: one 1 ms job (nothing handed over);
  // stage 2: three 1 ms pushes under one lock (serial: work = span, run where they are).
  for (int i = 0; i < 4; ++i) p.record("job", i * 2 * ms, (i + 1) * 2 * ms, 0);
  p.record("one", 8 * ms, 9 * ms, 1);
  for (int i = 0; i < 3; ++i) p.record("push", (9 + i) * ms, (10 + i) * ms, 2, /*serial*/ true);
  const WorkSpan ws = p.workSpan(0);
  ASSERT_EQ(ws.stages, 3);
  const double h = 0.25;
  EXPECT_DOUBLE_EQ(ws.boundMsWithHandOvers(1, h), ws.boundMs(1));
  EXPECT_DOUBLE_EQ(ws.boundMsWithHandOvers(2, h), 4.0 + 2 * h + 1.0 + 3.0);
  EXPECT_DOUBLE_EQ(ws.boundMsWithHandOvers(16, h), 2.0 + 2 * h + 1.0 + 3.0);
  EXPECT_DOUBLE_EQ(ws.boundMsWithHandOvers(16, 0.0), ws.boundMs(16));
}

TEST(Profiler, SerialZonesCountWholeInTheSpan) {
  // Eight 1 ms pushes under one lock from eight jobs: however many threads, they take 8 ms.
  Profiler p;
  const int64_t ms = 1'000'000;
  for (int i = 0; i < 8; ++i) p.record("push", i * ms, (i + 1) * ms, 0, /*serial*/ true);
  for (int i = 0; i < 8; ++i) p.record("update", i * ms, (i + 1) * ms, 1);
  const WorkSpan ws = p.workSpan(0);
  EXPECT_DOUBLE_EQ(ws.workMs, 16.0);
  EXPECT_DOUBLE_EQ(ws.stageSpanMs[0], 8.0);
  EXPECT_DOUBLE_EQ(ws.stageSpanMs[1], 1.0);
  EXPECT_DOUBLE_EQ(ws.boundMs(8), 8.0 + 1.0);
  ASSERT_EQ(ws.stageIds.size(), 2u);
  EXPECT_EQ(ws.stageIds[1], 1);
}

TEST(Profiler, BesideZonesAddWorkButStayOffTheStagesChain) {
  // Two stages of 4 x 1 ms and 1 x 1 ms, and a 3 ms beside job (the render wake of a frame).
  const int64_t ms = 1'000'000;
  Profiler p;
  p.beginFrame(2);
  for (int i = 0; i < 4; ++i) p.record("job", i * ms, (i + 1) * ms, 0);
  p.record("tail", 4 * ms, 5 * ms, 1);
  p.recordBeside("wake", 5 * ms, 8 * ms, 1, /*frame*/ 2);
  p.recordBeside("other frame's", 0, 9 * ms, 1, /*frame*/ 3);
  for (const WorkSpan& ws : {p.workSpan(2), p.workSpans(3)[2]}) {
    EXPECT_EQ(ws.stages, 2) << "a beside zone is not a stage";
    ASSERT_EQ(ws.stageWorkMs.size(), 2u);
    EXPECT_DOUBLE_EQ(ws.stageWorkMs[1], 1.0) << "nor part of its stage";
    EXPECT_DOUBLE_EQ(ws.workMs, 8.0);
    EXPECT_DOUBLE_EQ(ws.besideWorkMs, 3.0);
    EXPECT_DOUBLE_EQ(ws.besideSpanMs, 3.0);
    EXPECT_DOUBLE_EQ(ws.spanMs, 3.0) << "the chain is 1 + 1 ms, the beside job 3";
    EXPECT_DOUBLE_EQ(ws.boundMs(1), 8.0) << "all the work on one thread";
    EXPECT_DOUBLE_EQ(ws.boundMs(2), 4.0) << "the work over two threads exceeds the chain (2 + 1 ms)";
    EXPECT_DOUBLE_EQ(ws.boundMs(16), 3.0) << "the beside job is the longest path";
  }
  const WorkSpanTotals t = p.workSpanTotals(4);  // frames 0..3
  EXPECT_DOUBLE_EQ(t.workMs, 8.0 + 9.0);
  EXPECT_DOUBLE_EQ(t.spanMs, 3.0 + 9.0);
}

TEST(Profiler, OneFramesWorkSpanEqualsTheWholeRunPassInAnyFrameOrder) {
  // Frames recorded in ascending order (a world's, found by binary search) and a profiler that
  // went back to an earlier frame (scanned whole): workSpan(f) must equal workSpans()[f].
  for (bool ascending : {true, false}) {
    Profiler p;
    const uint32_t frames = 50;
    for (uint32_t k = 0; k < frames; ++k) {
      const uint32_t f = ascending ? k : (k * 7) % frames;
      p.beginFrame(f);
      // Frame 3 has 300 stages (found through StageSums' hash table, which the next frame
      // summed in the same pass must not inherit).
      const uint32_t zones = f == 3 ? 300 : f % 5 + 1;
      for (uint32_t z = 0; z < zones; ++z)
        p.record("job", int64_t(k) * 1000 + z, int64_t(k) * 1000 + z + 1 + f, int32_t(f == 3 ? z : z % 3), z == 2);
      p.record("outside", 0, 5, -1);
    }
    const std::vector<WorkSpan> all = p.workSpans(frames);
    for (uint32_t f = 0; f < frames; ++f) {
      const WorkSpan one = p.workSpan(f);
      EXPECT_DOUBLE_EQ(one.workMs, all[f].workMs) << f;
      EXPECT_DOUBLE_EQ(one.spanMs, all[f].spanMs) << f;
      EXPECT_EQ(one.stages, all[f].stages) << f;
      EXPECT_GT(one.workMs, 0.0) << f;
    }
    EXPECT_EQ(p.workSpan(frames + 3).workMs, 0.0);
    // The run's totals: the same sums, stage by stage in another order.
    double work = 0, span = 0;
    uint64_t stages = 0;
    for (const WorkSpan& ws : all) {
      work += ws.workMs;
      span += ws.spanMs;
      stages += uint64_t(ws.stages);
    }
    const WorkSpanTotals totals = p.workSpanTotals(frames);
    EXPECT_NEAR(totals.workMs, work, 1e-12 * work);
    EXPECT_NEAR(totals.spanMs, span, 1e-12 * span);
    EXPECT_EQ(totals.stages, stages);
    EXPECT_EQ(p.workSpanTotals(2).stages, uint64_t(all[0].stages + all[1].stages));
    // Stages 1 and 2 alone: exactly those entries of the whole frames' figures.
    const std::vector<WorkSpan> some = p.workSpans(frames, 1, 2);
    ASSERT_EQ(some.size(), size_t(frames));
    for (uint32_t f = 0; f < frames; ++f) {
      std::vector<int32_t> ids;
      std::vector<double> spans;
      for (size_t k = 0; k < all[f].stageIds.size(); ++k)
        if (all[f].stageIds[k] >= 1 && all[f].stageIds[k] <= 2) {
          ids.push_back(all[f].stageIds[k]);
          spans.push_back(all[f].stageSpanMs[k]);
        }
      EXPECT_EQ(some[f].stageIds, ids) << f;
      EXPECT_EQ(some[f].stageSpanMs, spans) << f;
    }
  }
}

TEST(Profiler, TimeBetweenStagesOnTheOneThreadIsSerialGlueInTheSpan) {
  const int64_t us = 1'000;
  // Stage 0: two 1 ms jobs 0.2 ms apart (a parallelFor's own scheduling, not glue); 0.8 ms
  // later stage 1's job; stage 2 at once; then a 0.5 ms beside job this thread ran inline (not
  // glue) and 0.5 ms later stage 3. An envelope zone (stage -1) spans them all.
  const auto frame = [&](Profiler& p, uint32_t f, bool stage1Elsewhere) {
    p.beginFrame(f);
    const int64_t t0 = int64_t(f) * 100'000 * us;
    p.record("stage 0", t0, t0 + 1000 * us, 0);
    p.record("stage 0", t0 + 1200 * us, t0 + 2200 * us, 0);
    if (stage1Elsewhere) {
      std::thread([&] { p.record("stage 1", t0 + 3000 * us, t0 + 4000 * us, 1); }).join();
    } else {
      p.record("stage 1", t0 + 3000 * us, t0 + 4000 * us, 1);
    }
    p.record("stage 2", t0 + 4000 * us, t0 + 5000 * us, 2);
    p.recordBeside("wake", t0 + 5000 * us, t0 + 5500 * us, 2, f);
    p.record("stage 3", t0 + 6000 * us, t0 + 7000 * us, 3);
    p.record("envelope", t0, t0 + 10'000 * us, -1);
  };
  Profiler p;
  frame(p, 0, false);
  frame(p, 1, true);
  for (const WorkSpan& ws : {p.workSpan(0), p.workSpans(2)[0]}) {
    EXPECT_NEAR(ws.glueMs, 0.8 + 0.5, 1e-12) << "0.8 ms before stage 1, 0.5 ms before stage 3";
    EXPECT_NEAR(ws.workMs, 5.0 + 0.5 + 1.3, 1e-12) << "five jobs, the beside job and the glue";
    EXPECT_NEAR(ws.spanMs, 4.0 + 1.3, 1e-12);
    EXPECT_NEAR(ws.boundMs(16), 4.0 + 1.3, 1e-12) << "glue is serial at any thread count";
    EXPECT_NEAR(ws.boundMs(1), ws.workMs, 1e-12);
    EXPECT_EQ(ws.stages, 4) << "glue is not a stage";
  }
  for (const WorkSpan& ws : {p.workSpan(1), p.workSpans(2)[1]})
    EXPECT_EQ(ws.glueMs, 0.0) << "a frame with zones from two threads: gaps may be waiting, no glue";
  EXPECT_NEAR(p.workSpanTotals(2).glueMs, 1.3, 1e-12);
  EXPECT_NEAR(p.workSpanTotals(2).workMs, 2 * 5.5 + 1.3, 1e-12);
  EXPECT_EQ(p.workSpans(2, 1, 2)[0].glueMs, 0.0) << "some stages alone: the gaps between them hold the others";
}

TEST(Profiler, AJobsZonesRecordedBackToBackCountAsItsFirstStageForGlue) {
  const int64_t us = 1'000;
  // Three jobs of one loop, each timed as an update zone (stage 4) and a submission zone
  // (stage 5) back to back, 0.3 ms between jobs (the loop's scheduling); stage 6 follows 0.7 ms
  // after the last (glue). Then a zone that starts 1 ns after stage 6's end: not back to back.
  Profiler p;
  p.beginFrame(0);
  p.record("stage 3", 0, 1000 * us, 3);
  int64_t t = 1500 * us;  // 0.5 ms of glue before the loop
  for (int job = 0; job < 3; ++job) {
    p.record("update", t, t + 400 * us, 4);
    p.record("submission", t + 400 * us, t + 600 * us, 5);
    t += 900 * us;
  }
  const int64_t stage6 = t - 300 * us + 700 * us;
  p.record("stage 6", stage6, stage6 + 1000 * us, 6);
  p.record("stage 7", stage6 + 1000 * us + 1, stage6 + 2000 * us, 7);
  const WorkSpan ws = p.workSpan(0);
  EXPECT_NEAR(ws.glueMs, 0.5 + 0.7 + 1e-6, 1e-12) << "before the loop, after it, and the 1 ns gap; none between its jobs";
  EXPECT_EQ(ws.stages, 5);
}

TEST(Profiler, ThousandsOfInterleavedStagesSumLikeAMapPerStage) {
  // A coloured island's frame: thousands of stages (ids up to 2^27, as the solver's waves give
  // them), zones of one stage scattered among others; each stage's work, longest and serial
  // zones against a std::map of the same zones.
  Profiler p;
  uint64_t x = 12345;
  const auto next = [&x] {
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    return x;
  };
  struct Sums {
    double work = 0, longest = 0, serial = 0;
  };
  std::map<int32_t, Sums> expected;
  // One thread: the gaps before a zone of another stage than the last one's are glue (a zone
  // that begins at the last one's end continues its chain, which keeps its first stage).
  int64_t glueNs = 0, lastEnd = 0, prevEnd = -1;
  int32_t chainStage = 0;
  int chained = 0;
  p.beginFrame(2);
  for (int z = 0; z < 20000; ++z) {
    const int32_t stage = next() % 4 == 0 ? int32_t(next() % 40) : (1 << 20) + int32_t(next() % 1500) * 65536 + int32_t(next() % 3);
    const int64_t begin = z > 0 && next() % 8 == 0 ? prevEnd : int64_t(next() % 1000000), length = int64_t(next() % 50000);
    const bool serial = next() % 5 == 0;
    p.record("zone", begin, begin + length, stage, serial);
    const bool continues = begin == prevEnd;
    chained += continues && stage != chainStage ? 1 : 0;
    if (z > 0 && !continues && stage != chainStage && begin > lastEnd) glueNs += begin - lastEnd;
    if (!continues) chainStage = stage;
    lastEnd = z == 0 ? begin + length : std::max(lastEnd, begin + length);
    prevEnd = begin + length;
    Sums& s = expected[stage];
    const double ms = double(length) * 1e-6;
    s.work += ms;
    s.longest = std::max(s.longest, ms);
    if (serial) s.serial += ms;
  }
  const WorkSpan ws = p.workSpan(2);
  ASSERT_EQ(ws.stageIds.size(), expected.size());
  double work = 0, span = 0;
  size_t k = 0;
  for (const auto& [stage, s] : expected) {
    ASSERT_EQ(ws.stageIds[k], stage);
    EXPECT_NEAR(ws.stageWorkMs[k], s.work, 1e-9 * s.work);
    EXPECT_DOUBLE_EQ(ws.stageSpanMs[k], std::max(s.longest, s.serial)) << "stage " << stage;
    work += s.work;
    span += std::max(s.longest, s.serial);
    ++k;
  }
  const double glue = double(glueNs) * 1e-6;
  EXPECT_GT(glue, 0.0);
  EXPECT_NEAR(ws.glueMs, glue, 1e-9 * glue);
  EXPECT_NEAR(ws.workMs, work + glue, 1e-9 * work);
  EXPECT_NEAR(ws.spanMs, span + glue, 1e-9 * span);
  EXPECT_GT(expected.size(), 3000u);
  EXPECT_GT(chained, 1000) << "back-to-back zones of another stage than their chain's: the rule is exercised";
}

TEST(Profiler, ZonesFromManyThreadsGoToATraceThatParses) {
  Profiler p;
  JobSystem jobs(4);
  p.beginFrame(0);
  {
    ProfileZone frame(p, "frame");
    jobs.parallelFor(0, 1000, 1, [&](uint32_t b, uint32_t) {
      ProfileZone z(p, "chunk", 0);
      double x = 0;
      for (int i = 0; i < 200 + int(b % 7) * 50; ++i) x += std::sqrt(double(i));
      benchmarkSink = x;
    });
  }
  p.endFrame();
  const auto ev = p.events();
  ASSERT_EQ(ev.size(), 1001u);
  std::set<uint32_t> threads;
  for (const ProfileEvent& e : ev) {
    EXPECT_LE(e.beginNs, e.endNs);
    threads.insert(e.thread);
  }
  EXPECT_LE(threads.size(), 5u);
  const WorkSpan ws = p.workSpan(0);
  EXPECT_GT(ws.workMs, 0.0);
  EXPECT_LE(ws.spanMs, ws.workMs);
  EXPECT_GE(ws.speedupBound(16), ws.speedupBound(2));

  const std::string path = ::testing::TempDir() + "bw_profiler_trace.json";
  p.writeChromeTrace(path);
  std::ifstream in(path);
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j["traceEvents"].size(), 1001u);
  EXPECT_EQ(j["traceEvents"][0]["ph"], "X");
  std::remove(path.c_str());
  p.clear();
  EXPECT_TRUE(p.events().empty());
  EXPECT_THROW(p.writeChromeTrace("/nonexistent-dir/x/trace.json"), std::runtime_error);
}

TEST(Profiler, OneThreadAlternatingBetweenProfilersKeepsOneBufferEach) {
  Profiler a, b;
  for (int i = 0; i < 10; ++i) {
    a.record("a", i, i + 1, 0);
    b.record("b", i, i + 1, 0);
  }
  std::set<uint32_t> ta, tb;
  for (const auto& e : a.events()) ta.insert(e.thread);
  for (const auto& e : b.events()) tb.insert(e.thread);
  EXPECT_EQ(a.events().size(), 10u);
  EXPECT_EQ(ta.size(), 1u);
  EXPECT_EQ(tb.size(), 1u);
}

}  // namespace
}  // namespace bw
