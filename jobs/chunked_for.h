#pragma once
/// Helpers for stages that may run with or without a job system and a profiler (a structure
/// used by the world, which gives both, and by tests and benchmarks, which may give neither).
///
///   chunkedFor(jobs, profiler, n, grain, stage, "stage name", [&](uint32_t begin, uint32_t end) { ... });
///   { const OptionalZone z(profiler, "serial part", stage); ... }
///
/// chunkedFor's chunks are JobSystem::parallelFor's (boundaries at multiples of `grain`), run on
/// `jobs` or, without one, in order on the calling thread: per-chunk outputs indexed by
/// begin / grain come out the same either way. Each chunk is a profiling zone at `stage` when
/// there is a profiler.
#include <algorithm>
#include <cstdint>
#include <optional>

#include "jobs/job_system.h"
#include "jobs/profiler.h"

namespace bw {

/// A profiling zone when there is a profiler, nothing otherwise.
struct OptionalZone {
  std::optional<ProfileZone> zone;
  OptionalZone(Profiler* profiler, const char* name, int stage) {
    if (profiler) zone.emplace(*profiler, name, stage);
  }
};

template <class F>
void chunkedFor(JobSystem* jobs, Profiler* profiler, uint32_t n, uint32_t grain, int stage, const char* zone, F&& body) {
  if (grain == 0) grain = 1;
  if (jobs) {
    jobs->parallelFor(0, n, grain, [&](uint32_t begin, uint32_t end) {
      const OptionalZone z(profiler, zone, stage);
      body(begin, end);
    });
    return;
  }
  for (uint32_t begin = 0; begin < n; begin += grain) {
    const OptionalZone z(profiler, zone, stage);
    body(begin, std::min(n, begin + grain));
  }
}

}  // namespace bw
