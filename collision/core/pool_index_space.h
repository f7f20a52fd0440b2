#pragma once
/// Index bookkeeping behind VirtualPool: one virtual reservation holding block metadata, a
/// live bitmap and one column per element type, all addressed by the same 32-bit index.
///
/// Slots are grouped into blocks of a power-of-two count sized so the largest column's block
/// is about one OS page. Each block keeps its own free-slot list (links stored in the free
/// slots of column 0), so when a block's last element is freed its pages can be given back
/// (madvise) without breaking any list. A page straddling several blocks is given back once
/// every block touching it is empty. One emptied block is kept resident as a spare so an
/// alternating allocate/free at a block boundary does not page-fault and madvise every time.
///
/// Complexity: acquire and release are O(1) (release may madvise a handful of pages).
/// Thread safety: none; one writer at a time. Elements never move while live.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <span>
#include <string>
#include <vector>

#include "collision/core/ids.h"
#include "collision/core/virtual_reservation.h"

namespace bw {

class PoolIndexSpace {
 public:
  /// Largest capacity: indices are 32-bit and kInvalidIndex is reserved.
  static constexpr uint32_t kMaxCapacity = 0xFFFFFFF0u;

  /// Reserves room for `maxElements` slots in each column of the given byte strides.
  /// Throws InvalidInput for maxElements == 0 or > kMaxCapacity, or a column-0 stride < 4.
  PoolIndexSpace(uint32_t maxElements, std::initializer_list<size_t> strides, std::string name);

  /// A free slot index; its column memory is uninitialised. Throws CapacityExceeded when full.
  uint32_t acquire();
  /// The indices n acquire() calls would give, in their order, into out[0..n), leaving the
  /// state they leave; a block's untouched slots go as one run (a grid made of a part that broke
  /// off takes thousands at once). Throws CapacityExceeded, acquiring nothing, if n do not fit.
  void acquireMany(uint32_t n, uint32_t* out);
  /// Returns a live slot (its elements already destroyed) to its block's free list.
  void release(uint32_t index);
  /// Throws InvalidInput naming the first index that is not live or is listed twice, before
  /// anything is released (for releaseMany's callers that destroy elements first). Not const:
  /// the live bits serve as its marks and are restored; call it as a writer.
  void requireLiveDistinct(std::span<const uint32_t> indices, const char* operation);
  /// release() of each index in turn (live and distinct: call requireLiveDistinct first), leaving exactly
  /// the state those calls leave, faster for thousands: the slots are asked for ahead (each
  /// release writes a free-list link into its slot, a cache miss in a random order), and the
  /// emptied blocks' pages are given back once at the end, a run of pages per madvise.
  void releaseMany(std::span<const uint32_t> indices);

  /// While one is alive, emptied blocks' pages are given back when the last one ends, in runs,
  /// instead of a madvise per block (a bulk removal empties hundreds of blocks). Nests.
  class DeferPageRelease {
   public:
    explicit DeferPageRelease(PoolIndexSpace& space) : space_(space) { ++space_.deferDepth_; }
    ~DeferPageRelease() {
      if (--space_.deferDepth_ == 0) space_.releaseDeferredPages();
    }
    DeferPageRelease(const DeferPageRelease&) = delete;
    DeferPageRelease& operator=(const DeferPageRelease&) = delete;

   private:
    PoolIndexSpace& space_;
  };
  /// Throws InvalidInput naming `operation` if index is not a live slot.
  void requireLive(uint32_t index, const char* operation) const;

  bool isLive(uint32_t index) const {
    return index < highWaterSlots() && (liveBits_[index >> 6] >> (index & 63)) & 1u;
  }
  /// Asks the cache for what release(index) writes besides the slot: its live bits and its
  /// block's record (index < highWaterSlots()).
  void prefetchRelease(uint32_t index) const {
    __builtin_prefetch(&liveBits_[index >> 6], 1);
    __builtin_prefetch(&meta_[blockOf(index)], 1);
  }
  std::byte* column(size_t k) const { return columns_[k]; }
  uint32_t size() const { return live_; }
  uint32_t capacity() const { return capacity_; }
  /// One past the largest slot index that may be live.
  uint32_t highWaterSlots() const { return highWater_ * slotsPerBlock_; }
  uint32_t slotsPerBlock() const { return slotsPerBlock_; }
  const std::string& name() const { return name_; }

  /// Calls f(index) for every live slot in ascending index order.
  template <class F>
  void forEachLive(F&& f) const {
    const uint32_t words = (highWaterSlots() + 63) / 64;
    for (uint32_t w = 0; w < words; ++w) {
      uint64_t bits = liveBits_[w];
      while (bits) {
        const int b = __builtin_ctzll(bits);
        bits &= bits - 1;
        f(uint32_t(w * 64 + b));
      }
    }
  }

  /// Resident bytes of the whole reservation (metadata + columns), measured with mincore().
  size_t residentBytes() const;
  size_t reservedBytes() const { return reservation_.size(); }

 private:
  enum class BlockState : uint8_t { Untouched, Active, Released };
  struct BlockMeta {
    uint32_t live;      // 4  live slots in the block
    uint32_t freeHead;  // 4  first free slot (block-relative) or kInvalidIndex
    uint32_t bump;      // 4  slots [0, bump) have been handed out since the block was (re)started
    uint32_t next;      // 4  next block in the available or released list
    uint32_t prev;      // 4  previous block in the available list
    BlockState state;   // 1
  };
  static_assert(sizeof(BlockMeta) == 24);

  // note: the link lives in the free slot's first 4 bytes through memcpy, so element types
  // with alignment below 4 (byte arrays, packed structs) are fine.
  uint32_t readFreeLink(uint32_t index) const {
    uint32_t v;
    std::memcpy(&v, columns_[0] + size_t(index) * strides_[0], sizeof v);
    return v;
  }
  void writeFreeLink(uint32_t index, uint32_t v) const { std::memcpy(columns_[0] + size_t(index) * strides_[0], &v, sizeof v); }
  void pushAvailable(uint32_t b);
  void removeAvailable(uint32_t b);
  void releaseBlock(uint32_t b);
  /// Gives back the pages of column k that only released (or untouched) blocks share, over
  /// blocks [firstBlock, lastBlock].
  void releaseFreePages(size_t k, uint32_t firstBlock, uint32_t lastBlock);
  void releaseDeferredPages();
  /// release() once the slot's live bit is cleared.
  void releaseCleared(uint32_t index);
  uint32_t blockOf(uint32_t index) const { return index >> blockShift_; }
  bool blockReleasedOrUntouched(uint32_t b) const {
    return b >= highWater_ || meta_[b].state == BlockState::Released;
  }

  std::string name_;
  VirtualReservation reservation_;
  BlockMeta* meta_ = nullptr;
  uint64_t* liveBits_ = nullptr;
  std::vector<std::byte*> columns_;
  std::vector<size_t> strides_;
  std::vector<size_t> columnOffsets_;
  uint32_t capacity_ = 0;
  uint32_t slotsPerBlock_ = 1;
  uint32_t blockShift_ = 0;                 // log2(slotsPerBlock_)
  uint32_t numBlocks_ = 0;
  uint32_t highWater_ = 0;           // blocks [0, highWater_) have been touched
  uint32_t availableHead_ = kInvalidIndex;  // Active blocks with at least one free slot
  uint32_t releasedHead_ = kInvalidIndex;   // Released blocks, LIFO
  uint32_t spare_ = kInvalidIndex;          // the one empty block kept resident
  uint32_t live_ = 0;
  int deferDepth_ = 0;                      // DeferPageRelease scopes alive
  std::vector<uint32_t> deferredBlocks_;    // blocks released while deferring
};

}  // namespace bw
