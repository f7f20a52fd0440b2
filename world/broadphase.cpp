#include "world/broadphase.h"

#include <algorithm>
#include <cstring>
#include <string>

#include "collision/core/argument_checks.h"
#include "jobs/chunked_for.h"
#include "world/static_bounds_tree.h"
#include "world/world_tuning.h"

namespace bw {

SweepAndPrune::SweepAndPrune() : staticTree_(std::make_unique<StaticBoundsTree>()) {}
SweepAndPrune::~SweepAndPrune() = default;
SweepAndPrune::SweepAndPrune(SweepAndPrune&&) noexcept = default;
SweepAndPrune& SweepAndPrune::operator=(SweepAndPrune&&) noexcept = default;

void validateProxies(const std::vector<WorldAabb>& bounds, const std::vector<uint8_t>& isStatic, const std::vector<uint32_t>* owner,
                     const char* who) {
  const std::string context(who);
  if (isStatic.size() != bounds.size())
    throw InvalidInput(context + ": " + std::to_string(bounds.size()) + " bounds but " + std::to_string(isStatic.size()) + " static flags");
  if (owner && owner->size() != bounds.size())
    throw InvalidInput(context + ": " + std::to_string(bounds.size()) + " bounds but " + std::to_string(owner->size()) + " owners");
  for (uint32_t i = 0; i < uint32_t(bounds.size()); ++i) {
    // Checked without building a message per proxy (this runs every substep); the message is
    // made only for the one that fails.
    const WorldAabb& b = bounds[i];
    if (b.min.allFinite() && b.max.allFinite() && (b.min.array() <= b.max.array()).all()) continue;
    const std::string what = "bounds of body " + std::to_string(i);
    requireFinite(b.min, who, (what + " min").c_str());
    requireFinite(b.max, who, (what + " max").c_str());
    throw InvalidInput(context + ": " + what + " are inverted (min > max)");
  }
}

// The static proxies now, against those the tree holds: ids and boxes, compared bit for bit.
bool SweepAndPrune::staticSetChanged(const std::vector<WorldAabb>& bounds, const std::vector<uint8_t>& isStatic) {
  staticScratch_.clear();
  for (uint32_t i = 0; i < uint32_t(bounds.size()); ++i)
    if (isStatic[i]) staticScratch_.push_back(i);
  bool changed = staticScratch_ != staticIds_ || staticTree_->empty() != staticIds_.empty();
  for (size_t k = 0; !changed && k < staticIds_.size(); ++k)
    changed = std::memcmp(&bounds[staticIds_[k]], &staticBoxes_[k], sizeof(WorldAabb)) != 0;
  if (!changed && staticBuilds_ > 0) return false;
  staticIds_.swap(staticScratch_);
  staticBoxes_.clear();
  for (uint32_t id : staticIds_) staticBoxes_.push_back(bounds[id]);
  return true;
}

// Insertion sort from last frame's order: near-linear for coherent motion. Gives up (false)
// when the moving set changed or bodies jumped far (more than a few moves per body).
bool SweepAndPrune::insertionSort(const std::vector<WorldAabb>& bounds, const std::vector<uint8_t>& isStatic) {
  const uint32_t m = uint32_t(moving_.size());
  if (order_.size() != m) return false;
  for (uint32_t id : order_)
    if (id >= bounds.size() || isStatic[id]) return false;  // same count, another set
  // Ties break by id so the order is a pure function of the bounds (whichever sort made it).
  const int axis = axis_;
  auto less = [&](uint32_t a, uint32_t b) {
    const double ma = bounds[a].min[axis], mb = bounds[b].min[axis];
    return ma < mb || (ma == mb && a < b);
  };
  const uint64_t budget = 8ull * m + 1024;
  uint64_t moves = 0;
  for (uint32_t i = 1; i < m && moves <= budget; ++i) {
    const uint32_t v = order_[i];
    uint32_t j = i;
    while (j > 0 && less(v, order_[j - 1])) {
      order_[j] = order_[j - 1];
      --j;
    }
    order_[j] = v;
    moves += i - j;
  }
  return moves <= budget;
}

// Sorts (min on the axis, id) pairs held by value: the comparisons read a contiguous array
// instead of jumping through the ids into the bounds (1M bodies: several times faster).
void SweepAndPrune::sortInBulk(const std::vector<WorldAabb>& bounds, int stage) {
  const uint32_t m = uint32_t(moving_.size());
  keys_.resize(m);
  for (uint32_t k = 0; k < m; ++k) keys_[k] = {bounds[moving_[k]].min[axis_], moving_[k]};
  if (jobs_) {
    keySorter_.sort(keys_, false, *jobs_, profiler_, "broadphase: bulk sort", stage);
  } else {
    std::sort(keys_.begin(), keys_.end());
  }
  order_.resize(m);
  for (uint32_t k = 0; k < m; ++k) order_[k] = keys_[k].second;
}

void SweepAndPrune::update(const std::vector<WorldAabb>& bounds, const std::vector<uint8_t>& isStatic, std::vector<BodyPair>& pairs,
                           JobSystem* jobs, Profiler* profiler, int stage, const std::vector<uint32_t>* owner) {
  jobs_ = jobs;
  profiler_ = profiler;
  OptionalZone orderZone(profiler, "broadphase: order", stage);
  validateProxies(bounds, isStatic, owner, "SweepAndPrune::update");
  const uint32_t n = uint32_t(bounds.size());
  moving_.clear();
  for (uint32_t i = 0; i < n; ++i)
    if (!isStatic[i]) moving_.push_back(i);
  const uint32_t m = uint32_t(moving_.size());
  if (staticSetChanged(bounds, isStatic)) {
    staticTree_->build(staticBoxes_, staticIds_);
    ++staticBuilds_;
  }
  // Sweep along the axis where the moving proxies' centres spread most (fewest overlapping
  // intervals).
  Vec3d mean = Vec3d::Zero(), sq = Vec3d::Zero();
  for (uint32_t id : moving_) {
    const Vec3d c = (bounds[id].min + bounds[id].max) * 0.5;
    mean += c;
    sq += c.cwiseProduct(c);
  }
  int axis = 0;
  if (m > 0) {
    const Vec3d var = sq / m - (mean / m).cwiseProduct(mean / m);
    var.maxCoeff(&axis);
  }
  // No order to start from (the first frame, a new axis, another moving set): sort in bulk,
  // O(m log m), where an insertion sort from scratch is quadratic (100k bodies: seconds).
  const bool keep = axis == axis_ && insertionSort(bounds, isStatic);
  orderZone.zone.reset();
  if (!keep) {
    axis_ = axis;
    sortInBulk(bounds, stage + 1);
  }
  // The sorted copy, then the sweep: each moving proxy tests the moving proxies after it in the
  // sorted order up to its own max, and queries the static tree. Proxies are independent, so
  // both run in chunks; each chunk of the sweep writes its own pair list, and the lists are
  // joined in chunk order and sorted: the same pairs for any thread count.
  const int a1 = (axis_ + 1) % 3, a2 = (axis_ + 2) % 3;
  const uint32_t grain = tuning::grainFor(m, kMinSweepGrain);
  sorted_.resize(m);
  forChunks(m, grain, stage + 5, "broadphase: sorted copy", [&](uint32_t begin, uint32_t end) {
    for (uint32_t i = begin; i < end; ++i) {
      const WorldAabb& b = bounds[order_[i]];
      sorted_[i] = {b.min[axis_], b.max[axis_], b.min[a1], b.max[a1], b.min[a2], b.max[a2], order_[i]};
    }
  });
  // The sweep's jobs cut by cost, not by count: proxy i tests the proxies up to the first whose
  // min lies past its max (found by binary search), plus a static tree query. A landing pile
  // packs most of the tests into a few hundred proxies; equal counts left one job with a sixth
  // of crate_pile's sweep. The cut decides only which job finds a pair, never the pairs.
  const StaticBoundsTree& tree = *staticTree_;
  // A tree query costs what the last frame's queries cost on average (box tests weigh like
  // interval tests); the cut changes only how the work is shared, never the pairs.
  const uint64_t queryCost = tree.empty() ? 0 : std::max<uint64_t>(1, queryTestsPerProxy_);
  const uint32_t copyChunks = JobSystem::chunkCount(0, m, grain);
  costPrefix_.resize(m);
  chunkCost_.assign(copyChunks, 0);
  forChunks(m, grain, stage + 6, "broadphase: sweep costs", [&](uint32_t begin, uint32_t end) {
    uint64_t sum = 0;
    for (uint32_t i = begin; i < end; ++i) {
      const double hi = sorted_[i].hi;
      const auto last = std::upper_bound(sorted_.begin() + i + 1, sorted_.end(), hi, [](double v, const Sorted& s) { return v < s.lo; });
      sum += uint64_t(last - sorted_.begin()) - i + queryCost;
      costPrefix_[i] = sum;  // inclusive, within the chunk
    }
    chunkCost_[begin / grain] = sum;
  });
  uint64_t totalCost = 0;
  for (uint64_t c : chunkCost_) totalCost += c;
  const uint32_t sweepJobs = uint32_t(std::clamp<uint64_t>(totalCost / kMinSweepJobCost, 1, tuning::kTargetJobs));
  jobBegin_.assign(sweepJobs + 1, m);
  jobBegin_[0] = 0;
  {
    // Job k starts at the first proxy whose inclusive cost prefix exceeds k / jobs of the total.
    uint32_t chunk = 0;
    uint64_t before = 0;  // cost of the chunks before `chunk`
    for (uint32_t k = 1; k < sweepJobs; ++k) {
      const uint64_t target = totalCost * k / sweepJobs;
      while (chunk < copyChunks && before + chunkCost_[chunk] <= target) before += chunkCost_[chunk++];
      if (chunk == copyChunks) break;
      const uint32_t begin = chunk * grain, end = std::min(m, begin + grain);
      const auto it = std::upper_bound(costPrefix_.begin() + begin, costPrefix_.begin() + end, target - before);
      jobBegin_[k] = std::max(jobBegin_[k - 1], uint32_t(it - costPrefix_.begin()));
    }
  }
  if (chunkPairs_.size() < sweepJobs) chunkPairs_.resize(sweepJobs);
  chunkTests_.assign(sweepJobs, 0);
  chunkTreeTests_.assign(sweepJobs, 0);
  forChunks(sweepJobs, 1, stage + 7, "broadphase: sweep", [&](uint32_t job, uint32_t) {
    std::vector<BodyPair>& out = chunkPairs_[job];
    out.clear();
    auto emit = [&](uint32_t p, uint32_t q) {
      const uint32_t a = owner ? (*owner)[p] : p, b = owner ? (*owner)[q] : q;
      if (a != b) out.push_back(a < b ? BodyPair{a, b} : BodyPair{b, a});
    };
    uint64_t tests = 0, treeTests = 0;
    for (uint32_t i = jobBegin_[job]; i < jobBegin_[job + 1]; ++i) {
      const Sorted& a = sorted_[i];
      for (uint32_t j = i + 1; j < m; ++j) {
        const Sorted& b = sorted_[j];
        ++tests;
        if (b.lo > a.hi) break;  // sorted by min: nothing further can overlap
        if (a.lo1 <= b.hi1 && b.lo1 <= a.hi1 && a.lo2 <= b.hi2 && b.lo2 <= a.hi2) emit(a.proxy, b.proxy);
      }
      treeTests += tree.query(bounds[a.proxy], [&](uint32_t s) { emit(a.proxy, s); });
    }
    chunkTests_[job] = tests;
    chunkTreeTests_[job] = treeTests;
  });
  const uint32_t chunks = sweepJobs;
  // Joined in chunk order: each chunk copies its list to its offset, in parallel.
  chunkOffset_.assign(chunks + 1, 0);
  tests_ = 0;
  uint64_t treeTests = 0;
  for (uint32_t c = 0; c < chunks; ++c) {
    chunkOffset_[c + 1] = chunkOffset_[c] + uint32_t(chunkPairs_[c].size());
    tests_ += chunkTests_[c] + chunkTreeTests_[c];
    treeTests += chunkTreeTests_[c];
  }
  queryTestsPerProxy_ = m > 0 ? treeTests / m : 0;
  pairs.resize(chunkOffset_[chunks]);
  forChunks(chunks, 1, stage + 8, "broadphase: join pairs", [&](uint32_t begin, uint32_t end) {
    for (uint32_t c = begin; c < end; ++c) std::copy(chunkPairs_[c].begin(), chunkPairs_[c].end(), pairs.begin() + chunkOffset_[c]);
  });
  sortPairs(pairs, stage + 9);
}

void SweepAndPrune::sortPairs(std::vector<BodyPair>& pairs, int stage) {
  // Repeats come only from owners with several proxies (a grid's cover boxes).
  if (jobs_) {
    pairSorter_.sort(pairs, true, *jobs_, profiler_, "broadphase: sort pairs", stage);
    return;
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
}

template <class F>
void SweepAndPrune::forChunks(uint32_t n, uint32_t grain, int stage, const char* zone, F&& body) {
  chunkedFor(jobs_, profiler_, n, grain, stage, zone, body);
}

}  // namespace bw
