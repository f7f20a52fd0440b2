// bulkLoad's build: the canonical tree of build() from one radix sort instead of a partition
// at every level.
//
// Why: a part that breaks off a grid is bulk-loaded into its own index, and that build was the
// cut's critical path (issue 18): build() partitions its items in place at every level, a swap
// and a mispredicted branch per item per level (half of a 50k-brick build in perf).
//
// How: every element's path from the root is the child slots of its centre's lattice point
// (Lattice::slotBelow), and it stops at its natural depth, the first node whose level its min
// level reaches. A key holds the path's first kSortedLevels slots, 3 bits each, with the slots
// below the natural depth zeroed, and the natural depth in its low bits. Sorted by key:
// - every node's elements are one run of keys, its children's runs follow each other in slot
//   order, and the elements that stop at the node (its `big` ones) come first in its run (their
//   key is the node's own prefix, zero-padded, with the smallest depth);
// - so each node finds its held elements and its children's runs by searching its run, with
//   nothing moved (an element's natural depth is in its key, and item i is input i: an item's
//   BuildItem is made from its input only where build() takes over).
// What the keys cannot order is left to build(): a node at depth kSortedLevels, and elements
// forced below their natural depth (their key stops at the node that forces them down).
// The tree is build()'s (structureHash equal, tested); inside a node, elements are listed in key
// order, then input order, where build()'s partitions left its own order.
#include <algorithm>
#include <array>
#include <bit>

#include "collision/index/octobvh.h"

namespace bw {

using namespace octobvh;

namespace {

constexpr int kSortedLevels = 19;  // 57 bits of slots
constexpr int kDepthBits = 5;      // the natural depth (0..kSortedLevels) below the slots
static_assert(3 * kSortedLevels + kDepthBits <= 64);
constexpr uint64_t kDepthMask = (uint64_t(1) << kDepthBits) - 1;

// Bit j of a byte to bit 3j.
constexpr std::array<uint32_t, 256> kSpreadByte = [] {
  std::array<uint32_t, 256> t{};
  for (uint32_t b = 0; b < 256; ++b)
    for (int j = 0; j < 8; ++j) t[b] |= ((b >> j) & 1u) << (3 * j);
  return t;
}();

// Bits 0..kSortedLevels-1 of v to bits 0, 3, 6, ...
uint64_t spreadBits3(uint64_t v) {
  return uint64_t(kSpreadByte[v & 0xFF]) | uint64_t(kSpreadByte[(v >> 8) & 0xFF]) << 24 |
         uint64_t(kSpreadByte[(v >> 16) & 0xFF]) << 48;
}

// The bits where a range's keys differ (zero when they are all equal).
template <class Keyed>
uint64_t differingBits(const Keyed* v, size_t n) {
  uint64_t all = ~uint64_t(0), any = 0;
  for (size_t i = 0; i < n; ++i) all &= v[i].key, any |= v[i].key;
  return all ^ any;
}

// Stable LSD radix sort of v[0, n) by key over the bits where keys differ, `Bits` bits a pass,
// every pass's counts taken in one read; tmp (n items) is scratch. The result is in v.
template <int Bits, class Keyed>
void lsdSortByKey(Keyed* v, Keyed* tmp, size_t n, uint64_t differ) {
  constexpr uint32_t kBuckets = 1u << Bits;
  const int lo = std::countr_zero(differ), hi = 64 - std::countl_zero(differ);
  const int passes = (hi - lo + Bits - 1) / Bits;
  std::vector<uint32_t> counts(size_t(passes) * kBuckets, 0);
  for (size_t i = 0; i < n; ++i)
    for (int p = 0; p < passes; ++p) ++counts[size_t(p) * kBuckets + ((v[i].key >> (lo + p * Bits)) & (kBuckets - 1))];
  Keyed *from = v, *to = tmp;
  for (int p = 0; p < passes; ++p) {
    uint32_t* start = &counts[size_t(p) * kBuckets];
    for (uint32_t b = 0, acc = 0; b < kBuckets; ++b) {
      const uint32_t c = start[b];
      start[b] = acc;
      acc += c;
    }
    const int shift = lo + p * Bits;
    for (size_t i = 0; i < n; ++i) to[start[(from[i].key >> shift) & (kBuckets - 1)]++] = from[i];
    std::swap(from, to);
  }
  if (from != v) std::copy(from, from + n, v);
}

// Stable sort of v[0, n) by key (tmp: n items of scratch). Big ranges first scatter by their top
// 11 differing bits, then sort each bucket on its own (most fit in cache): a 2.5M-brick build
// read and wrote its 40 MB of keys five times over with LSD passes alone.
template <class Keyed>
void sortByKey(Keyed* v, Keyed* tmp, size_t n) {
  constexpr size_t kSmall = 24, kCacheSized = size_t(1) << 16;
  if (n <= kSmall) {  // insertion sort: stable
    for (size_t i = 1; i < n; ++i) {
      const Keyed x = v[i];
      size_t j = i;
      for (; j > 0 && v[j - 1].key > x.key; --j) v[j] = v[j - 1];
      v[j] = x;
    }
    return;
  }
  const uint64_t differ = differingBits(v, n);
  if (differ == 0) return;
  if (n <= kCacheSized) return lsdSortByKey<8>(v, tmp, n, differ);
  constexpr int kBits = 11;
  constexpr uint32_t kBuckets = 1u << kBits;
  const int hi = 64 - std::countl_zero(differ);
  const int shift = std::max(hi - kBits, std::countr_zero(differ));
  std::vector<uint32_t> start(kBuckets + 1, 0);
  for (size_t i = 0; i < n; ++i) ++start[((v[i].key >> shift) & (kBuckets - 1)) + 1];
  for (uint32_t b = 0; b < kBuckets; ++b) start[b + 1] += start[b];
  std::vector<uint32_t> next(start.begin(), start.end() - 1);
  for (size_t i = 0; i < n; ++i) tmp[next[(v[i].key >> shift) & (kBuckets - 1)]++] = v[i];
  for (uint32_t b = 0; b < kBuckets; ++b)
    if (start[b + 1] - start[b] > 1) sortByKey(tmp + start[b], v + start[b], start[b + 1] - start[b]);
  std::copy(tmp, tmp + n, v);
}

template <class Keyed>
void radixSortByKey(OverwriteVector<Keyed>& v) {
  OverwriteVector<Keyed> tmp;
  resizeForOverwrite(tmp, v.size());  // scratch: every entry written before it is read
  sortByKey(v.data(), tmp.data(), v.size());
}

}  // namespace

uint64_t OctoBvh::sortedBuildKey(const BuildItem& it) const {
  const int depth = std::clamp(rootLevel_ - int(it.minLevel), 0, kSortedLevels);
  const Lattice at = latticeOf(it.ctr);
  // The lattice has rootLevel_ - kMinLevel bits an axis, the first slot the highest of them.
  const int width = rootLevel_ - kMinLevel;
  uint64_t path = 0;
  for (int k = 0; k < 3; ++k) {
    const uint64_t x = uint64_t(at.x[k]);
    const uint64_t top = width >= kSortedLevels ? x >> (width - kSortedLevels) : x << (kSortedLevels - width);
    path |= spreadBits3(top) << k;
  }
  const int below = 3 * (kSortedLevels - depth);
  if (below > 0) path &= ~((uint64_t(1) << below) - 1);
  return path << kDepthBits | uint64_t(depth);
}

// note: the keys come straight from the inputs' bounds (an item's centre and min level are a few
// operations): an array of every input's BuildItem, 32 bytes each, was written and read once
// more, its pages first touched here (a 50k-brick part: 400 pages, 1.6 MB).
OverwriteVector<OctoBvh::SortedItem> OctoBvh::sortForBuild(std::span<const Aabb> bounds) const {
  OverwriteVector<SortedItem> sorted;
  resizeForOverwrite(sorted, bounds.size());
  BuildItem it;
  for (uint32_t i = 0; i < uint32_t(bounds.size()); ++i) {
    buildItemOf(ElementRecord::of(bounds[i], 0, 0), i, it);
    sorted[i] = {sortedBuildKey(it), i};
  }
  radixSortByKey(sorted);
  return sorted;
}

void OctoBvh::buildRunUnsorted(uint32_t c, int s, const Cube& cube, const SortedItem* sorted, uint32_t count, bool octants) {
  std::vector<BuildItem>& run = runScratch_;  // build() never comes back here: one scratch
  run.resize(count);
  for (uint32_t i = 0; i < count; ++i) {
    const uint32_t item = sorted[i].item;
    buildItemOf(ElementRecord::of(bulk_->bounds[item], 0, 0), item, run[i]);
  }
  if (octants) buildOctants(c, cube, run.data(), count);
  else build(c, s, cube, run.data(), count);
}

void OctoBvh::buildSorted(uint32_t c, int s, const Cube& cube, int depth, const SortedItem* sorted, uint32_t count) {
  if (depth == kSortedLevels) return buildRunUnsorted(c, s, cube, sorted, count, false);
  if (count <= uint32_t(kLeafCapacity) || cube.level == kMinLevel) {
    // note: the inputs are scattered (asked for first, as build()'s leaves do).
    for (uint32_t i = 0; i < count; ++i) {
      const uint32_t e = sorted[i].item;
      __builtin_prefetch(&bulk_->bounds[e]);
      __builtin_prefetch(&bulk_->filters[e]);
      __builtin_prefetch(&bulk_->payloads[e]);
    }
    for (uint32_t i = 0; i < count; ++i) heldAdd(c, s, placeBuilt(sorted[i].item));
    refit(c, s);
    return;
  }
  // The elements that stop here lead the run: their natural depth is this node's.
  uint32_t big = 0;
  while (big < count && (sorted[big].key & kDepthMask) == uint64_t(depth)) ++big;
  const bool forced = big > uint32_t(kLeafCapacity);
  const uint32_t child = allocCluster(cube.level - 1);
  clusters_[c].child[s] = child;
  if (!forced) {
    for (uint32_t i = 0; i < big; ++i) heldAdd(c, s, placeBuilt(sorted[i].item));
    buildOctantsSorted(child, cube, depth, sorted + big, count - big);
  } else if (big == count) {
    clusters_[child].forcedCount = big;  // as build(): nothing fits a child, all forced down
    buildRunUnsorted(child, 0, cube, sorted, count, true);
  } else {
    const uint32_t forcedCluster = allocCluster(cube.level - 1);
    clusters_[c].leaf[s] = forcedCluster;
    clusters_[c].numHeld[s] = kForcedCluster;
    clusters_[forcedCluster].forcedCount = big;
    buildRunUnsorted(forcedCluster, 0, cube, sorted, big, true);
    buildOctantsSorted(child, cube, depth, sorted + big, count - big);
  }
  refit(c, s);
}

void OctoBvh::buildOctantsSorted(uint32_t sub, const Cube& cube, int depth, const SortedItem* sorted, uint32_t n) {
  clusters_[sub].childTotal = n;
  // Every key here shares the slots above depth + 1; the slot at depth + 1 orders the runs.
  const int shift = kDepthBits + 3 * (kSortedLevels - depth - 1);
  const SortedItem* first = sorted;
  const SortedItem* const end = sorted + n;
  for (int o = 0; o < 8 && first != end; ++o) {
    const SortedItem* last =
        std::partition_point(first, end, [&](const SortedItem& k) { return int((k.key >> shift) & 7) <= o; });
    const uint32_t count = uint32_t(last - first);
    if (count) buildSorted(sub, o, cube.child(o), depth + 1, first, count);
    first = last;
  }
}

}  // namespace bw
