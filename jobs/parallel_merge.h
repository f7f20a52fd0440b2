#pragma once
/// A deterministic parallel merge of two sorted sequences on the job system (merge path).
///
///   bw::parallelMerge(a, b, out, jobs, &profiler, "pairs: merge", stage);
///
/// The output is cut at fixed positions (every `grain` elements); for each cut, a binary search
/// finds how many of its elements come from a (the merge path), and each piece is merged by
/// std::merge on its own job. On ties a's elements come first, as std::merge does, so the output
/// is std::merge's for any thread count. Inputs below kSerialBelow elements in all merge on the
/// calling thread (one zone at `stage`).
/// Thread safety: the inputs are read only; `out` is resized and written.
#include <algorithm>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "jobs/job_system.h"
#include "jobs/profiler.h"

namespace bw {

template <class T, class Less = std::less<T>>
void parallelMerge(const std::vector<T>& a, const std::vector<T>& b, std::vector<T>& out, JobSystem* jobs, Profiler* profiler,
                   const char* zone, int stage, Less less = Less{}) {
  constexpr size_t kSerialBelow = 4096, kMinPiece = 2048, kMaxPieces = 64;
  const size_t n = a.size() + b.size();
  out.resize(n);
  const auto merge = [&](size_t begin, size_t end) {
    std::optional<ProfileZone> z;
    if (profiler) z.emplace(*profiler, zone, stage);
    // The merge path: i elements of a and begin - i of b precede output position `begin`, with
    // a first on ties: the smallest i such that a[i] is not below... found by binary search.
    const auto split = [&](size_t k) {
      size_t lo = k > b.size() ? k - b.size() : 0, hi = std::min(k, a.size());
      while (lo < hi) {
        const size_t i = (lo + hi) / 2;
        // b[k - i - 1] < a[i] means a[i] comes after the first k outputs: fewer of a.
        if (less(b[k - i - 1], a[i])) {
          hi = i;
        } else {
          lo = i + 1;
        }
      }
      return lo;
    };
    const size_t i0 = split(begin), i1 = split(end);
    std::merge(a.begin() + i0, a.begin() + i1, b.begin() + (begin - i0), b.begin() + (end - i1), out.begin() + begin, less);
  };
  if (!jobs || n < kSerialBelow) {
    merge(0, n);
    return;
  }
  const size_t grain = std::max(kMinPiece, (n + kMaxPieces - 1) / kMaxPieces);
  const uint32_t pieces = uint32_t((n + grain - 1) / grain);
  jobs->parallelFor(0, pieces, 1, [&](uint32_t begin, uint32_t end) {
    for (uint32_t p = begin; p < end; ++p) merge(p * grain, std::min(n, (p + 1) * grain));
  });
}

}  // namespace bw
