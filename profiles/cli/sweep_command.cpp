// `brickworld sweep SCENE --threads 1,2,4`: the same scene at several thread counts. For each:
// median/p95 frame time, total time, measured speedup over 1 thread, the state hash (must be
// identical), and, from the 1-thread run's per-job timings, the work, span and the speedup they
// bound at 2, 4, 8 and 16 threads, so a small machine still says how the frame would scale.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli/command_registry.h"
#include "cli/scene_run.h"
#include "world/scene_file.h"
#include "world/world.h"

namespace bw::cli {
namespace {

struct SweepRow {
  int threads;
  double medianMs, p95Ms, totalS;
  uint64_t hash;
  double workMs, spanMs;
  WorkSpan perFrame;  // summed stage figures over the run
};

SweepRow runAt(const SceneDescription& scene, int threads, uint32_t frames) {
  World world(scene, threads);
  std::vector<double> t;
  const auto start = std::chrono::steady_clock::now();
  for (uint32_t f = 0; f < frames; ++f) {
    world.step();
    t.push_back(world.lastStats().totalMs);
  }
  SweepRow r{threads, 0, 0, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), world.stateHash(), 0, 0, {}};
  std::sort(t.begin(), t.end());
  r.medianMs = t[t.size() / 2];
  r.p95Ms = t[std::min(t.size() - 1, size_t(double(t.size()) * 0.95))];
  // Sum the per-frame bounds: the run's time with p threads is at least the sum over frames.
  for (const WorkSpan& ws : world.profiler().workSpans(frames)) {
    r.workMs += ws.workMs;
    r.spanMs += ws.spanMs;
    if (r.perFrame.stageWorkMs.size() < ws.stageWorkMs.size()) {
      r.perFrame.stageWorkMs.resize(ws.stageWorkMs.size(), 0.0);
      r.perFrame.stageSpanMs.resize(ws.stageSpanMs.size(), 0.0);
    }
    for (size_t s = 0; s < ws.stageWorkMs.size(); ++s) {
      r.perFrame.stageWorkMs[s] += ws.stageWorkMs[s];
      r.perFrame.stageSpanMs[s] += ws.stageSpanMs[s];
    }
  }
  r.perFrame.workMs = r.workMs;
  r.perFrame.spanMs = r.spanMs;
  return r;
}

CommandRegistration reg{"sweep", "Run a scene at several thread counts: measured scaling next to the work/span bound", [](CLI::App& cmd) {
  auto scene = std::make_shared<std::string>("crates_on_grid");
  auto threads = std::make_shared<std::vector<int>>(std::vector<int>{1, 2});
  auto frames = std::make_shared<uint32_t>(0);
  auto csv = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  auto sleeping = std::make_shared<std::string>();
  cmd.add_option("scene", *scene, "scene file or shipped scene name");
  cmd.add_option("--sleeping", *sleeping, "on/off overrides the scene's sleeping setting")->check(CLI::IsMember({"on", "off"}));
  cmd.add_option("--threads", *threads, "thread counts, e.g. 1,2,4")->delimiter(',')->check(CLI::Range(1, 1024));
  cmd.add_option("--frames", *frames, "frames per run (default: the scene's)")->check(CLI::Range(1u, 10'000'000u));
  cmd.add_option("--csv", *csv, "write one row per thread count");
  cmd.add_flag("--json", *json, "print one JSON object");
  return [=] {
    SceneDescription desc = loadScene(resolveScenePath(*scene));
    if (!sleeping->empty()) desc.settings.sleeping = *sleeping == "on";
    const uint32_t n = *frames ? *frames : desc.settings.frames;
    std::vector<int> counts = *threads;
    if (std::find(counts.begin(), counts.end(), 1) == counts.end()) counts.insert(counts.begin(), 1);
    std::vector<SweepRow> rows;
    for (int t : counts) rows.push_back(runAt(desc, t, n));
    const SweepRow& one = rows.front();
    bool sameHash = true;
    for (const SweepRow& r : rows) sameHash = sameHash && r.hash == one.hash;
    if (!csv->empty()) {
      std::ofstream out(*csv);
      if (!out) throw std::runtime_error("cannot write " + *csv);
      out << "scene,threads,frames,median_ms,p95_ms,total_s,measured_speedup,bound_speedup,state_hash\n";
      for (const SweepRow& r : rows)
        out << desc.name << "," << r.threads << "," << n << "," << r.medianMs << "," << r.p95Ms << "," << r.totalS << ","
            << one.totalS / r.totalS << "," << one.perFrame.speedupBound(r.threads) << "," << r.hash << "\n";
    }
    if (*json) {
      nlohmann::json j{{"scene", desc.name}, {"frames", n}, {"state_hash_identical", sameHash}};
      for (const SweepRow& r : rows)
        j["runs"].push_back({{"threads", r.threads}, {"median_ms", r.medianMs}, {"p95_ms", r.p95Ms}, {"total_s", r.totalS},
                             {"measured_speedup", one.totalS / r.totalS}, {"state_hash", r.hash}});
      for (int p : {2, 4, 8, 16}) j["bound_speedup"][std::to_string(p)] = one.perFrame.speedupBound(p);
      j["work_ms"] = one.workMs;
      j["span_ms"] = one.spanMs;
      std::cout << j.dump(2) << "\n";
      return sameHash ? 0 : 3;
    }
    std::printf("sweep %s: %u frames per run\n", desc.name.c_str(), n);
    std::printf("  %-8s %10s %10s %9s %9s %9s  %s\n", "threads", "median", "p95", "total", "measured", "bound", "state hash");
    for (const SweepRow& r : rows)
      std::printf("  %-8d %7.3f ms %7.3f ms %7.2f s %8.2fx %8.2fx  %016llx\n", r.threads, r.medianMs, r.p95Ms, r.totalS,
                  one.totalS / r.totalS, one.perFrame.speedupBound(r.threads), (unsigned long long)r.hash);
    std::printf("  from the 1-thread run: work %.1f ms, span %.1f ms; speedup bound at 2/4/8/16 threads: %.2fx %.2fx %.2fx %.2fx\n",
                one.workMs, one.spanMs, one.perFrame.speedupBound(2), one.perFrame.speedupBound(4), one.perFrame.speedupBound(8),
                one.perFrame.speedupBound(16));
    std::printf("  state hash %s across thread counts\n", sameHash ? "identical" : "DIFFERS");
    if (!csv->empty()) std::printf("  CSV: %s\n", csv->c_str());
    return sameHash ? 0 : 3;
  };
}};

}  // namespace
}  // namespace bw::cli
