#include "collision/core/pool_index_space.h"

#include <algorithm>

#include "collision/core/argument_checks.h"
#include "collision/core/assert.h"

namespace bw {
namespace {

size_t roundUp(size_t v, size_t m) { return (v + m - 1) / m * m; }

}  // namespace

PoolIndexSpace::PoolIndexSpace(uint32_t maxElements, std::initializer_list<size_t> strides, std::string name)
    : name_(std::move(name)), strides_(strides) {
  if (maxElements == 0 || maxElements > kMaxCapacity)
    throw InvalidInput(name_ + ": capacity is " + std::to_string(maxElements) + ", expected 1.." +
                       std::to_string(kMaxCapacity));
  if (strides_.empty() || strides_[0] < sizeof(uint32_t))
    throw InvalidInput(name_ + ": the first column's element must be at least 4 bytes (it holds the free list)");

  const size_t page = VirtualReservation::pageSize();
  const size_t largest = *std::max_element(strides_.begin(), strides_.end());
  while (size_t(slotsPerBlock_) * 2 * largest <= page && slotsPerBlock_ < (1u << 16)) {
    slotsPerBlock_ *= 2;
    ++blockShift_;
  }

  numBlocks_ = uint32_t((uint64_t(maxElements) + slotsPerBlock_ - 1) / slotsPerBlock_);
  capacity_ = uint32_t(std::min<uint64_t>(uint64_t(numBlocks_) * slotsPerBlock_, kMaxCapacity));

  // Layout: [block metadata][live bitmap][column 0][column 1]..., each page-aligned.
  size_t offset = roundUp(size_t(numBlocks_) * sizeof(BlockMeta), page);
  const size_t bitsOffset = offset;
  offset += roundUp((size_t(numBlocks_) * slotsPerBlock_ + 63) / 64 * sizeof(uint64_t), page);
  for (size_t s : strides_) {
    columnOffsets_.push_back(offset);
    offset += roundUp(size_t(numBlocks_) * slotsPerBlock_ * s, page);
  }
  reservation_ = VirtualReservation(offset, name_.c_str());
  meta_ = reinterpret_cast<BlockMeta*>(reservation_.data());
  liveBits_ = reinterpret_cast<uint64_t*>(reservation_.data() + bitsOffset);
  for (size_t off : columnOffsets_) columns_.push_back(reservation_.data() + off);
}

void PoolIndexSpace::pushAvailable(uint32_t b) {
  BlockMeta& m = meta_[b];
  m.prev = kInvalidIndex;
  m.next = availableHead_;
  if (availableHead_ != kInvalidIndex) meta_[availableHead_].prev = b;
  availableHead_ = b;
}

void PoolIndexSpace::removeAvailable(uint32_t b) {
  BlockMeta& m = meta_[b];
  if (m.prev != kInvalidIndex) meta_[m.prev].next = m.next;
  else availableHead_ = m.next;
  if (m.next != kInvalidIndex) meta_[m.next].prev = m.prev;
  m.next = m.prev = kInvalidIndex;
}

uint32_t PoolIndexSpace::acquire() {
  uint32_t b = availableHead_;
  if (b == kInvalidIndex) {
    if (releasedHead_ != kInvalidIndex) {
      b = releasedHead_;
      releasedHead_ = meta_[b].next;
    } else if (highWater_ < numBlocks_) {
      b = highWater_++;
    } else {
      throw CapacityExceeded(name_ + ": pool exhausted, all " + std::to_string(capacity_) +
                             " slots of the reservation are in use");
    }
    meta_[b] = BlockMeta{0, kInvalidIndex, 0, kInvalidIndex, kInvalidIndex, BlockState::Active};
    pushAvailable(b);
  }
  BlockMeta& m = meta_[b];
  uint32_t slot;
  if (m.freeHead != kInvalidIndex) {
    slot = b * slotsPerBlock_ + m.freeHead;
    m.freeHead = readFreeLink(slot);
  } else {
    slot = b * slotsPerBlock_ + m.bump++;
  }
  if (++m.live == slotsPerBlock_) removeAvailable(b);
  if (spare_ == b) spare_ = kInvalidIndex;
  liveBits_[slot >> 6] |= uint64_t(1) << (slot & 63);
  ++live_;
  return slot;
}

void PoolIndexSpace::acquireMany(uint32_t n, uint32_t* out) {
  // (acquire() runs out only once every block is full: the same count, checked before any)
  if (uint64_t(n) > uint64_t(numBlocks_) * slotsPerBlock_ - live_)
    throw CapacityExceeded(name_ + ": pool exhausted, " + std::to_string(n) + " slots asked for, " +
                           std::to_string(uint64_t(numBlocks_) * slotsPerBlock_ - live_) + " free");
  uint32_t done = 0;
  while (done < n) {
    const uint32_t b = availableHead_;
    if (b == kInvalidIndex || meta_[b].freeHead != kInvalidIndex) {
      out[done++] = acquire();  // a block to start, or a freed slot first: acquire's own order
      continue;
    }
    // The head block has no freed slot, so slots [0, bump) are all live and acquire() would
    // hand out bump, bump + 1, ... until the block is full or n are taken.
    BlockMeta& m = meta_[b];
    const uint32_t first = b * slotsPerBlock_ + m.bump;
    const uint32_t run = std::min(n - done, slotsPerBlock_ - m.bump);
    for (uint32_t k = 0; k < run; ++k) out[done + k] = first + k;
    for (uint32_t slot = first; slot < first + run;) {  // the live bits a word at a time
      const uint32_t bit = slot & 63, take = std::min(64 - bit, first + run - slot);
      liveBits_[slot >> 6] |= (take == 64 ? ~uint64_t(0) : ((uint64_t(1) << take) - 1)) << bit;
      slot += take;
    }
    m.bump += run;
    m.live += run;
    live_ += run;
    done += run;
    if (m.live == slotsPerBlock_) removeAvailable(b);
    BW_ASSERT(spare_ != b);  // the spare emptied by freeing: its slots are on its free list
  }
}

void PoolIndexSpace::requireLive(uint32_t index, const char* operation) const {
  if (!isLive(index))
    throw InvalidInput(name_ + ": " + operation + " of index " + std::to_string(index) +
                       ", which is not a live element");
}

void PoolIndexSpace::release(uint32_t index) {
  requireLive(index, "release");
  liveBits_[index >> 6] &= ~(uint64_t(1) << (index & 63));
  releaseCleared(index);
}

void PoolIndexSpace::releaseCleared(uint32_t index) {
  const uint32_t b = blockOf(index);
  BlockMeta& m = meta_[b];
  --live_;
  if (m.live-- == slotsPerBlock_) pushAvailable(b);
  writeFreeLink(index, m.freeHead);
  m.freeHead = index - (b << blockShift_);
  if (m.live == 0) {
    if (spare_ != kInvalidIndex) releaseBlock(spare_);
    spare_ = b;
  }
}

void PoolIndexSpace::requireLiveDistinct(std::span<const uint32_t> indices, const char* operation) {
  // note: the live bits double as marks: cleared as each index is checked (a repeated one then
  // reads dead), all set again before returning or throwing.
  uint64_t* bits = liveBits_;
  size_t checked = 0;
  for (; checked < indices.size(); ++checked) {
    const uint32_t i = indices[checked];
    if (!isLive(i)) break;
    bits[i >> 6] &= ~(uint64_t(1) << (i & 63));
  }
  for (size_t j = 0; j < checked; ++j) bits[indices[j] >> 6] |= uint64_t(1) << (indices[j] & 63);
  if (checked == indices.size()) return;
  const uint32_t bad = indices[checked];
  const bool repeated = std::find(indices.begin(), indices.begin() + checked, bad) != indices.begin() + checked;
  throw InvalidInput(name_ + ": " + operation + " of index " + std::to_string(bad) +
                     (repeated ? ", which is listed twice" : ", which is not a live element"));
}

void PoolIndexSpace::releaseMany(std::span<const uint32_t> indices) {
  DeferPageRelease defer(*this);
  // note: 16 slots ahead covers a miss (~100 ns) at a few ns per release.
  constexpr size_t kAhead = 16;
  const size_t n = indices.size();
  for (size_t j = 0; j < n; ++j) {
    if (j + kAhead < n) {
      const uint32_t a = indices[j + kAhead];
      __builtin_prefetch(columns_[0] + size_t(a) * strides_[0], 1);
      __builtin_prefetch(&meta_[blockOf(a)], 1);
    }
    const uint32_t i = indices[j];
    BW_ASSERT(isLive(i));
    liveBits_[i >> 6] &= ~(uint64_t(1) << (i & 63));
    releaseCleared(i);
  }
}

void PoolIndexSpace::releaseBlock(uint32_t b) {
  removeAvailable(b);
  BlockMeta& m = meta_[b];
  m.state = BlockState::Released;
  m.next = releasedHead_;
  releasedHead_ = b;
  if (deferDepth_ > 0) {
    deferredBlocks_.push_back(b);
    return;
  }
  for (size_t k = 0; k < columns_.size(); ++k) releaseFreePages(k, b, b);
}

void PoolIndexSpace::releaseDeferredPages() {
  if (deferredBlocks_.empty()) return;
  // Blocks taken again since (acquire reuses released blocks first) are Active: their pages
  // stay. The rest, sorted, make runs of adjacent blocks, each run one pass per column.
  std::vector<uint32_t>& blocks = deferredBlocks_;
  std::sort(blocks.begin(), blocks.end());
  blocks.erase(std::unique(blocks.begin(), blocks.end()), blocks.end());
  size_t r = 0;
  while (r < blocks.size()) {
    if (meta_[blocks[r]].state != BlockState::Released) {
      ++r;
      continue;
    }
    size_t e = r + 1;
    while (e < blocks.size() && blocks[e] == blocks[e - 1] + 1 && meta_[blocks[e]].state == BlockState::Released) ++e;
    for (size_t k = 0; k < columns_.size(); ++k) releaseFreePages(k, blocks[r], blocks[e - 1]);
    r = e;
  }
  blocks.clear();
}

void PoolIndexSpace::releaseFreePages(size_t k, uint32_t firstBlock, uint32_t lastBlock) {
  // Every page of the blocks' range in column k that only released (or never touched) blocks
  // share, given back in maximal runs.
  const size_t page = VirtualReservation::pageSize();
  const size_t blockBytes = size_t(slotsPerBlock_) * strides_[k];
  const size_t start = size_t(firstBlock) * blockBytes, end = (size_t(lastBlock) + 1) * blockBytes;
  size_t runStart = 0, runEnd = 0;
  for (size_t p = start / page; p * page < end; ++p) {
    const uint32_t first = uint32_t(p * page / blockBytes);
    const uint32_t last = uint32_t(std::min<size_t>((p + 1) * page - 1, size_t(numBlocks_) * blockBytes - 1) / blockBytes);
    bool free = true;
    for (uint32_t o = first; o <= last && free; ++o) free = blockReleasedOrUntouched(o);
    if (!free) continue;
    if (runEnd != p) {
      if (runEnd > runStart) reservation_.releasePages(columnOffsets_[k] / page + runStart, columnOffsets_[k] / page + runEnd);
      runStart = p;
    }
    runEnd = p + 1;
  }
  if (runEnd > runStart) reservation_.releasePages(columnOffsets_[k] / page + runStart, columnOffsets_[k] / page + runEnd);
}

size_t PoolIndexSpace::residentBytes() const {
  // Metadata and bitmap in one range, then each column up to the high-water block (pages
  // beyond it were never touched).
  size_t total = reservation_.residentBytes(0, columnOffsets_[0]);
  for (size_t k = 0; k < columns_.size(); ++k)
    total += reservation_.residentBytes(columnOffsets_[k], size_t(highWaterSlots()) * strides_[k]);
  return total;
}

}  // namespace bw
