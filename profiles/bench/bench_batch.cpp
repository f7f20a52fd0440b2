// bench_batch: batched render transform updates (article 000: frame 30 ms -> 8 ms).
//
// Both sides of each comparison in one run, for 1k / 10k / 100k moving attachments and each
// thread count from 1 to the core count:
//   BatchSubmit/{PerObjectMutex,PerObjectMutexNoRadius,PerObjectConcurrent,
//               PerObjectConcurrentNoRadius,Batched}/attachments:N/threads:T
//     time = game-thread time per frame (transform update + submission + commit);
//     counters render_ms, frame_ms, commands_per_frame, radius_per_frame.
//     PerObjectMutex / PerObjectConcurrent send the article engine's light-radius refresh per
//     light move, which batching does not; the NoRadius rows leave it out (like for like).
//   TransformUpdate/{SoA,ObjectStyle}/attachments:N/threads:T
//     time = update time per frame, records into per-id slots (no render side).
// Each runs 3 repetitions (other processes share the cores); the ratio table after the runs
// uses the medians and compares them with the article and the goals.
#include <algorithm>
#include <benchmark/benchmark.h>
#include <cstdio>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "jobs/job_system.h"
#include "render_batch/render_frame_pipeline.h"
#include "render_batch/submission_mode.h"
#include "transforms/attachment_workload.h"
#include "transforms/object_style_components.h"
#include "transforms/record_slot_sink.h"

namespace {

using namespace bw;

constexpr uint32_t kSizes[] = {1'000, 10'000, 100'000};

std::vector<int> threadCounts() {
  const int cores = std::max(1u, std::thread::hardware_concurrency());
  std::vector<int> t;
  for (int n = 1; n < cores; n *= 2) t.push_back(n);
  t.push_back(cores);
  return t;
}

void batchSubmit(benchmark::State& state, SubmissionMode mode, uint32_t attachments, int threads) {
  AttachmentWorkload w = makeAttachmentWorkload({.attachments = attachments, .seed = 1});
  JobSystem jobs(threads);
  RenderFramePipeline pipeline(w.store, mode);
  uint64_t frame = 0;
  for (int i = 0; i < 3; ++i) {  // warm-up: first frame sends everything, queues reach size
    w.bodies.step(++frame, 1.f);
    pipeline.runFrame(w.bodies.view(), jobs);
  }
  pipeline.finish();
  const RenderThreadStats before = pipeline.renderThread().stats();
  double frameMs = 0;
  for (auto _ : state) {
    w.bodies.step(++frame, 1.f);  // every body moves: all attachments move
    const FrameTiming t = pipeline.runFrame(w.bodies.view(), jobs);
    state.SetIterationTime(t.gameMs * 1e-3);
    frameMs += t.gameMs + t.waitMs;
  }
  pipeline.finish();
  const RenderThreadStats after = pipeline.renderThread().stats();
  const double frames = static_cast<double>(state.iterations());
  state.counters["render_ms"] = (after.busyNanoseconds - before.busyNanoseconds) * 1e-6 / frames;
  state.counters["frame_ms"] = frameMs / frames;
  state.counters["commands_per_frame"] = (after.commandsExecuted - before.commandsExecuted) / frames;
  state.counters["radius_per_frame"] = (after.lightRadiusUpdates - before.lightRadiusUpdates) / frames;
  state.counters["updates_per_frame"] =
      (after.primitiveUpdates + after.lightUpdates - before.primitiveUpdates - before.lightUpdates) / frames;
}

void transformUpdate(benchmark::State& state, bool objectStyle, uint32_t attachments, int threads) {
  AttachmentWorkload w = makeAttachmentWorkload({.attachments = attachments, .seed = 1});
  JobSystem jobs(threads);
  RecordSlotSink sink(w.store.primitiveCount(), w.store.lightCount());
  ObjectStyleScene objects(w.store);
  uint64_t frame = 0;
  for (auto _ : state) {
    state.PauseTiming();
    w.bodies.step(++frame, 1.f);
    state.ResumeTiming();
    if (objectStyle)
      objects.update(jobs, w.bodies.view(), sink);
    else
      TransformUpdate(w.store, w.bodies.view(), sink).run(jobs);
  }
  state.counters["attachments_per_us"] =
      benchmark::Counter(double(attachments) * state.iterations() * 1e-6, benchmark::Counter::kIsRate);
}

/// Console output as usual, plus the real time of every run kept by name for the ratio table.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      // note: Google Benchmark appends "/min_time:...", "/repeats:..." and "/manual_time"; key by our part.
      std::string name = r.benchmark_name();
      const size_t suffix = name.find("/min_time:");
      if (suffix != std::string::npos) name.resize(suffix);
      if (r.run_type == Run::RT_Aggregate && r.aggregate_name == "median")
        ms[name] = r.GetAdjustedRealTime();
      else if (r.run_type == Run::RT_Iteration && !ms.count(name))
        ms[name] = r.GetAdjustedRealTime();  // single repetition (--benchmark_repetitions=1)
    }
  }
  std::map<std::string, double> ms;  // in the benchmark's unit (milliseconds)
};

std::string submitName(SubmissionMode m, uint32_t n, int t) {
  return "BatchSubmit/" + std::string(submissionModeName(m)) + "/attachments:" + std::to_string(n) +
         "/threads:" + std::to_string(t);
}
std::string layoutName(bool objectStyle, uint32_t n, int t) {
  return std::string("TransformUpdate/") + (objectStyle ? "ObjectStyle" : "SoA") + "/attachments:" +
         std::to_string(n) + "/threads:" + std::to_string(t);
}

void printRatios(const RatioReporter& rep) {
  auto get = [&rep](const std::string& name) {
    const auto it = rep.ms.find(name);
    return it == rep.ms.end() ? 0.0 : it->second;
  };
  std::printf("\nRatios (median of repetitions, game-thread ms per frame; article: 30 ms -> 8 ms = 3.75x)\n");
  std::printf("mutex, concurrent: per-object with the engine's radius refresh; _nr: without it (like for like)\n");
  std::printf("%-11s %-7s %10s %10s %13s %13s %10s %13s %13s %14s %14s %10s\n", "attachments", "threads", "mutex_ms",
              "mutex_nr_ms", "concurrent_ms", "concur_nr_ms", "batched_ms", "mutex/batch", "mutex_nr/batch",
              "concur/batch", "concur_nr/batch", "obj/SoA");
  int checkedMutex = 0, checkedConcurrent = 0, metMutex = 0, metConcurrent = 0;
  int checkedMutexNr = 0, checkedConcurrentNr = 0, metMutexNr = 0, metConcurrentNr = 0;
  for (uint32_t n : kSizes)
    for (int t : threadCounts()) {
      const double mutex = get(submitName(SubmissionMode::PerObjectMutex, n, t));
      const double concurrent = get(submitName(SubmissionMode::PerObjectConcurrent, n, t));
      const double mutexNr = get(submitName(SubmissionMode::PerObjectMutexNoRadius, n, t));
      const double concurrentNr = get(submitName(SubmissionMode::PerObjectConcurrentNoRadius, n, t));
      const double batched = get(submitName(SubmissionMode::Batched, n, t));
      const double soa = get(layoutName(false, n, t));
      const double obj = get(layoutName(true, n, t));
      if (batched <= 0) continue;  // filtered out
      const double rm = mutex / batched, rc = concurrent / batched, rmn = mutexNr / batched, rcn = concurrentNr / batched;
      if (n >= 10'000 && mutex > 0) {
        ++checkedMutex;
        metMutex += rm >= 4.0;
      }
      if (concurrent > 0) {
        ++checkedConcurrent;
        metConcurrent += rc > 1.0;
      }
      if (n >= 10'000 && mutexNr > 0) {
        ++checkedMutexNr;
        metMutexNr += rmn >= 4.0;
      }
      if (concurrentNr > 0) {
        ++checkedConcurrentNr;
        metConcurrentNr += rcn > 1.0;
      }
      std::printf("%-11u %-7d %10.3f %10.3f %13.3f %13.3f %10.3f %12.2fx %13.2fx %13.2fx %14.2fx %9.2fx\n", n, t, mutex,
                  mutexNr, concurrent, concurrentNr, batched, rm, rmn, rc, rcn, soa > 0 ? obj / soa : 0.0);
    }
  std::printf("goal batched >= 4x per-object mutex at 10k+: met in %d of %d configurations (with radius refresh), "
              "%d of %d (without: like for like)\n",
              metMutex, checkedMutex, metMutexNr, checkedMutexNr);
  std::printf("goal batched faster than concurrent queue: met in %d of %d configurations (with radius refresh), "
              "%d of %d (without: like for like)\n",
              metConcurrent, checkedConcurrent, metConcurrentNr, checkedConcurrentNr);
}

}  // namespace

int main(int argc, char** argv) {
  for (uint32_t n : kSizes)
    for (int t : threadCounts()) {
      for (SubmissionMode m : kAllSubmissionModes)
        benchmark::RegisterBenchmark(submitName(m, n, t).c_str(), batchSubmit, m, n, t)
            ->UseManualTime()
            ->Unit(benchmark::kMillisecond)
            ->MinTime(0.3)
            ->Repetitions(3)
            ->ReportAggregatesOnly(true);
      for (bool objectStyle : {false, true})
        benchmark::RegisterBenchmark(layoutName(objectStyle, n, t).c_str(), transformUpdate, objectStyle, n, t)
            ->Unit(benchmark::kMillisecond)
            ->MinTime(0.2)
            ->Repetitions(3)
            ->ReportAggregatesOnly(true);
    }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  printRatios(reporter);
  benchmark::Shutdown();
  return 0;
}
