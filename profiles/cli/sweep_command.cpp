// `brickworld sweep SCENE --threads 1,2,4`: the same scene at several thread counts. For each:
// median/p95 frame time, total time, measured speedup over 1 thread, the state hash (must be
// identical), and, from the 1-thread run's per-job timings, the work, span and the speedup they
// bound at 2, 4, 8 and 16 threads, so a small machine still says how the frame would scale.
// Around each run it times a cache line's hand-over between two threads (jobs/core_handover.h):
// on a VM it moves from run to run with where the host put the vCPUs, and the measured speedup
// of the fine-grained stages with it.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "cli/command_registry.h"
#include "cli/output_check.h"
#include "cli/render_figures.h"
#include "cli/scene_run.h"
#include "jobs/core_handover.h"
#include "world/scene_file.h"
#include "world/world.h"

namespace bw::cli {
namespace {

struct SweepRow {
  int threads;
  double medianMs, p95Ms, totalS;
  uint64_t hash;
  double workMs, spanMs, glueMs = 0;  // glue: in the work and the span (see WorkSpan)
  std::vector<WorkSpan> frameSpans;  // per frame
  // Work over the sum of each frame's bound at p threads (stages differ from frame to frame,
  // so they are not summed across frames first).
  double speedupBound(int p) const {
    double bound = 0;
    for (const WorkSpan& ws : frameSpans) bound += ws.boundMs(p);
    return bound > 0 ? workMs / bound : 1.0;
  }
  // The same with each stage of several jobs charged two hand-overs of handOverNs (WorkSpan).
  double speedupBoundWithHandOvers(int p, double handOverNs) const {
    double bound = 0;
    for (const WorkSpan& ws : frameSpans) bound += ws.boundMsWithHandOvers(p, handOverNs * 1e-6);
    return bound > 0 ? workMs / bound : 1.0;
  }
  RenderFigures render;  // scenes with attachments
  bool hasRender = false;
  CoreHandover handoverBefore, handoverAfter;  // timed just before and just after the run
};

nlohmann::json handoverJson(const CoreHandover& h) { return h.measured ? nlohmann::json(h.medianNs) : nlohmann::json(nullptr); }
std::string handoverText(const CoreHandover& h) { return h.measured ? std::to_string(int(std::lround(h.medianNs))) : "-"; }

// The median of every hand-over the sweep timed (0: none could be timed).
double medianHandOverNs(const std::vector<SweepRow>& rows) {
  std::vector<double> ns;
  for (const SweepRow& r : rows)
    for (const CoreHandover* h : {&r.handoverBefore, &r.handoverAfter})
      if (h->measured) ns.push_back(h->medianNs);
  if (ns.empty()) return 0;
  std::sort(ns.begin(), ns.end());
  return ns[ns.size() / 2];
}

SweepRow runAt(const SceneDescription& scene, int threads, uint32_t frames, SubmissionMode mode) {
  // note: before the world exists: its render thread's start-up would share a core with the timing.
  const CoreHandover before = measureCoreHandover();
  World world(scene, threads, mode);
  std::vector<double> t;
  RenderFigures render;
  const auto start = std::chrono::steady_clock::now();
  for (uint32_t f = 0; f < frames; ++f) {
    world.step();
    t.push_back(world.lastStats().totalMs);
    if (world.render()) render.add(world.lastStats());
  }
  SweepRow r{threads, 0, 0, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), world.stateHash(), 0, 0, 0, {}, {}, false, before, {}};
  r.handoverAfter = measureCoreHandover();
  std::sort(t.begin(), t.end());
  r.medianMs = t[t.size() / 2];
  r.p95Ms = t[std::min(t.size() - 1, size_t(double(t.size()) * 0.95))];
  // The run's time with p threads is at least the sum over frames of each frame's bound.
  r.frameSpans = world.profiler().workSpans(frames);
  for (const WorkSpan& ws : r.frameSpans) {
    r.workMs += ws.workMs;
    r.spanMs += ws.spanMs;
    r.glueMs += ws.glueMs;
  }
  if (world.render()) {
    render.finish(world);
    r.render = std::move(render);
    r.hasRender = true;
  }
  return r;
}

CommandRegistration reg{"sweep", "Run a scene at several thread counts: measured scaling next to the work/span bound", [](CLI::App& cmd) {
  auto scene = std::make_shared<std::string>("crates_on_grid");
  // Default: 1 and the machine's hardware threads.
  auto threads = std::make_shared<std::vector<int>>(std::vector<int>{1, int(std::max(2u, std::thread::hardware_concurrency()))});
  auto frames = std::make_shared<uint32_t>(0);
  auto csv = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  auto sleeping = std::make_shared<std::string>();
  auto submission = std::make_shared<std::string>();
  auto chargeNs = std::make_shared<double>(-1.0);
  cmd.add_option("scene", *scene, "scene file or shipped scene name");
  cmd.add_option("--sleeping", *sleeping, "on/off overrides the scene's sleeping setting")->check(CLI::IsMember({"on", "off"}));
  cmd.add_option("--threads", *threads, "thread counts, e.g. 1,2,4 (default: 1 and the machine's hardware threads; 1 is always run)")->delimiter(',')->check(CLI::Range(1, 1024));
  cmd.add_option("--frames", *frames, "frames per run (default: the scene's)")->check(CLI::Range(1u, 10'000'000u));
  cmd.add_option("--csv", *csv, "write one row per thread count");
  cmd.add_option("--submission", *submission,
                 "scene with attachments: batched (default), mutex, concurrent, or all (each mode at each thread count)")
      ->check(CLI::IsMember({"batched", "mutex", "concurrent", "all"}));
  cmd.add_option("--handover-ns", *chargeNs,
                 "hand-over latency the second bound charges each stage of several jobs twice (default: the median timed here)")
      ->check(CLI::Range(0.0, 1e6));
  cmd.add_flag("--json", *json, "print one JSON object");
  return [=] {
    requireWritable(*csv, "--csv");
    const std::string path = resolveScenePath(*scene);
    SceneDescription desc = loadScene(path);
    if (!sleeping->empty()) desc.settings.sleeping = *sleeping == "on";
    if (!submission->empty() && !desc.attachments.enabled)
      throw SceneError(path + ": --submission " + *submission + ": the scene declares no attachments (no render thread to submit to)");
    const uint32_t n = *frames ? *frames : desc.settings.frames;
    std::vector<int> counts = *threads;
    if (std::find(counts.begin(), counts.end(), 1) == counts.end()) counts.insert(counts.begin(), 1);
    std::vector<SubmissionMode> modes{submissionModeFromName(submission->empty() ? "batched" : *submission)};
    if (*submission == "all") modes = {SubmissionMode::Batched, SubmissionMode::PerObjectMutexNoRadius, SubmissionMode::PerObjectConcurrentNoRadius};
    // Every mode but the first: only its render figures are reported (the physics is the same run).
    std::vector<std::vector<SweepRow>> otherModes;
    for (size_t m = 1; m < modes.size(); ++m) {
      otherModes.emplace_back();
      for (int t : counts) otherModes.back().push_back(runAt(desc, t, n, modes[m]));
    }
    std::vector<SweepRow> rows;
    for (int t : counts) rows.push_back(runAt(desc, t, n, modes[0]));
    const SweepRow& one = rows.front();
    const double handOverNs = *chargeNs >= 0 ? *chargeNs : medianHandOverNs(rows);
    bool sameHash = true;
    for (const SweepRow& r : rows) sameHash = sameHash && r.hash == one.hash && (!r.hasRender || r.render.sceneHash == one.render.sceneHash);
    if (!csv->empty()) {
      std::ofstream out(*csv);
      if (!out) throw std::runtime_error("cannot write " + *csv);
      out << "scene,threads,frames,median_ms,p95_ms,total_s,measured_speedup,bound_speedup,state_hash,handover_before_ns,handover_after_ns\n";
      for (const SweepRow& r : rows)
        out << desc.name << "," << r.threads << "," << n << "," << r.medianMs << "," << r.p95Ms << "," << r.totalS << ","
            << one.totalS / r.totalS << "," << one.speedupBound(r.threads) << "," << r.hash << ","
            << (r.handoverBefore.measured ? std::to_string(r.handoverBefore.medianNs) : "") << ","
            << (r.handoverAfter.measured ? std::to_string(r.handoverAfter.medianNs) : "") << "\n";
    }
    if (*json) {
      nlohmann::json j{{"scene", desc.name}, {"frames", n}, {"state_hash_identical", sameHash}};
      for (const SweepRow& r : rows)
        j["runs"].push_back({{"threads", r.threads}, {"median_ms", r.medianMs}, {"p95_ms", r.p95Ms}, {"total_s", r.totalS},
                             {"measured_speedup", one.totalS / r.totalS}, {"state_hash", r.hash},
                             {"core_handover_ns", {{"before", handoverJson(r.handoverBefore)}, {"after", handoverJson(r.handoverAfter)}}}});
      for (int p : {2, 4, 8, 16}) j["bound_speedup"][std::to_string(p)] = one.speedupBound(p);
      if (handOverNs > 0) {
        j["handover_ns_charged"] = handOverNs;
        for (int p : {2, 4, 8, 16}) j["bound_speedup_with_handovers"][std::to_string(p)] = one.speedupBoundWithHandOvers(p, handOverNs);
      }
      j["work_ms"] = one.workMs;
      j["span_ms"] = one.spanMs;
      j["glue_ms"] = one.glueMs;
      if (one.hasRender) {
        auto modeJson = [&](const std::vector<SweepRow>& rs) {
          nlohmann::json m{{"mode", submissionModeName(rs.front().render.mode)}};
          for (const SweepRow& r : rs)
            m["measured_submission_commit_ms"][std::to_string(r.threads)] = (r.render.submission.sum() + r.render.commit.sum()) / n;
          for (int p : {1, 2, 4, 8, 16}) {
            m["predicted_submission_commit_ms"][std::to_string(p)] = rs.front().render.predictedMs(p);
            m["predicted_render_ms"][std::to_string(p)] = rs.front().render.predictedMs(p, true);
          }
          m["render_scene_hash"] = rs.front().render.sceneHash;
          return m;
        };
        j["submission"].push_back(modeJson(rows));
        for (const auto& rs : otherModes) {
          j["submission"].push_back(modeJson(rs));
          for (const SweepRow& r : rs) sameHash = sameHash && r.render.sceneHash == one.render.sceneHash && r.hash == one.hash;
        }
        j["state_hash_identical"] = sameHash;
      }
      std::cout << j.dump(2) << "\n";
      return sameHash ? 0 : 3;
    }
    std::printf("sweep %s: %u frames per run\n", desc.name.c_str(), n);
    std::printf("  %-8s %10s %10s %9s %9s %9s  %-16s  %s\n", "threads", "median", "p95", "total", "measured", "bound", "state hash",
                "hand-over ns");
    for (const SweepRow& r : rows)
      std::printf("  %-8d %7.3f ms %7.3f ms %7.2f s %8.2fx %8.2fx  %016llx  %s / %s\n", r.threads, r.medianMs, r.p95Ms, r.totalS,
                  one.totalS / r.totalS, one.speedupBound(r.threads), (unsigned long long)r.hash, handoverText(r.handoverBefore).c_str(),
                  handoverText(r.handoverAfter).c_str());
    std::printf("  hand-over: a cache line from one thread to another, median ns, before / after each run (threads placed by\n"
                "  the OS; on a VM it follows where the host put the vCPUs, and the waves of the coloured solve with it)\n");
    std::printf("  from the 1-thread run: work %.1f ms, span %.1f ms (%.1f ms of it serial between stages, outside any zone);\n"
                "  speedup bound at 2/4/8/16 threads: %.2fx %.2fx %.2fx %.2fx\n",
                one.workMs, one.spanMs, one.glueMs, one.speedupBound(2), one.speedupBound(4), one.speedupBound(8),
                one.speedupBound(16));
    if (handOverNs > 0)
      std::printf("  the same charging each stage of several jobs two hand-overs of %.0f ns (%s):\n"
                  "  %.2fx %.2fx %.2fx %.2fx\n",
                  handOverNs, *chargeNs >= 0 ? "--handover-ns" : "the median timed here", one.speedupBoundWithHandOvers(2, handOverNs), one.speedupBoundWithHandOvers(4, handOverNs),
                  one.speedupBoundWithHandOvers(8, handOverNs), one.speedupBoundWithHandOvers(16, handOverNs));
    if (one.hasRender) {
      std::printf("  render frame (transform update + submission + commit); submission + commit per frame, measured and\n"
                  "  predicted from each mode's 1-thread work/span (the mutex queue's pushes are serial: all in the span):\n");
      std::printf("  %-28s %10s %10s | predicted %7s %7s %7s %7s %7s  %s\n", "mode", "1 thread", "2 threads", "1", "2", "4", "8", "16",
                  "render scene hash");
      auto modeRow = [&](const std::vector<SweepRow>& rs) {
        auto measured = [&](int t) {
          for (const SweepRow& r : rs)
            if (r.threads == t) return (r.render.submission.sum() + r.render.commit.sum()) / n;
          return 0.0;
        };
        const RenderFigures& f = rs.front().render;
        std::printf("  %-28s %7.3f ms %7.3f ms | %17.3f %7.3f %7.3f %7.3f %7.3f  %016llx\n", submissionModeName(f.mode), measured(1),
                    measured(2), f.predictedMs(1), f.predictedMs(2), f.predictedMs(4), f.predictedMs(8), f.predictedMs(16),
                    (unsigned long long)f.sceneHash);
      };
      modeRow(rows);
      for (const auto& rs : otherModes) {
        modeRow(rs);
        for (const SweepRow& r : rs) sameHash = sameHash && r.render.sceneHash == one.render.sceneHash && r.hash == one.hash;
      }
    }
    std::printf("  state hash %s across thread counts%s\n", sameHash ? "identical" : "DIFFERS",
                one.hasRender ? " (and render scene hashes across modes and thread counts)" : "");
    if (!csv->empty()) std::printf("  CSV: %s\n", csv->c_str());
    return sameHash ? 0 : 3;
  };
}};

}  // namespace
}  // namespace bw::cli
