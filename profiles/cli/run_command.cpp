// `brickworld run [SCENE|octobvh|pool]`: the default headless stress run.
//   SCENE (default crates_on_grid): a scene file, or the name of one in profiles/scenes.
//   octobvh: load a seeded brick build into the OctoBVH with the article's load workload
//     (insert each brick, query around it), then overlaps, rays, edits and memory.
//   pool: grow a VirtualPool to N elements and free 99% of it in random order.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <random>
#include <thread>

#include "cli/command_registry.h"
#include "cli/scene_run.h"
#include "collision/content/brick_workload.h"
#include "collision/core/seeded_random.h"
#include "collision/core/virtual_pool.h"
#include "collision/index/octobvh.h"

namespace bw::cli {
namespace {

struct Element64 {
  uint64_t words[8];
};

int runPoolStress(uint32_t elements, uint64_t seed, bool json) {
  using Clock = std::chrono::steady_clock;
  VirtualPool<Element64> pool(elements, "stress pool");
  std::vector<uint32_t> ids(elements);
  double worstPushNs = 0;
  const auto t0 = Clock::now();
  for (uint32_t i = 0; i < elements; ++i) {
    const auto a = Clock::now();
    ids[i] = pool.allocate();
    pool[ids[i]].words[0] = i;
    const double ns = std::chrono::duration<double, std::nano>(Clock::now() - a).count();
    worstPushNs = std::max(worstPushNs, ns);
  }
  const double growMs = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  const size_t residentFull = pool.residentBytes();

  std::mt19937_64 rng(seed);
  std::shuffle(ids.begin(), ids.end(), rng);
  const uint32_t keep = elements / 100;
  const auto t1 = Clock::now();
  for (uint32_t i = keep; i < elements; ++i) pool.free(ids[i]);
  const double freeMs = std::chrono::duration<double, std::milli>(Clock::now() - t1).count();
  const size_t residentAfter = pool.residentBytes();

  if (json) {
    nlohmann::json j{{"workload", "pool"},          {"elements", elements},
                     {"grow_ms", growMs},           {"worst_push_ns", worstPushNs},
                     {"free_99pct_ms", freeMs},     {"resident_bytes_full", residentFull},
                     {"resident_bytes_after_free", residentAfter}, {"live_after_free", pool.size()}};
    std::cout << j.dump(2) << "\n";
  } else {
    std::printf("pool stress: %u x 64-byte elements, seed %llu\n", elements, (unsigned long long)seed);
    std::printf("  grow        %9.1f ms  (%.1f ns/push, worst single push %.1f us)\n", growMs,
                growMs * 1e6 / elements, worstPushNs / 1000);
    std::printf("  resident    %9.1f MiB after growth\n", residentFull / 1048576.0);
    std::printf("  free 99%%    %9.1f ms  (random order)\n", freeMs);
    std::printf("  resident    %9.1f MiB with %u live (%.1f MiB of element data)\n", residentAfter / 1048576.0,
                pool.size(), pool.size() * sizeof(Element64) / 1048576.0);
  }
  return 0;
}

double msSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

int runOctoBvhStress(uint32_t elements, uint64_t seed, bool json) {
  using Clock = std::chrono::steady_clock;
  BrickWorkloadParams p;
  p.count = elements;
  p.seed = seed;
  p.extent = elements >= 1'000'000 ? 4000.f : 2000.f;
  const std::vector<Aabb> bricks = generateBrickWorkload(p);
  OctoBvh tree(OctoBvh::Config{elements + 1024});

  QueryStats loadStats;
  uint64_t neighbours = 0;
  auto t = Clock::now();
  for (uint32_t i = 0; i < elements; ++i) {
    tree.insert(bricks[i], 1, i);
    tree.overlap(bricks[i].expanded(0.05f), 1, [&](uint32_t) { ++neighbours; }, &loadStats);
  }
  const double loadMs = msSince(t);

  constexpr uint32_t kQueries = 20'000;
  SeededRandom r(seed + 1);
  QueryStats overlapStats, rayStats;
  uint64_t overlapHits = 0, rayHits = 0;
  t = Clock::now();
  for (uint32_t q = 0; q < kQueries; ++q) {
    const Vec3f c = bricks[r.below(elements)].center();
    tree.overlap(Aabb::fromCenterHalf(c, Vec3f::Constant(1.f)), 1, [&](uint32_t) { ++overlapHits; }, &overlapStats);
  }
  const double overlapMs = msSince(t);
  t = Clock::now();
  for (uint32_t q = 0; q < kQueries; ++q) {
    const float dx = float(r.normal()), dy = float(r.normal()), dz = float(r.normal());  // in this order
    const Vec3f dir = Vec3f(dx, dy, dz).normalized();
    const Vec3f o = bricks[r.below(elements)].center() + dir * 3.f;
    rayHits += tree.raycastClosest(Ray::make(o, dir, 200.f), 1, &rayStats).hit();
  }
  const double rayMs = msSince(t);

  // Edits: move 1% of the bricks and put them back (a player rebuilding), no rebuild of the index.
  const uint32_t edits = std::max<uint32_t>(elements / 100, 1);
  std::vector<uint32_t> moved;
  t = Clock::now();
  for (uint32_t k = 0; k < edits; ++k) {
    const uint32_t h = r.below(elements);
    const Aabb& b = bricks[tree.payload(h)];
    tree.update(h, {b.min + Vec3f(0, 0.4f, 0), b.max + Vec3f(0, 0.4f, 0)}, 1);
    moved.push_back(h);
  }
  for (uint32_t h : moved) tree.update(h, bricks[tree.payload(h)], 1);
  const double editMs = msSince(t);
  const auto mem = tree.memoryStats();
  const auto shape = tree.shapeStats();

  if (json) {
    nlohmann::json j{{"workload", "octobvh"},
                     {"elements", elements},
                     {"seed", seed},
                     {"load_ms", loadMs},
                     {"load_box_tests", loadStats.boxTests},
                     {"overlap_2m_us", overlapMs * 1e3 / kQueries},
                     {"overlap_box_tests", double(overlapStats.boxTests) / kQueries},
                     {"ray_200m_us", rayMs * 1e3 / kQueries},
                     {"ray_box_tests", double(rayStats.boxTests) / kQueries},
                     {"ray_hit_rate", double(rayHits) / kQueries},
                     {"update_us", editMs * 1e3 / (2.0 * edits)},
                     {"bytes_per_element", double(mem.totalBytes()) / elements},
                     {"resident_bytes", tree.residentBytes()},
                     {"depth", shape.depth},
                     {"forced_nodes", shape.forcedNodes},
                     {"structure_hash", tree.structureHash()}};
    std::cout << j.dump(2) << "\n";
  } else {
    std::printf("octobvh stress: %u bricks (seeded build, seed %llu)\n", elements, (unsigned long long)seed);
    std::printf("  load (insert + query around each)  %9.1f ms  %6.2f us/brick  %.3g box tests (%.0f per brick)\n", loadMs,
                loadMs * 1e3 / elements, double(loadStats.boxTests), double(loadStats.boxTests) / elements);
    std::printf("  2 m overlap                        %9.2f us/query  %.0f box tests, %.1f hits\n", overlapMs * 1e3 / kQueries,
                double(overlapStats.boxTests) / kQueries, double(overlapHits) / kQueries);
    std::printf("  200 m closest-hit ray              %9.2f us/ray    %.0f box tests, %.0f%% hit\n", rayMs * 1e3 / kQueries,
                double(rayStats.boxTests) / kQueries, 100.0 * rayHits / kQueries);
    std::printf("  update (move brick)                %9.2f us/op\n", editMs * 1e3 / (2.0 * edits));
    std::printf("  memory                             %9.1f B/element (%.1f nodes, %.1f leaves, %.1f elements), %.1f MiB resident\n",
                double(mem.totalBytes()) / elements, double(mem.nodeBytes) / elements, double(mem.leafBytes) / elements,
                double(mem.elementBytes) / elements, tree.residentBytes() / 1048576.0);
    std::printf("  shape                              depth %d, %llu leaves, %llu inner nodes, %llu forced splits\n", shape.depth,
                (unsigned long long)shape.leaves, (unsigned long long)shape.innerNodes, (unsigned long long)shape.forcedNodes);
    std::printf("  structure hash                     %016llx\n", (unsigned long long)tree.structureHash());
  }
  return 0;
}

CommandRegistration reg{"run", "Headless stress run: a scene (default crates_on_grid) or the octobvh/pool workloads", [](CLI::App& cmd) {
  auto workload = std::make_shared<std::string>("crates_on_grid");
  auto elements = std::make_shared<uint32_t>(0);
  auto seed = std::make_shared<uint64_t>(1);
  auto json = std::make_shared<bool>(false);
  auto scene = std::make_shared<SceneRunOptions>();
  cmd.add_option("workload", *workload, "a scene file or shipped scene name (default crates_on_grid), or the octobvh or pool workloads");
  cmd.add_option("--elements", *elements, "octobvh/pool: element count (default 1M bricks / 10M pool slots)")
      ->check(CLI::Range(1u, 1'000'000'000u));
  cmd.add_option("--seed", *seed, "octobvh/pool: random seed");
  cmd.add_option("--frames", scene->frames, "scene: frames to run (default: the scene's)")->check(CLI::Range(1u, 10'000'000u));
  scene->threads = int(std::max(1u, std::thread::hardware_concurrency()));
  cmd.add_option("--threads", scene->threads, "scene: worker threads (default: the machine's hardware threads; the state hash is the same for any count)")
      ->check(CLI::Range(1, 1024));
  cmd.add_option("--csv", scene->csvPath, "scene: write per-frame stage times to this CSV");
  cmd.add_option("--trace", scene->tracePath, "scene: write a Chrome trace (open in Perfetto)");
  cmd.add_option("--record", scene->recordPath,
                 "scene: record the run (geometry, per-frame poses, states, edits, splits, stage times; recording/FORMAT.md) "
                 "for `brickworld view`");
  cmd.add_flag("--record-contacts", scene->recordContacts, "scene: the recording also carries every frame's contacts");
  cmd.add_flag("--record-gzip", scene->recordGzip, "scene: compress the recording (gzip; ~4x smaller with terrain, slower to write)");
  cmd.add_option("--record-bricks", scene->recordBricks,
                 "scene: grids with more bricks than this are recorded as their OctoBVH boxes (default 300000)")
      ->check(CLI::Range(0u, 100'000'000u));
  cmd.add_option("--record-depth", scene->recordDepth,
                 "scene: levels of OctoBVH boxes recorded per grid, level k at most 8^k boxes (default 5; a grid recorded as boxes "
                 "is drawn by its deepest level)")
      ->check(CLI::Range(1, 7));
  cmd.add_option("--engine", scene->engine,
                 "scene: brickworld (default); bullet (as a Bullet expert sets it up: chunk compounds, CCD) or bullet-naive "
                 "(one compound per grid); both (brickworld and bullet) or all: same initial state, ratios and accuracy")
      ->check(CLI::IsMember({"brickworld", "bullet", "bullet-naive", "both", "all"}));
  cmd.add_option("--bullet-chunk", scene->bulletChunk, "scene: chunk edge of the expert Bullet setup's static compounds, m (default 16, the fastest measured)")
      ->check(CLI::Range(0.1f, 10000.f));
  cmd.add_option("--bullet-kinematic", scene->bulletKinematic,
                 "scene: how the expert Bullet setup holds a kinematic grid: compound (one body of chunk compounds), chunks (one "
                 "kinematic body per chunk) or auto (chunks from 256 dynamic bodies on; default)")
      ->check(CLI::IsMember({"auto", "compound", "chunks"}));
  cmd.add_option("--submission", scene->submission,
                 "scene with attachments: how transform updates reach the render thread: batched (default: one atomic-append "
                 "batch committed once per frame), mutex or concurrent (one command per update into a mutex / lock-free queue), "
                 "all (the three from the same initial state: ratios, render-scene hashes required equal)")
      ->check(CLI::IsMember({"batched", "mutex", "concurrent", "all"}));
  cmd.add_option("--sleeping", scene->sleeping, "scene: on/off overrides the scene's sleeping setting")
      ->check(CLI::IsMember({"on", "off"}));
  cmd.add_option("--drift-after", scene->driftAfter,
                 "scene: report the largest displacement of a dynamic body from this frame to the end (stacks at rest)")
      ->check(CLI::Range(1u, 10'000'000u));
  cmd.add_flag("--json", *json, "print one JSON object");
  return [=] {
    if (*workload == "pool") return runPoolStress(*elements ? *elements : 10'000'000, *seed, *json);
    if (*workload == "octobvh") return runOctoBvhStress(*elements ? *elements : 1'000'000, *seed, *json);
    SceneRunOptions o = *scene;
    o.scene = *workload;
    o.json = *json;
    return runScene(o);
  };
}};

}  // namespace
}  // namespace bw::cli
