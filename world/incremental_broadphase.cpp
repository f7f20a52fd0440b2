#include "world/incremental_broadphase.h"

#include <algorithm>
#include <cstring>
#include <string>

#include "collision/core/errors.h"
#include "jobs/chunked_for.h"
#include "jobs/parallel_merge.h"
#include "world/static_bounds_tree.h"
#include "world/world_tuning.h"

namespace bw {

namespace {

constexpr uint32_t kNone = DynamicBoundsTree::kNull;
/// Owner ids index per-owner arrays (85 bytes each): larger ids are refused rather than
/// allocated for.
constexpr uint32_t kMaxOwner = 1u << 26;
/// How far ahead the bounds filter prefetches a static pair's moving bounds.
constexpr uint32_t kPrefetch = 16;

bool contains(const WorldAabb& outer, const WorldAabb& inner) {
  return (outer.min.array() <= inner.min.array()).all() && (inner.max.array() <= outer.max.array()).all();
}

// Stage offsets within update()'s range.
enum Stage : int {
  kGather = 0,  // .. + 1: the proxies scanned, the keys written
  kStatics = 2,
  kFat = 3,
  kTreeEdits = 4,
  kTreeBuild = 5,  // .. + DynamicBoundsTree::kBuildStages - 1
  kOrder = kTreeBuild + DynamicBoundsTree::kBuildStages,
  kSelf,  // .. + DynamicBoundsTree::kSelfPairStages - 1
  kQueries = kSelf + DynamicBoundsTree::kSelfPairStages,
  kJoinNew,
  kSortNew,  // .. + 7: the moving pairs', then the static pairs' sort
  kKeep = kSortNew + 8,
  kJoinKept,
  kMerge,  // .. + 1
  kTight = kMerge + 2,
  kJoinTight,
  kMergeOut,
  kEnd,
};
static_assert(kEnd == IncrementalBroadphase::kStages);

}  // namespace

IncrementalBroadphase::IncrementalBroadphase() : staticTree_(std::make_unique<StaticBoundsTree>()) {}
IncrementalBroadphase::~IncrementalBroadphase() = default;
IncrementalBroadphase::IncrementalBroadphase(IncrementalBroadphase&&) noexcept = default;
IncrementalBroadphase& IncrementalBroadphase::operator=(IncrementalBroadphase&&) noexcept = default;

template <class F>
void IncrementalBroadphase::forChunks(uint32_t n, uint32_t grain, int stage, const char* zone, F&& body) {
  chunkedFor(jobs_, profiler_, n, grain, stage, zone, body);
}

template <class T>
void IncrementalBroadphase::join(std::vector<std::vector<T>>& chunks, uint32_t count, std::vector<T>& out, int stage, const char* zone) {
  chunkOffset_.assign(count + 1, 0);
  for (uint32_t c = 0; c < count; ++c) chunkOffset_[c + 1] = chunkOffset_[c] + chunks[c].size();
  out.resize(chunkOffset_[count]);
  forChunks(count, 1, stage, zone, [&](uint32_t c, uint32_t) { std::copy(chunks[c].begin(), chunks[c].end(), out.begin() + chunkOffset_[c]); });
}

// The moving proxies' keys this frame (ascending) and each key's proxy, in parallel chunks;
// bad bounds, owners over the limit and owners with two moving proxies are refused before
// anything that lasts is changed (the frame stamp is new every call).
void IncrementalBroadphase::gather(const std::vector<WorldAabb>& bounds, const std::vector<uint8_t>& isStatic,
                                   const std::vector<uint32_t>* owner) {
  const uint32_t n = uint32_t(bounds.size());
  if (isStatic.size() != n || (owner && owner->size() != n)) validateProxies(bounds, isStatic, owner, "IncrementalBroadphase::update");
  ++frame_;
  const uint32_t grain = tuning::grainFor(n, tuning::kMinProxyGrain);
  const uint32_t chunks = JobSystem::chunkCount(0, n, grain);
  if (chunkKeys_.size() < chunks) {
    chunkKeys_.resize(chunks);
    chunkStatics_.resize(chunks);
  }
  chunkScan_.assign(chunks, ChunkScan{});
  forChunks(n, grain, stage_ + kGather, "broadphase: gather", [&](uint32_t begin, uint32_t end) {
    ChunkScan& scan = chunkScan_[begin / grain];
    std::vector<std::pair<uint32_t, uint32_t>>& keys = chunkKeys_[begin / grain];
    std::vector<uint32_t>& statics = chunkStatics_[begin / grain];
    keys.clear();
    statics.clear();
    for (uint32_t i = begin; i < end; ++i) {
      const WorldAabb& b = bounds[i];
      scan.bad |= !(b.min.allFinite() && b.max.allFinite() && (b.min.array() <= b.max.array()).all());
      if (isStatic[i]) {
        statics.push_back(i);
        continue;
      }
      const uint32_t key = owner ? (*owner)[i] : i;
      scan.largest = std::max(scan.largest, key);
      scan.ascending &= keys.empty() || keys.back().first < key;
      keys.push_back({key, i});
    }
  });
  uint32_t largest = 0;
  bool ascending = true;
  size_t count = 0;
  for (uint32_t c = 0; c < chunks; ++c) {
    if (chunkScan_[c].bad) validateProxies(bounds, isStatic, owner, "IncrementalBroadphase::update");  // throws, naming the proxy
    if (chunkKeys_[c].empty()) continue;
    ascending = ascending && chunkScan_[c].ascending && (count == 0 || largest < chunkKeys_[c].front().first);
    largest = std::max(largest, chunkScan_[c].largest);
    count += chunkKeys_[c].size();
  }
  if (largest >= kMaxOwner) {
    for (uint32_t i = 0; i < n; ++i) {
      const uint32_t key = owner ? (*owner)[i] : i;
      if (!isStatic[i] && key >= kMaxOwner)
        throw InvalidInput("IncrementalBroadphase::update: owner " + std::to_string(key) + " of proxy " + std::to_string(i) +
                           " is over the limit of " + std::to_string(kMaxOwner) + " owners");
    }
  }
  if (!ascending) {
    // Owners out of order (never in the world, whose proxies follow its bodies): sorted, and
    // an owner listed twice refused.
    sortedKeys_.clear();
    for (uint32_t c = 0; c < chunks; ++c) sortedKeys_.insert(sortedKeys_.end(), chunkKeys_[c].begin(), chunkKeys_[c].end());
    std::sort(sortedKeys_.begin(), sortedKeys_.end());
    for (size_t k = 1; k < sortedKeys_.size(); ++k)
      if (sortedKeys_[k].first == sortedKeys_[k - 1].first)
        throw InvalidInput("IncrementalBroadphase::update: owner " + std::to_string(sortedKeys_[k].first) + " has two moving proxies (" +
                           std::to_string(sortedKeys_[k - 1].second) + " and " + std::to_string(sortedKeys_[k].second) + ")");
    chunkKeys_[0].swap(sortedKeys_);
    for (uint32_t c = 1; c < chunks; ++c) chunkKeys_[c].clear();
  }
  // Checked: from here on the state changes.
  if (largest >= seen_.size() && count > 0) {
    const size_t size = std::max<size_t>(largest + 1, seen_.size() * 3 / 2);
    proxy_.resize(size, kNone);
    seen_.resize(size, 0);
    leaf_.resize(size, kNone);
    fat_.resize(size, WorldAabb{Vec3d::Zero(), Vec3d::Zero()});
    centre_.resize(size, Vec3d::Zero());
    moved_.resize(size, 0);
  }
  keys_.resize(count);
  chunkOffset_.assign(chunks + 1, 0);
  staticStart_.assign(chunks + 1, 0);
  for (uint32_t c = 0; c < chunks; ++c) {
    chunkOffset_[c + 1] = chunkOffset_[c] + chunkKeys_[c].size();
    staticStart_[c + 1] = staticStart_[c] + uint32_t(chunkStatics_[c].size());
  }
  // The keys written, and the static proxies compared with those the static tree holds (ids,
  // owners and boxes, bit for bit), in the same chunks.
  const bool sameCount = staticStart_[chunks] == staticIds_.size() && staticBuilds_ > 0;
  forChunks(chunks, 1, stage_ + kGather + 1, "broadphase: keys", [&](uint32_t c, uint32_t) {
    size_t at = chunkOffset_[c];
    for (const auto& [key, proxy] : chunkKeys_[c]) {
      keys_[at++] = key;
      seen_[key] = frame_;
      proxy_[key] = proxy;
    }
    bool changed = !sameCount;
    for (uint32_t k = 0, slot = staticStart_[c]; !changed && k < chunkStatics_[c].size(); ++k, ++slot) {
      const uint32_t i = chunkStatics_[c][k];
      changed = staticIds_[slot] != i || std::memcmp(&bounds[i], &staticBoxes_[slot], sizeof(WorldAabb)) != 0 ||
                staticOwner_[slot] != (owner ? (*owner)[i] : i);
    }
    chunkScan_[c].staticChanged = changed;
  });
}

// The static tree built again when the static proxies changed (gather() compared them).
bool IncrementalBroadphase::rebuildStatics(const std::vector<WorldAabb>& bounds, const std::vector<uint32_t>* owner) {
  bool changed = staticBuilds_ == 0 || staticStart_.back() != staticIds_.size();
  for (const ChunkScan& scan : chunkScan_) changed = changed || scan.staticChanged;
  if (!changed) return false;
  staticIds_.clear();
  // note: chunkStatics_ keeps lists of earlier, larger frames past this frame's chunks.
  for (uint32_t c = 0; c < uint32_t(chunkScan_.size()); ++c)
    staticIds_.insert(staticIds_.end(), chunkStatics_[c].begin(), chunkStatics_[c].end());
  staticBoxes_.clear();
  staticOwner_.clear();
  slots_.clear();
  for (uint32_t s = 0; s < uint32_t(staticIds_.size()); ++s) {
    staticBoxes_.push_back(bounds[staticIds_[s]]);
    staticOwner_.push_back(owner ? (*owner)[staticIds_[s]] : staticIds_[s]);
    slots_.push_back(s);
  }
  staticTree_->build(staticBoxes_, slots_);
  ++staticBuilds_;
  return true;
}

// Each moving proxy's bounds against its fat box, in parallel: one that left it (or is new, or
// whose box is far looser than it needs) gets a new one and joins the moved list (joined in
// chunk order: ascending keys).
void IncrementalBroadphase::fatten(const std::vector<WorldAabb>& bounds) {
  const uint32_t m = uint32_t(keys_.size());
  const uint32_t grain = tuning::grainFor(m, tuning::kMinProxyGrain);
  const uint32_t chunks = JobSystem::chunkCount(0, m, grain);
  if (chunkMoved_.size() < chunks) chunkMoved_.resize(chunks);
  const Vec3d margin = Vec3d::Constant(tuning::kFatMargin), limit = Vec3d::Constant(tuning::kFatPredictionLimit);
  forChunks(m, grain, stage_ + kFat, "broadphase: fat boxes", [&](uint32_t begin, uint32_t end) {
    std::vector<uint32_t>& out = chunkMoved_[begin / grain];
    out.clear();
    for (uint32_t k = begin; k < end; ++k) {
      const uint32_t key = keys_[k];
      const WorldAabb& b = bounds[proxy_[key]];
      const Vec3d c = (b.min + b.max) * 0.5;
      const bool fresh = leaf_[key] == kNone;
      // note: a new proxy's last centre is stale (or unset): no prediction for it.
      const Vec3d ahead = fresh ? Vec3d::Zero() : Vec3d(((c - centre_[key]) * tuning::kFatPrediction).cwiseMin(limit).cwiseMax(-limit));
      // A box stretched for a fall that has ended (a crate landed on a pile) would keep pairs
      // with everything under it: when its slack is over kFatLoose times what the motion now
      // needs, it is made again.
      const Vec3d slack = (fat_[key].max - fat_[key].min) - (b.max - b.min);
      const Vec3d needed = ahead.cwiseAbs() + 2 * margin;
      if (fresh || !contains(fat_[key], b) || (slack.array() > tuning::kFatLoose * needed.array()).any()) {
        fat_[key] = {b.min - margin + ahead.cwiseMin(0.0), b.max + margin + ahead.cwiseMax(0.0)};
        moved_[key] = 1;
        out.push_back(key);
      } else {
        moved_[key] = 0;
      }
      centre_[key] = c;
    }
  });
  movedKeys_.clear();
  for (uint32_t c = 0; c < chunks; ++c) movedKeys_.insert(movedKeys_.end(), chunkMoved_[c].begin(), chunkMoved_[c].end());
  movedCount_ = uint32_t(movedKeys_.size());
}

// Leaves of proxies gone taken out; moved ones refit in place or moved (serial, in key order),
// or the whole tree built again in bulk when many moved. Then the order the queries run in: by
// leaf, so that
// queries near in space run one after another and find the tree's nodes in cache (a million
// queries in key order, spread over the world, missed the cache at every level: 1.3 us each).
bool IncrementalBroadphase::editTree(bool staticChanged) {
  const bool bulk = moveLeaves();
  const OptionalZone z(profiler_, "broadphase: query order", stage_ + kOrder);
  if (bulk || staticChanged) tree_.leafIds(spatial_);
  if (bulk) {
    movedOrder_.clear();
    for (const uint32_t key : spatial_)
      if (moved_[key]) movedOrder_.push_back(key);
    return true;
  }
  byLeaf_.resize(movedKeys_.size());
  for (size_t k = 0; k < movedKeys_.size(); ++k) byLeaf_[k] = uint64_t(leaf_[movedKeys_[k]]) << 32 | movedKeys_[k];
  std::sort(byLeaf_.begin(), byLeaf_.end());
  movedOrder_.resize(byLeaf_.size());
  for (size_t k = 0; k < byLeaf_.size(); ++k) movedOrder_[k] = uint32_t(byLeaf_[k]);
  return false;
}

bool IncrementalBroadphase::moveLeaves() {
  {
    const OptionalZone z(profiler_, "broadphase: tree edits", stage_ + kTreeEdits);
    for (const uint32_t key : removed_) {
      tree_.remove(leaf_[key]);
      leaf_[key] = kNone;
      moved_[key] = 1;  // its pairs go with it
    }
    const uint32_t m = uint32_t(keys_.size());
    const double moved = double(movedKeys_.size());
    const bool bulk = (moved > 64 && (moved > tuning::kFatRebuildShare * double(m) || moved > tuning::kFatRebuildMoves)) ||
                      grownSinceBuild_ > uint64_t(m) + 64;
    if (!bulk) {
      for (const uint32_t key : movedKeys_) {
        if (leaf_[key] == kNone) {
          leaf_[key] = tree_.insert(fat_[key], key);
        } else {
          grownSinceBuild_ += tree_.refit(leaf_[key], fat_[key], tuning::kFatRefitLevels);
        }
      }
      return false;
    }
  }
  const uint32_t m = uint32_t(keys_.size());
  buildBoxes_.resize(m);
  const uint32_t grain = tuning::grainFor(m, tuning::kMinProxyGrain);
  forChunks(m, grain, stage_ + kTreeEdits, "broadphase: tree boxes", [&](uint32_t begin, uint32_t end) {
    for (uint32_t k = begin; k < end; ++k) buildBoxes_[k] = fat_[keys_[k]];
  });
  tree_.build(buildBoxes_, keys_, buildLeaves_, jobs_, profiler_, stage_ + kTreeBuild);
  for (uint32_t k = 0; k < m; ++k) leaf_[keys_[k]] = buildLeaves_[k];
  ++movingBuilds_;
  grownSinceBuild_ = 0;
  return true;
}

// The moved proxies' fat boxes against the tree (a pair of two moved proxies is found by the
// smaller key only) and the static tree, in parallel chunks joined in chunk order, then sorted.
// When the static set changed, every moving proxy queries the static tree instead. After a bulk
// build, the tree against itself gives every pair with a moved proxy at once (a million sparse
// bodies: 4x faster than a query each).
void IncrementalBroadphase::findNewPairs(bool staticChanged, bool bulk) {
  if (bulk) tests_ += tree_.selfPairs(newMm_, moved_.data(), jobs_, profiler_, stage_ + kSelf);
  const std::vector<uint32_t>& staticQueries = staticChanged ? spatial_ : movedOrder_;
  const uint32_t moved = bulk ? 0 : uint32_t(movedOrder_.size()), queries = uint32_t(staticQueries.size());
  const uint32_t items = std::max(moved, queries);
  const uint32_t grain = tuning::grainFor(items, tuning::kMinQueryGrain);
  const uint32_t chunks = JobSystem::chunkCount(0, items, grain);
  if (chunkA_.size() < chunks) chunkA_.resize(chunks);
  if (chunkS_.size() < chunks) chunkS_.resize(chunks);
  chunkTests_.assign(chunks, 0);
  const StaticBoundsTree& statics = *staticTree_;
  forChunks(items, grain, stage_ + kQueries, "broadphase: new pairs", [&](uint32_t begin, uint32_t end) {
    const uint32_t c = begin / grain;
    std::vector<BodyPair>& mm = chunkA_[c];
    std::vector<StaticPair>& ms = chunkS_[c];
    mm.clear();
    ms.clear();
    uint64_t tests = 0;
    for (uint32_t i = begin; i < std::min(end, moved); ++i) {
      const uint32_t p = movedOrder_[i];
      tests += tree_.query(fat_[p], [&](uint32_t q) {
        if (q != p && (!moved_[q] || p < q)) mm.push_back(p < q ? BodyPair{p, q} : BodyPair{q, p});
      });
    }
    for (uint32_t i = begin; i < std::min(end, queries); ++i) {
      const uint32_t p = staticQueries[i];
      tests += statics.query(fat_[p], [&](uint32_t s) {
        const uint32_t o = staticOwner_[s];
        if (o != p) ms.push_back({o < p ? BodyPair{o, p} : BodyPair{p, o}, p, s});
      });
    }
    chunkTests_[c] = tests;
  });
  for (const uint64_t t : chunkTests_) tests_ += t;
  if (!bulk) join(chunkA_, chunks, newMm_, stage_ + kJoinNew, "broadphase: join new pairs");
  join(chunkS_, chunks, newMs_, stage_ + kJoinNew, "broadphase: join new pairs");
  if (jobs_) {
    if (!bulk) sorter_.sort(newMm_, false, *jobs_, profiler_, "broadphase: sort new pairs", stage_ + kSortNew);
    staticSorter_.sort(newMs_, false, *jobs_, profiler_, "broadphase: sort new pairs", stage_ + kSortNew + 4);
  } else {
    if (!bulk) std::sort(newMm_.begin(), newMm_.end());
    std::sort(newMs_.begin(), newMs_.end());
  }
}

// The fat pairs of proxies that did not move stay (their fat boxes did not change); the new
// ones are merged in: both lists stay sorted. (After a static change, the new static pairs are
// all of them.)
void IncrementalBroadphase::keepPairs(bool staticChanged) {
  const uint32_t nmm = uint32_t(mm_.size()), nms = staticChanged ? 0 : uint32_t(ms_.size());
  const uint32_t total = nmm + nms;
  const uint32_t grain = tuning::grainFor(total, tuning::kMinPairGrain);
  const uint32_t chunks = JobSystem::chunkCount(0, total, grain);
  if (chunkA_.size() < chunks) chunkA_.resize(chunks);
  if (chunkS_.size() < chunks) chunkS_.resize(chunks);
  forChunks(total, grain, stage_ + kKeep, "broadphase: kept pairs", [&](uint32_t begin, uint32_t end) {
    std::vector<BodyPair>& mm = chunkA_[begin / grain];
    std::vector<StaticPair>& ms = chunkS_[begin / grain];
    mm.clear();
    ms.clear();
    for (uint32_t i = begin; i < std::min(end, nmm); ++i) {
      const BodyPair p = mm_[i];
      if (!moved_[p.a] && !moved_[p.b]) mm.push_back(p);
    }
    for (uint32_t i = std::max(begin, nmm); i < end; ++i) {
      const StaticPair& p = ms_[i - nmm];
      if (!moved_[p.key]) ms.push_back(p);
    }
  });
  join(chunkA_, chunks, keptMm_, stage_ + kJoinKept, "broadphase: join kept pairs");
  join(chunkS_, chunks, keptMs_, stage_ + kJoinKept, "broadphase: join kept pairs");
  parallelMerge(keptMm_, newMm_, mergedMm_, jobs_, profiler_, "broadphase: merge pairs", stage_ + kMerge);
  mm_.swap(mergedMm_);
  parallelMerge(keptMs_, newMs_, mergedMs_, jobs_, profiler_, "broadphase: merge pairs", stage_ + kMerge + 1);
  ms_.swap(mergedMs_);
}

// The fat pairs whose proxies' bounds overlap now, as pairs of owners: the two lists filtered in
// parallel (each stays sorted, an owner pair met through several static proxies, a grid's
// cover boxes, kept once), then merged.
void IncrementalBroadphase::tightPairs(const std::vector<WorldAabb>& bounds, std::vector<BodyPair>& pairs) {
  const uint32_t nmm = uint32_t(mm_.size()), total = nmm + uint32_t(ms_.size());
  const uint32_t grain = tuning::grainFor(total, tuning::kMinPairGrain);
  const uint32_t chunks = JobSystem::chunkCount(0, total, grain);
  if (chunkA_.size() < chunks) chunkA_.resize(chunks);
  if (chunkB_.size() < chunks) chunkB_.resize(chunks);
  const auto touching = [&](const StaticPair& p) { return bounds[proxy_[p.key]].overlaps(staticBoxes_[p.slot]); };
  forChunks(total, grain, stage_ + kTight, "broadphase: bounds of kept pairs", [&](uint32_t begin, uint32_t end) {
    std::vector<BodyPair>& mm = chunkA_[begin / grain];
    std::vector<BodyPair>& ms = chunkB_[begin / grain];
    mm.clear();
    ms.clear();
    for (uint32_t i = begin; i < std::min(end, nmm); ++i) {
      const BodyPair p = mm_[i];
      if (i + kPrefetch < std::min(end, nmm)) __builtin_prefetch(&bounds[proxy_[mm_[i + kPrefetch].b]]);
      if (bounds[proxy_[p.a]].overlaps(bounds[proxy_[p.b]])) mm.push_back(p);
    }
    if (end <= nmm) return;
    const uint32_t first = std::max(begin, nmm) - nmm, last = end - nmm;
    // The owner pair last kept: one the chunk before kept, if this chunk starts inside its run.
    BodyPair kept{kNone, kNone};
    for (uint32_t j = first; j > 0 && ms_[j - 1].owners == ms_[first].owners; --j)
      if (touching(ms_[j - 1])) {
        kept = ms_[first].owners;
        break;
      }
    for (uint32_t i = first; i < last; ++i) {
      const StaticPair& p = ms_[i];
      // note: the static pairs run by owner pair, so their moving proxies' bounds are read out
      // of order (a grid's pairs span every key): fetched kPrefetch pairs ahead (1M bodies: 117
      // -> 58 ms a frame).
      if (i + kPrefetch < last) __builtin_prefetch(&bounds[proxy_[ms_[i + kPrefetch].key]]);
      if (!(kept == p.owners) && touching(p)) {
        ms.push_back(p.owners);
        kept = p.owners;
      }
    }
  });
  tests_ += total;
  join(chunkA_, chunks, outMm_, stage_ + kJoinTight, "broadphase: join pairs");
  join(chunkB_, chunks, outMs_, stage_ + kJoinTight, "broadphase: join pairs");
  if (!mixedOwners_) {
    // An owner is static or moving, never both: no pair can come from both lists.
    parallelMerge(outMm_, outMs_, pairs, jobs_, profiler_, "broadphase: merge pairs", stage_ + kMergeOut);
    return;
  }
  const OptionalZone z(profiler_, "broadphase: merge pairs", stage_ + kMergeOut);
  pairs.clear();
  size_t i = 0, j = 0;
  while (i < outMm_.size() || j < outMs_.size()) {
    const bool fromMm = j == outMs_.size() || (i < outMm_.size() && outMm_[i] < outMs_[j]);
    const BodyPair p = fromMm ? outMm_[i++] : outMs_[j++];
    if (pairs.empty() || !(pairs.back() == p)) pairs.push_back(p);
  }
}

void IncrementalBroadphase::update(const std::vector<WorldAabb>& bounds, const std::vector<uint8_t>& isStatic, std::vector<BodyPair>& pairs,
                                   JobSystem* jobs, Profiler* profiler, int stage, const std::vector<uint32_t>* owner) {
  jobs_ = jobs;
  profiler_ = profiler;
  stage_ = stage;
  tests_ = 0;
  bool staticChanged;
  gather(bounds, isStatic, owner);
  {
    const OptionalZone z(profiler, "broadphase: statics", stage + kStatics);
    staticChanged = rebuildStatics(bounds, owner);
    // Proxies gone since the last frame (none when the keys are the same), and whether an owner
    // has both static and moving proxies (it can pair with a body through both).
    const bool keysChanged = lastKeys_ != keys_;
    removed_.clear();
    if (keysChanged)
      for (const uint32_t key : lastKeys_)
        if (seen_[key] != frame_) removed_.push_back(key);
    if (keysChanged || staticChanged) {
      mixedOwners_ = false;
      for (const uint32_t o : staticOwner_) mixedOwners_ = mixedOwners_ || (o < seen_.size() && seen_[o] == frame_);
    }
  }
  fatten(bounds);
  const bool bulk = editTree(staticChanged);
  findNewPairs(staticChanged, bulk);
  keepPairs(staticChanged);
  tightPairs(bounds, pairs);
  lastKeys_.swap(keys_);
}

}  // namespace bw
