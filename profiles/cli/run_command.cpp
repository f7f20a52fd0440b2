// `brickworld run [WORKLOAD]`: the default headless stress run.
// Until the world and its scene files exist (issue 7), the workloads are the engine's
// building blocks under stress: `pool` grows a VirtualPool and frees it in random order.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <random>

#include "cli/command_registry.h"
#include "collision/virtual_pool.h"

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

CommandRegistration reg{"run", "Headless stress run of a workload (default: pool)", [](CLI::App& cmd) {
  auto workload = std::make_shared<std::string>("pool");
  auto elements = std::make_shared<uint32_t>(10'000'000);
  auto seed = std::make_shared<uint64_t>(1);
  auto json = std::make_shared<bool>(false);
  cmd.add_option("workload", *workload, "pool")->check(CLI::IsMember({"pool"}));
  cmd.add_option("--elements", *elements, "element count")->check(CLI::Range(1u, 1'000'000'000u));
  cmd.add_option("--seed", *seed, "random seed");
  cmd.add_flag("--json", *json, "print one JSON object");
  return [=] { return runPoolStress(*elements, *seed, *json); };
}};

}  // namespace
}  // namespace bw::cli
