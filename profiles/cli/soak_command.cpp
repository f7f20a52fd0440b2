// `brickworld soak [SCENE]`: a long run of grid edits interleaved with queries and world steps,
// to show that nothing grows or slows over time (issue 21). The scene (default
// profiles/scenes/soak.json) must have an edit load; the world steps until the edit load has
// placed and removed --edits bricks in all. Every window (--samples of them) reports resident
// memory, step and edit times, and checks each grid's index against a fresh bulk load of its
// bricks (validate(), equal structure hash). Verdict: resident memory within 5% of its level
// after warm-up (the first tenth of the edits), every index canonical at every check, no body inside
// solid; the step time's drift (last quarter of the windows against the first after warm-up)
// is reported, not judged (this machine is shared).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>
#include <unistd.h>
#include <vector>

#include "cli/command_registry.h"
#include "cli/scene_run.h"
#include "collision/bricks/brick_geometry.h"
#include "world/containment.h"
#include "world/scene_file.h"
#include "world/world.h"

namespace bw::cli {
namespace {

constexpr double kMemoryGrowthLimit = 0.05;  // the goal: within 5% of the warm-up level

struct SoakOptions {
  std::string scene = "soak";
  uint64_t edits = 1'000'000;
  uint32_t samples = 20;
  int threads = 1;
  bool json = false;
};

struct Window {
  uint64_t edits = 0;  // placed + removed so far
  uint32_t frame = 0;
  double residentMiB = 0, stepMeanMs = 0, stepMaxMs = 0, editMeanMs = 0, checkMs = 0;
  double indexMiB = 0;  // the grids' OctoBVH nodes, leaves and elements (live pool slots)
  uint64_t bricks = 0;
  uint32_t awake = 0;
};

double residentMiB() {
  long pages = 0, resident = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
    std::fclose(f);
  }
  return double(resident) * double(sysconf(_SC_PAGESIZE)) / 1048576.0;
}

// Whether a grid's index is what a bulk load of its bricks builds (the OctoBVH is canonical:
// any edit history must give the same structure). validate() throws on a broken invariant.
bool gridIsCanonical(const BrickGrid& grid) {
  grid.index().validate();
  std::vector<Aabb> bounds;
  std::vector<uint32_t> filters, ids;
  bounds.reserve(grid.brickCount());
  grid.forEachBrick([&](uint32_t id) {
    bounds.push_back(brickBounds(grid.brick(id)));
    filters.push_back(grid.brick(id).filter);
    ids.push_back(id);
  });
  OctoBvh fresh(OctoBvh::Config{uint32_t(bounds.size()) + 1024});
  fresh.bulkLoad(bounds, filters, ids);
  return fresh.structureHash() == grid.index().structureHash();
}

int runSoak(const SoakOptions& o) {
  using Clock = std::chrono::steady_clock;
  const std::string path = resolveScenePath(o.scene);
  const SceneDescription scene = loadScene(path);
  if (scene.edits.empty()) throw SceneError(path + ": soak needs a scene with an edit load (\"edits\")");
  const auto tBuild = Clock::now();
  World world(scene, o.threads);
  world.profiler().setEnabled(false);  // a long run: the profiler would keep every zone
  ContainmentTracker containment(world);
  const double buildMs = std::chrono::duration<double, std::milli>(Clock::now() - tBuild).count();
  if (!o.json)
    std::printf("soak %s (%s): %u bodies, %llu bricks, built in %.0f ms; %llu edits on %d thread(s)\n", scene.name.c_str(),
                path.c_str(), world.bodies().size(), (unsigned long long)world.brickCount(), buildMs,
                (unsigned long long)o.edits, o.threads);

  std::vector<Window> windows;
  uint64_t edits = 0, windowFrames = 0, idleFrames = 0;
  double stepSum = 0, stepMax = 0, editSum = 0;
  bool canonical = true;
  const uint64_t perWindow = std::max<uint64_t>(1, o.edits / o.samples);
  const auto tRun = Clock::now();
  while (edits < o.edits) {
    const auto t0 = Clock::now();
    world.step();
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    containment.update();
    const StepStats& s = world.lastStats();
    const uint64_t made = uint64_t(s.bricksPlaced) + s.bricksRemoved;
    edits += made;
    idleFrames = made ? 0 : idleFrames + 1;
    if (idleFrames > 1000)
      throw SceneError(path + ": the edit load made no edit for 1000 frames (frame " + std::to_string(world.frame()) +
                       "): its last_frame passed, or no brick is left to remove or free spot to place");
    stepSum += ms;
    stepMax = std::max(stepMax, ms);
    editSum += s.editMs + s.editLoadMs;
    ++windowFrames;
    if (edits >= perWindow * (windows.size() + 1) || edits >= o.edits) {
      Window w;
      w.edits = edits;
      w.frame = world.frame();
      w.stepMeanMs = stepSum / double(windowFrames);
      w.stepMaxMs = stepMax;
      w.editMeanMs = editSum / double(windowFrames);
      w.bricks = world.brickCount();
      w.awake = world.bodies().size() - world.sleepingCount();
      const auto tc = Clock::now();
      for (uint32_t g = 0; g < world.gridCount(); ++g) {
        canonical = gridIsCanonical(world.grid(g)) && canonical;
        w.indexMiB += double(world.grid(g).index().memoryStats().totalBytes()) / 1048576.0;
      }
      w.checkMs = std::chrono::duration<double, std::milli>(Clock::now() - tc).count();
      // after the check, whose bulk loads' transient memory the allocator may keep
      w.residentMiB = residentMiB();
      windows.push_back(w);
      if (!o.json)
        std::fprintf(stderr, "  %9llu edits  frame %6u  resident %6.1f MiB (index %5.1f)  step %5.2f ms (max %5.2f)  edits %5.2f ms  %u awake  %s\n",
                     (unsigned long long)w.edits, w.frame, w.residentMiB, w.indexMiB, w.stepMeanMs, w.stepMaxMs, w.editMeanMs,
                     w.awake, canonical ? "canonical" : "NOT CANONICAL");
      windowFrames = 0;
      stepSum = stepMax = editSum = 0;
    }
  }
  const double runS = std::chrono::duration<double>(Clock::now() - tRun).count();

  // Verdict. Warm-up: the first tenth of the edits (at least one window): pools, caches, the
  // edit load's scratch and the settling bodies' contacts reach their working size there.
  const size_t warmWindows = std::max<size_t>(1, windows.size() / 10);
  const double warm = windows[warmWindows - 1].residentMiB;
  double peak = warm;
  for (size_t i = warmWindows; i < windows.size(); ++i) peak = std::max(peak, windows[i].residentMiB);
  const double growth = peak / warm - 1.0;
  auto meanStep = [&](size_t from, size_t to) {
    double sum = 0;
    for (size_t i = from; i < to; ++i) sum += windows[i].stepMeanMs;
    return to > from ? sum / double(to - from) : 0.0;
  };
  const size_t n = windows.size(), quarter = std::max<size_t>(1, (n - 1) / 4);
  const double early = meanStep(warmWindows, std::min(n, warmWindows + quarter)), late = meanStep(n - quarter, n);
  const double drift = n > 2 && early > 0 ? late / early - 1.0 : 0.0;
  const uint32_t inside = containment.report().count();
  const bool memoryFlat = growth <= kMemoryGrowthLimit;
  const bool pass = memoryFlat && canonical && inside == 0;

  if (o.json) {
    nlohmann::json list = nlohmann::json::array();
    for (const Window& w : windows)
      list.push_back({{"edits", w.edits}, {"frame", w.frame}, {"resident_mib", w.residentMiB}, {"step_mean_ms", w.stepMeanMs},
                      {"step_max_ms", w.stepMaxMs}, {"edit_mean_ms", w.editMeanMs}, {"bricks", w.bricks}, {"check_ms", w.checkMs},
                      {"index_mib", w.indexMiB}, {"awake", w.awake}});
    nlohmann::json j{{"scene", scene.name}, {"file", path}, {"threads", o.threads}, {"edits", edits}, {"frames", world.frame()},
                     {"build_ms", buildMs}, {"run_s", runS}, {"windows", list}, {"resident_warm_mib", warm},
                     {"resident_peak_mib", peak}, {"resident_growth", growth}, {"step_drift", drift},
                     {"canonical", canonical}, {"bodies_inside_solid", inside}, {"pass", pass}};
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("  %llu edits over %u frames in %.1f s (%.2f us an edit with its frame)\n", (unsigned long long)edits,
                world.frame(), runS, runS * 1e6 / double(edits));
    std::printf("  resident memory %.1f MiB after warm-up, peak %.1f MiB: %+.2f%% (limit +%.0f%%)%s\n", warm, peak,
                growth * 100, kMemoryGrowthLimit * 100, memoryFlat ? "" : "  GREW");
    std::printf("  step time %.2f ms early, %.2f ms late: drift %+.1f%% (reported, not judged)\n", early, late, drift * 100);
    std::printf("  every grid index canonical at every check: %s; bodies inside solid at the end: %u\n",
                canonical ? "yes" : "NO", inside);
    std::printf("  soak %s\n", pass ? "passed" : "FAILED");
  }
  return pass ? 0 : 1;
}

CommandRegistration reg{"soak", "Long run of grid edits, queries and steps: memory, step time and index canonicity over time", [](CLI::App& cmd) {
  auto o = std::make_shared<SoakOptions>();
  cmd.add_option("scene", o->scene, "a scene file or shipped scene name with an edit load (default soak)");
  cmd.add_option("--edits", o->edits, "bricks placed and removed in all before it stops (default 10^6)")
      ->check(CLI::Range(uint64_t(1), uint64_t(1'000'000'000'000)));
  cmd.add_option("--samples", o->samples, "report windows (memory, times, index check) over the run (default 20)")
      ->check(CLI::Range(2u, 10'000u));
  o->threads = int(std::max(1u, std::thread::hardware_concurrency()));
  cmd.add_option("--threads", o->threads, "worker threads (default: the machine's hardware threads)")->check(CLI::Range(1, 1024));
  cmd.add_flag("--json", o->json, "print one JSON object");
  return [o] { return runSoak(*o); };
}};

}  // namespace
}  // namespace bw::cli
