#pragma once
/// A deterministic parallel sort (optionally dropping repeats) on the job system: a sample sort
/// in four stages, each one parallelFor.
///
///   bw::ParallelSorter<BodyPair> sorter;                  // keeps its scratch between calls
///   sorter.sort(pairs, /*unique*/ true, jobs, &profiler, "pairs: sort", stage);  // stages stage..stage+3
///
/// 1. count    (chunks of the input): each element's bucket by binary search in the splitters
///             (a fixed, evenly spaced sample of the input, sorted), counted per chunk.
/// 2. scatter  (chunks): elements copied to their bucket, chunk by chunk in input order.
/// 3. buckets  (one job per bucket): std::sort, then repeats dropped. Equal elements always land
///             in the same bucket, so no repeat spans two buckets.
/// 4. gather   (one job per bucket): the buckets copied back in order.
/// Determinism: the chunks depend only on the input size and equal elements are
/// indistinguishable (the order must be strict and total on distinct values: T's operator< or
/// `Less`), so the output is the same sorted sequence for any thread count. Inputs below
/// kSerialBelow elements are sorted on the calling thread (one zone at `stage`).
/// No allocation once the scratch has grown to the largest input seen.
/// Thread safety: one sort() at a time per sorter.
#include <algorithm>
#include <cstdint>
#include <functional>
#include <vector>

#include "jobs/job_system.h"
#include "jobs/profiler.h"

namespace bw {

template <class T, class Less = std::less<T>>
class ParallelSorter {
 public:
  /// Inputs smaller than this are sorted serially: the four stages' scheduling would cost more.
  static constexpr uint32_t kSerialBelow = 512;
  /// Most chunks and buckets (four per thread at 16 threads), fewest elements per chunk.
  static constexpr uint32_t kMaxChunks = 64, kMinChunk = 128;
  /// Sample elements per bucket when choosing the splitters.
  static constexpr uint32_t kOversample = 16;

  template <class Alloc>
  void sort(std::vector<T, Alloc>& v, bool unique, JobSystem& jobs, Profiler* profiler, const char* zone, int stage) {
    const uint32_t n = uint32_t(v.size());
    if (n < kSerialBelow) {
      Zone z(profiler, zone, stage);
      std::sort(v.begin(), v.end(), less_);
      if (unique) v.erase(std::unique(v.begin(), v.end(), equal()), v.end());
      return;
    }
    const uint32_t grain = std::max(kMinChunk, (n + kMaxChunks - 1) / kMaxChunks);
    const uint32_t chunks = JobSystem::chunkCount(0, n, grain);
    const uint32_t buckets = chunks;
    // Splitters: every kOversample-th of an evenly spaced sample, sorted (a pure function of v).
    sample_.clear();
    const uint32_t samples = buckets * kOversample;
    for (uint32_t s = 0; s < samples; ++s) sample_.push_back(v[uint32_t(uint64_t(s) * n / samples)]);
    std::sort(sample_.begin(), sample_.end(), less_);
    splitters_.clear();
    for (uint32_t b = 1; b < buckets; ++b) splitters_.push_back(sample_[b * kOversample]);
    auto bucketOf = [&](const T& x) {
      return uint32_t(std::upper_bound(splitters_.begin(), splitters_.end(), x, less_) - splitters_.begin());
    };
    counts_.assign(size_t(chunks) * buckets, 0);
    jobs.parallelFor(0, n, grain, [&](uint32_t begin, uint32_t end) {
      Zone z(profiler, zone, stage);
      uint32_t* c = &counts_[size_t(begin / grain) * buckets];
      for (uint32_t i = begin; i < end; ++i) ++c[bucketOf(v[i])];
    });
    // Bucket-major offsets: bucket b holds chunk 0's elements of b, then chunk 1's, ...
    bucketBegin_.assign(buckets + 1, 0);
    uint32_t at = 0;
    for (uint32_t b = 0; b < buckets; ++b) {
      bucketBegin_[b] = at;
      for (uint32_t c = 0; c < chunks; ++c) {
        const uint32_t k = counts_[size_t(c) * buckets + b];
        counts_[size_t(c) * buckets + b] = at;  // now the chunk's write position in bucket b
        at += k;
      }
    }
    bucketBegin_[buckets] = n;
    scratch_.resize(n);
    jobs.parallelFor(0, n, grain, [&](uint32_t begin, uint32_t end) {
      Zone z(profiler, zone, stage + 1);
      uint32_t* at = &counts_[size_t(begin / grain) * buckets];
      for (uint32_t i = begin; i < end; ++i) scratch_[at[bucketOf(v[i])]++] = v[i];
    });
    bucketSize_.assign(buckets, 0);
    jobs.parallelFor(0, buckets, 1, [&](uint32_t begin, uint32_t end) {
      Zone z(profiler, zone, stage + 2);
      for (uint32_t b = begin; b < end; ++b) {
        const auto first = scratch_.begin() + bucketBegin_[b], last = scratch_.begin() + bucketBegin_[b + 1];
        std::sort(first, last, less_);
        bucketSize_[b] = uint32_t((unique ? std::unique(first, last, equal()) : last) - first);
      }
    });
    outBegin_.assign(buckets + 1, 0);
    for (uint32_t b = 0; b < buckets; ++b) outBegin_[b + 1] = outBegin_[b] + bucketSize_[b];
    v.resize(outBegin_[buckets]);
    jobs.parallelFor(0, buckets, 1, [&](uint32_t begin, uint32_t end) {
      Zone z(profiler, zone, stage + 3);
      for (uint32_t b = begin; b < end; ++b)
        std::copy_n(scratch_.begin() + bucketBegin_[b], bucketSize_[b], v.begin() + outBegin_[b]);
    });
  }

 private:
  // A zone when there is a profiler.
  struct Zone {
    Profiler* p;
    const char* name;
    int stage;
    int64_t begin;
    Zone(Profiler* p, const char* name, int stage) : p(p && p->enabled() ? p : nullptr), name(name), stage(stage), begin(this->p ? p->now() : 0) {}
    ~Zone() {
      if (p) p->record(name, begin, p->now(), stage);
    }
  };
  auto equal() const {
    return [this](const T& a, const T& b) { return !less_(a, b) && !less_(b, a); };
  }

  Less less_{};
  std::vector<T> scratch_, sample_, splitters_;
  std::vector<uint32_t> counts_, bucketBegin_, bucketSize_, outBegin_;
};

}  // namespace bw
