#include "collision/core/pool_index_space.h"

#include <algorithm>

#include "collision/core/argument_checks.h"

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
  while (size_t(slotsPerBlock_) * 2 * largest <= page && slotsPerBlock_ < (1u << 16)) slotsPerBlock_ *= 2;

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

void PoolIndexSpace::requireLive(uint32_t index, const char* operation) const {
  if (!isLive(index))
    throw InvalidInput(name_ + ": " + operation + " of index " + std::to_string(index) +
                       ", which is not a live element");
}

void PoolIndexSpace::release(uint32_t index) {
  requireLive(index, "release");
  const uint32_t b = index / slotsPerBlock_;
  BlockMeta& m = meta_[b];
  liveBits_[index >> 6] &= ~(uint64_t(1) << (index & 63));
  --live_;
  if (m.live-- == slotsPerBlock_) pushAvailable(b);
  writeFreeLink(index, m.freeHead);
  m.freeHead = index - b * slotsPerBlock_;
  if (m.live == 0) {
    if (spare_ != kInvalidIndex) releaseBlock(spare_);
    spare_ = b;
  }
}

void PoolIndexSpace::releaseBlock(uint32_t b) {
  removeAvailable(b);
  BlockMeta& m = meta_[b];
  m.state = BlockState::Released;
  m.next = releasedHead_;
  releasedHead_ = b;

  // Give back every page of every column that only released (or never touched) blocks share.
  const size_t page = VirtualReservation::pageSize();
  for (size_t k = 0; k < columns_.size(); ++k) {
    const size_t blockBytes = size_t(slotsPerBlock_) * strides_[k];
    const size_t start = size_t(b) * blockBytes, end = start + blockBytes;
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
