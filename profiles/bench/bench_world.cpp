// bench_world: the world's body-level broadphase, justified by measurement.
//
//   build/release/bin/bench_world --benchmark_counters_tabular=true
//
// Broadphase/<method>/<bodies>: bodies falling onto a few huge static grids (the shape of the
// shipped scenes), moved every frame, pairs recomputed every frame:
//   SweepAndPrune  - the world's choice (sorted order kept between frames)
//   OctoBVH        - our OctoBVH over the bodies, every body updated then queried each frame
//   BruteForce     - all pairs (the floor any method must beat)
// Counters: pairs per frame, interval/box tests per frame.
//
// WorldFrame/<engine>/<scene>: the shipped scene (crates_on_grid, city_rain, lighthouse) for
// its own frame count (300: landing and rest) on one thread, from the same initial state for
// every engine:
//   brickworld         - our World (its ray load included)
//   btCompoundChunked  - Bullet as an expert sets it up (world/bullet_baseline.h): static grids
//                        as 16 m chunk compounds, CCD, split impulse, the same ray load
//   btCompoundNaive    - each grid one btCompoundShape of one box per brick, no CCD (the
//                        article's "compounds" point; not run on city_rain: ~1 s a frame)
// Counters: median and p95 frame time (ms), contacts per frame; the summary prints the
// ratios, expert first. The scenes' render attachments are left out here (Bullet has no render
// side): these rows compare physics with physics.
//
// WorldRender/<mode>/<scene>: the world's frame steps 5-7 (transform update of the moved
// bodies' attachments, submission, commit to the render thread) in each submission mode, from
// the same initial state, on one thread:
//   Batched              - one atomic-append batch (a fetch_add per block of records), one commit
//   PerObjectMutex       - one command per record into a mutex-guarded queue (like for like:
//                          no light-radius refresh)
//   PerObjectConcurrent  - the same into oneTBB's lock-free concurrent_queue
// Counters: submission + commit ms per frame (measured, and predicted at 16 threads from the
// run's work/span with the mutex pushes serial), transform update ms, records per frame; the
// summary prints per-object / batched.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <string>

#include "collision/core/seeded_random.h"
#include "collision/index/octobvh.h"
#include "world/broadphase.h"
#include "world/bullet_baseline.h"
#include "world/scene_file.h"
#include "world/world.h"

namespace {

using namespace bw;

struct Bodies {
  std::vector<WorldAabb> bounds;
  std::vector<uint8_t> isStatic;
  std::vector<Vec3d> velocity;
  uint64_t frame = 0;
  // Bodies move back and forth (velocities flip every 120 frames) so every benchmark, whatever
  // its iteration count, averages over the same distribution of positions.
  void step() {
    if (++frame % 120 == 0)
      for (Vec3d& v : velocity) v = -v;
    for (size_t i = 0; i < bounds.size(); ++i) {
      bounds[i].min += velocity[i] * (1.0 / 60);
      bounds[i].max += velocity[i] * (1.0 / 60);
    }
  }
};

Bodies makeBodies(uint32_t n) {
  SeededRandom r(1);
  Bodies b;
  for (uint32_t i = 0; i < n; ++i) {
    const bool grid = i < 4;  // four large static grids
    const double cx = r.uniform(0, 500), cy = r.uniform(0, 500), cz = grid ? 10 : r.uniform(0, 60);  // in this order
    const Vec3d c(cx, cy, cz);
    const Vec3d h = grid ? Vec3d(200, 200, 20) : Vec3d::Constant(0.25);
    b.bounds.push_back({c - h, c + h});
    b.isStatic.push_back(grid);
    if (grid) {
      b.velocity.push_back(Vec3d::Zero());
    } else {
      const double vx = r.normal(), vy = r.normal(), vz = -r.uniform(0, 5);  // in this order
      b.velocity.push_back(Vec3d(vx, vy, vz));
    }
  }
  return b;
}

void Broadphase_SweepAndPrune(benchmark::State& state) {
  Bodies b = makeBodies(uint32_t(state.range(0)));
  SweepAndPrune sap;
  std::vector<BodyPair> pairs;
  uint64_t tests = 0, found = 0;
  for (auto _ : state) {
    b.step();
    sap.update(b.bounds, b.isStatic, pairs);
    tests += sap.lastTests();
    found += pairs.size();
  }
  state.counters["pairs"] = benchmark::Counter(double(found), benchmark::Counter::kAvgIterations);
  state.counters["tests"] = benchmark::Counter(double(tests), benchmark::Counter::kAvgIterations);
}

void Broadphase_OctoBVH(benchmark::State& state) {
  Bodies b = makeBodies(uint32_t(state.range(0)));
  OctoBvh tree(OctoBvh::Config{uint32_t(b.bounds.size() + 64)});
  std::vector<uint32_t> handles;
  auto local = [](const WorldAabb& w) { return Aabb{w.min.cast<float>(), w.max.cast<float>()}; };
  for (uint32_t i = 0; i < b.bounds.size(); ++i) handles.push_back(tree.insert(local(b.bounds[i]), 1, i));
  std::vector<BodyPair> pairs;
  uint64_t found = 0;
  QueryStats st;
  for (auto _ : state) {
    b.step();
    for (uint32_t i = 0; i < b.bounds.size(); ++i)
      if (!b.isStatic[i]) tree.update(handles[i], local(b.bounds[i]), 1);
    pairs.clear();
    for (uint32_t i = 0; i < b.bounds.size(); ++i) {
      if (b.isStatic[i]) continue;
      tree.overlap(local(b.bounds[i]), 1, [&](uint32_t h) {
        const uint32_t j = tree.payload(h);
        if (j != i && (b.isStatic[j] || j > i)) pairs.push_back(i < j ? BodyPair{i, j} : BodyPair{j, i});
      }, &st);
    }
    std::sort(pairs.begin(), pairs.end());
    found += pairs.size();
  }
  state.counters["pairs"] = benchmark::Counter(double(found), benchmark::Counter::kAvgIterations);
  state.counters["tests"] = benchmark::Counter(double(st.boxTests), benchmark::Counter::kAvgIterations);
}

void Broadphase_BruteForce(benchmark::State& state) {
  Bodies b = makeBodies(uint32_t(state.range(0)));
  std::vector<BodyPair> pairs;
  uint64_t found = 0;
  for (auto _ : state) {
    b.step();
    pairs.clear();
    const uint32_t n = uint32_t(b.bounds.size());
    for (uint32_t i = 0; i < n; ++i)
      for (uint32_t j = i + 1; j < n; ++j)
        if (!(b.isStatic[i] && b.isStatic[j]) && b.bounds[i].overlaps(b.bounds[j])) pairs.push_back({i, j});
    found += pairs.size();
  }
  state.counters["pairs"] = benchmark::Counter(double(found), benchmark::Counter::kAvgIterations);
  state.counters["tests"] = double(state.range(0)) * double(state.range(0) - 1) / 2;
}


// ---------------------------------------------------------------- whole frames vs Bullet

const char* const kScenes[] = {"crates_on_grid", "city_rain", "lighthouse"};
enum Engine { kBrickworld = 0, kBulletChunked = 1, kBulletNaive = 2 };
const char* const kEngineNames[] = {"brickworld", "btCompoundChunked", "btCompoundNaive"};

std::map<std::string, double>& medians() {  // "<engine>/<scene>" -> median frame ms
  static std::map<std::string, double> m;
  return m;
}

double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[std::min(v.size() - 1, size_t(q * double(v.size() - 1) + 0.5))];
}

void WorldFrame(benchmark::State& state, Engine engine, const char* scene) {
  SceneDescription description = loadScene(std::string(BW_SOURCE_DIR) + "/profiles/scenes/" + scene + ".json");
  description.attachments = AttachmentsDescription{};  // physics against physics
  std::vector<double> frameMs;
  uint64_t contacts = 0;
  for (auto _ : state) {
    World world(description, 1);
    std::unique_ptr<BulletBaseline> bullet;
    if (engine != kBrickworld)
      bullet = std::make_unique<BulletBaseline>(world, engine == kBulletChunked ? BulletSetup::Expert : BulletSetup::Naive);
    for (uint32_t f = 0; f < description.settings.frames; ++f) {
      const auto t = std::chrono::steady_clock::now();
      if (bullet) bullet->step();
      else world.step();
      frameMs.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count());
      contacts += bullet ? bullet->lastFrame().contacts : world.lastStats().contacts;
    }
  }
  const double median = quantile(frameMs, 0.5);
  medians()[std::string(kEngineNames[engine]) + "/" + scene] = median;
  state.counters["frame_ms_median"] = median;
  state.counters["frame_ms_p95"] = quantile(frameMs, 0.95);
  state.counters["contacts_per_frame"] = double(contacts) / double(frameMs.size());
}

// ---------------------------------------------------------------- the render frame per mode

const char* const kRenderScenes[] = {"crates_on_grid", "carrier_fleet"};
const SubmissionMode kRenderModes[] = {SubmissionMode::Batched, SubmissionMode::PerObjectMutexNoRadius,
                                       SubmissionMode::PerObjectConcurrentNoRadius};
const char* renderModeName(SubmissionMode m) {
  return m == SubmissionMode::Batched ? "Batched" : m == SubmissionMode::PerObjectMutexNoRadius ? "PerObjectMutex" : "PerObjectConcurrent";
}

std::map<std::string, std::pair<double, double>>& renderFigures() {  // "<mode>/<scene>" -> (measured, predicted at 16) ms
  static std::map<std::string, std::pair<double, double>> m;
  return m;
}

void WorldRenderFrame(benchmark::State& state, SubmissionMode mode, const char* scene) {
  const SceneDescription description = loadScene(std::string(BW_SOURCE_DIR) + "/profiles/scenes/" + scene + ".json");
  constexpr uint32_t kFrames = 60;
  double submitCommit = 0, update = 0, predicted16 = 0;
  uint64_t records = 0;
  for (auto _ : state) {
    World world(description, 1, mode);
    for (uint32_t f = 0; f < kFrames; ++f) {
      world.step();
      const RenderStageStats& r = world.lastStats().render;
      submitCommit += r.submissionMs + r.commitMs;
      update += r.updateMs;
      records += r.primitives + r.lights;
    }
    world.renderScene();
    // Submission + commit at 16 threads: per stage max(work / 16, span); the mutex queue's
    // pushes are serial zones, all in the span.
    for (const WorkSpan& ws : world.profiler().workSpans(kFrames)) predicted16 += predictedRenderMs(ws, world.renderStage(), 16);
  }
  const double frames = double(kFrames) * double(state.iterations());
  renderFigures()[std::string(renderModeName(mode)) + "/" + scene] = {submitCommit / frames, predicted16 / frames};
  state.counters["submit_commit_ms"] = submitCommit / frames;
  state.counters["submit_commit_ms_16thr"] = predicted16 / frames;
  state.counters["update_ms"] = update / frames;
  state.counters["records_per_frame"] = double(records) / frames;
}

void printRenderRatios() {
  const auto& m = renderFigures();
  for (const char* scene : kRenderScenes) {
    const std::string b = std::string("Batched/") + scene;
    if (!m.count(b)) continue;
    std::printf("%s: batched submission + commit %.3f ms a frame (%.3f predicted at 16 threads)", scene, m.at(b).first, m.at(b).second);
    for (const char* other : {"PerObjectMutex", "PerObjectConcurrent"}) {
      const std::string k = std::string(other) + "/" + scene;
      if (m.count(k))
        std::printf("; %s %.1fx (%.1fx at 16)", other, m.at(k).first / std::max(m.at(b).first, 1e-9),
                    m.at(k).second / std::max(m.at(b).second, 1e-9));
    }
    std::printf("\n");
  }
}

void printWorldRatios() {
  const auto& m = medians();
  for (const char* scene : kScenes) {
    const std::string s = scene;
    if (!m.count("brickworld/" + s)) continue;
    const double ours = std::max(m.at("brickworld/" + s), 1e-9);
    std::printf("%s: brickworld %.3f ms a frame (median)", scene, ours);
    if (m.count("btCompoundChunked/" + s))
      std::printf("; Bullet as an expert sets it up %.3f ms (%.1fx)", m.at("btCompoundChunked/" + s), m.at("btCompoundChunked/" + s) / ours);
    if (m.count("btCompoundNaive/" + s))
      std::printf("; naive single compound %.3f ms (%.1fx)", m.at("btCompoundNaive/" + s), m.at("btCompoundNaive/" + s) / ours);
    std::printf("\n");
  }
}

BENCHMARK(Broadphase_SweepAndPrune)->Arg(1000)->Arg(2000)->Arg(5000)->Unit(benchmark::kMicrosecond);
BENCHMARK(Broadphase_OctoBVH)->Arg(1000)->Arg(2000)->Arg(5000)->Unit(benchmark::kMicrosecond);
BENCHMARK(Broadphase_BruteForce)->Arg(1000)->Arg(2000)->Arg(5000)->Unit(benchmark::kMicrosecond);

}  // namespace

int main(int argc, char** argv) {
  for (const char* scene : kScenes)
    for (Engine e : {kBrickworld, kBulletChunked, kBulletNaive}) {
      if (e == kBulletNaive && std::string(scene) == "city_rain") continue;
      benchmark::RegisterBenchmark((std::string("WorldFrame/") + kEngineNames[e] + "/" + scene).c_str(), WorldFrame, e, scene)
          ->Iterations(1)
          ->Unit(benchmark::kMillisecond);
    }
  for (const char* scene : kRenderScenes)
    for (SubmissionMode mode : kRenderModes)
      benchmark::RegisterBenchmark((std::string("WorldRender/") + renderModeName(mode) + "/" + scene).c_str(), WorldRenderFrame, mode,
                                   scene)
          ->Iterations(1)
          ->Unit(benchmark::kMillisecond);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  printWorldRatios();
  printRenderRatios();
  return 0;
}
