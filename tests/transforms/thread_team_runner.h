#pragma once
// Runs a TransformUpdate on plain std::threads, level by level, so ThreadSanitizer sees every
// synchronisation (thread start and join) — unlike oneTBB's scheduler, which the Debian
// package does not instrument.
#include <cstdint>
#include <thread>
#include <vector>

#include "transforms/transform_update.h"

namespace bw::test {

/// Splits each level into `threads` contiguous ranges run on their own std::thread.
inline void runOnThreadTeam(TransformUpdate& update, uint32_t threads) {
  std::vector<std::thread> team;
  team.reserve(threads);
  for (uint32_t level = 0; level < update.levelCount(); ++level) {
    const uint32_t begin = update.levelBegin(level);
    const uint32_t end = update.levelEnd(level);
    const uint32_t n = end - begin;
    team.clear();
    for (uint32_t t = 0; t < threads; ++t) {
      const uint32_t b = begin + static_cast<uint32_t>(uint64_t(n) * t / threads);
      const uint32_t e = begin + static_cast<uint32_t>(uint64_t(n) * (t + 1) / threads);
      team.emplace_back([&update, b, e] { update.runRange(b, e); });
    }
    for (std::thread& th : team) th.join();
  }
}

}  // namespace bw::test
