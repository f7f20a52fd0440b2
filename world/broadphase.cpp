#include "world/broadphase.h"

#include <algorithm>
#include <optional>
#include <string>

#include "collision/core/argument_checks.h"

namespace bw {

// Sorts (min on the axis, id) pairs held by value: the comparisons read a contiguous array
// instead of jumping through the ids into the bounds (1M bodies: several times faster).
void SweepAndPrune::sortInBulk(const std::vector<WorldAabb>& bounds) {
  const uint32_t n = uint32_t(bounds.size());
  keys_.resize(n);
  for (uint32_t i = 0; i < n; ++i) keys_[i] = {bounds[i].min[axis_], i};
  std::sort(keys_.begin(), keys_.end());
  order_.resize(n);
  for (uint32_t i = 0; i < n; ++i) order_[i] = keys_[i].second;
}

namespace {

// A profiling zone when there is a profiler.
struct MaybeZone {
  std::optional<ProfileZone> zone;
  MaybeZone(Profiler* profiler, const char* name, int stage) {
    if (profiler) zone.emplace(*profiler, name, stage);
  }
};

}  // namespace

void SweepAndPrune::update(const std::vector<WorldAabb>& bounds, const std::vector<uint8_t>& isStatic, std::vector<BodyPair>& pairs,
                           JobSystem* jobs, Profiler* profiler, int stage) {
  jobs_ = jobs;
  profiler_ = profiler;
  MaybeZone sortZone(profiler, "broadphase: sort", stage);
  const uint32_t n = uint32_t(bounds.size());
  if (isStatic.size() != bounds.size())
    throw InvalidInput("SweepAndPrune::update: " + std::to_string(bounds.size()) + " bounds but " +
                       std::to_string(isStatic.size()) + " static flags");
  for (uint32_t i = 0; i < n; ++i) {
    // Checked without building a message per body (this runs every substep); the message is
    // made only for the body that fails.
    const WorldAabb& b = bounds[i];
    if (b.min.allFinite() && b.max.allFinite() && (b.min.array() <= b.max.array()).all()) continue;
    const std::string what = "bounds of body " + std::to_string(i);
    requireFinite(b.min, "SweepAndPrune::update", (what + " min").c_str());
    requireFinite(b.max, "SweepAndPrune::update", (what + " max").c_str());
    throw InvalidInput("SweepAndPrune::update: " + what + " are inverted (min > max)");
  }
  // Sweep along the axis where the body centres spread most (fewest overlapping intervals).
  Vec3d mean = Vec3d::Zero(), sq = Vec3d::Zero();
  for (const WorldAabb& b : bounds) {
    const Vec3d c = (b.min + b.max) * 0.5;
    mean += c;
    sq += c.cwiseProduct(c);
  }
  int axis = 0;
  if (n > 0) {
    const Vec3d var = sq / n - (mean / n).cwiseProduct(mean / n);
    var.maxCoeff(&axis);
  }
  // Ties break by id so the order is a pure function of the bounds (whichever sort made it).
  auto less = [&](uint32_t a, uint32_t b) {
    const double ma = bounds[a].min[axis], mb = bounds[b].min[axis];
    return ma < mb || (ma == mb && a < b);
  };
  if (axis != axis_ || order_.size() != n) {
    // No order to start from (the first frame, a new axis, bodies added): sort in bulk,
    // O(n log n), where an insertion sort from scratch is quadratic (100k bodies: seconds).
    axis_ = axis;
    sortInBulk(bounds);
  } else {
    // Insertion sort from last frame's order: near-linear for coherent motion. When bodies
    // jumped far (more than a few moves per body), it gives up and sorts in bulk.
    const uint64_t budget = 8ull * n + 1024;
    uint64_t moves = 0;
    for (uint32_t i = 1; i < n && moves <= budget; ++i) {
      const uint32_t v = order_[i];
      uint32_t j = i;
      while (j > 0 && less(v, order_[j - 1])) {
        order_[j] = order_[j - 1];
        --j;
      }
      order_[j] = v;
      moves += i - j;
    }
    if (moves > budget) sortInBulk(bounds);
  }
  sortZone.zone.reset();
  // The sorted copy, then the sweep: each body tests the bodies after it in the sorted order up
  // to its own max. Bodies are independent, so both run in chunks; each chunk of the sweep
  // writes its own pair list, and the lists are joined in chunk order and sorted: the same
  // pairs for any thread count.
  const int a1 = (axis_ + 1) % 3, a2 = (axis_ + 2) % 3;
  sorted_.resize(n);
  forChunks(n, stage + 1, "broadphase: sorted copy", [&](uint32_t begin, uint32_t end) {
    for (uint32_t i = begin; i < end; ++i) {
      const WorldAabb& b = bounds[order_[i]];
      sorted_[i] = {b.min[axis_], b.max[axis_], b.min[a1], b.max[a1], b.min[a2], b.max[a2], order_[i], isStatic[order_[i]]};
    }
  });
  const uint32_t chunks = JobSystem::chunkCount(0, n, kSweepGrain);
  if (chunkPairs_.size() < chunks) chunkPairs_.resize(chunks);
  chunkTests_.assign(chunks, 0);
  forChunks(n, stage + 2, "broadphase: sweep", [&](uint32_t begin, uint32_t end) {
    const uint32_t chunk = begin / kSweepGrain;
    std::vector<BodyPair>& out = chunkPairs_[chunk];
    out.clear();
    uint64_t tests = 0;
    for (uint32_t i = begin; i < end; ++i) {
      const Sorted& a = sorted_[i];
      for (uint32_t j = i + 1; j < n; ++j) {
        const Sorted& b = sorted_[j];
        ++tests;
        if (b.lo > a.hi) break;  // sorted by min: nothing further can overlap
        if (a.isStatic && b.isStatic) continue;
        if (a.lo1 <= b.hi1 && b.lo1 <= a.hi1 && a.lo2 <= b.hi2 && b.lo2 <= a.hi2)
          out.push_back(a.body < b.body ? BodyPair{a.body, b.body} : BodyPair{b.body, a.body});
      }
    }
    chunkTests_[chunk] = tests;
  });
  const MaybeZone joinZone(profiler_, "broadphase: join pairs", stage + 3);
  pairs.clear();
  tests_ = 0;
  for (uint32_t c = 0; c < chunks; ++c) {
    pairs.insert(pairs.end(), chunkPairs_[c].begin(), chunkPairs_[c].end());
    tests_ += chunkTests_[c];
  }
  std::sort(pairs.begin(), pairs.end());
}

template <class F>
void SweepAndPrune::forChunks(uint32_t n, int stage, const char* zone, F&& body) {
  if (jobs_) {
    jobs_->parallelFor(0, n, kSweepGrain, [&](uint32_t begin, uint32_t end) {
      const MaybeZone z(profiler_, zone, stage);
      body(begin, end);
    });
    return;
  }
  for (uint32_t begin = 0; begin < n; begin += kSweepGrain) body(begin, std::min(n, begin + kSweepGrain));
}

}  // namespace bw
