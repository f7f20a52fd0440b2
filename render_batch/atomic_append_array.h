#pragma once
/// Fixed-capacity array that many threads append to with one fetch_add each.
///
///   AtomicAppendArray<PrimitiveUpdate> batch(maxPrimitives);   // sized once, from the known maximum
///   batch.tryAppend(update);            // any thread, lock-free; false when full
///   if (batch.overflowed()) report(batch.overflowMessage("primitive updates"));
///
/// A slot is reserved by one fetch_add on the shared counter; the element is then written
/// into that slot by the reserving thread alone. Past capacity, tryAppend writes nothing and
/// returns false: the counter keeps counting (64-bit, it cannot wrap) so the owner sees how
/// many appends were attempted and reports the overflow; there is never a write out of bounds.
/// Reading: size() and the elements are valid for a thread that synchronised with every
/// appender (e.g. after the parallelFor that appended joined). clear() only while no one appends.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

namespace bw {

/// Lock-free, fixed-capacity, append-only array (see file comment).
template <typename T>
class AtomicAppendArray {
  static_assert(std::is_copy_assignable_v<T> && std::is_trivially_destructible_v<T>,
                "slots are plain values overwritten by copy assignment");

 public:
  /// Allocates all capacity slots up front; appends never allocate.
  explicit AtomicAppendArray(uint32_t capacity) : slots_(capacity) {}
  AtomicAppendArray(const AtomicAppendArray&) = delete;
  AtomicAppendArray& operator=(const AtomicAppendArray&) = delete;

  /// Appends a copy of item if room is left; returns false (and writes nothing) when full.
  bool tryAppend(const T& item) noexcept {
    // note: relaxed is enough: the slot index is unique per caller, and the element reaches
    // readers through the synchronisation that ends the append phase (join, queue hand-off).
    const uint64_t index = count_.value.fetch_add(1, std::memory_order_relaxed);
    if (index >= slots_.size()) return false;
    slots_[index] = item;
    return true;
  }

  /// Appends count items with one fetch_add (a block reserves its slots at once, so 16 threads
  /// appending blocks of 64 touch the shared counter 64 times less often); false when the block
  /// did not fit, in which case only the items that fit are written and the overflow is counted.
  bool tryAppend(const T* items, uint32_t count) noexcept {
    if (count == 0) return true;
    const uint64_t first = count_.value.fetch_add(count, std::memory_order_relaxed);
    const uint64_t cap = slots_.size();
    const uint64_t fit = first >= cap ? 0 : std::min<uint64_t>(count, cap - first);
    for (uint64_t i = 0; i < fit; ++i) slots_[first + i] = items[i];
    return fit == count;
  }

  /// Number of stored elements (at most capacity).
  uint32_t size() const noexcept {
    const uint64_t n = count_.value.load(std::memory_order_relaxed);
    return n < slots_.size() ? static_cast<uint32_t>(n) : capacity();
  }
  /// Number of appends attempted since the last clear (exceeds capacity after an overflow).
  uint64_t attempted() const noexcept { return count_.value.load(std::memory_order_relaxed); }
  /// True if an append was refused since the last clear.
  bool overflowed() const noexcept { return attempted() > slots_.size(); }
  /// Fixed capacity.
  uint32_t capacity() const noexcept { return static_cast<uint32_t>(slots_.size()); }
  /// "<what>: N appended, capacity C" for an error report.
  std::string overflowMessage(const char* what) const {
    return std::string(what) + ": " + std::to_string(attempted()) + " appended, capacity " +
           std::to_string(capacity());
  }
  /// Raises the capacity to at least n (allocates; only while no one appends or reads).
  void growCapacity(uint32_t n) {
    if (n > slots_.size()) slots_.resize(n);
  }
  /// Empties the array (slots keep their memory); only while no one appends.
  void clear() noexcept { count_.value.store(0, std::memory_order_relaxed); }

  /// Element i < size().
  const T& operator[](uint32_t i) const noexcept { return slots_[i]; }
  /// Pointer to the first element (size() contiguous elements).
  const T* data() const noexcept { return slots_.data(); }

 private:
  /// The one contended atomic, alone on its cache line so appends do not false-share with
  /// the slot storage pointer or with neighbouring objects.
  struct alignas(64) PaddedCounter {
    std::atomic<uint64_t> value{0};
  };
  static_assert(sizeof(PaddedCounter) == 64);

  PaddedCounter count_;   // 64  written by every append
  std::vector<T> slots_;  // 24  read-only while appending; on the next line, so reads never miss on the counter
};

}  // namespace bw
