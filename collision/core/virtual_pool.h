#pragma once
/// Virtual memory pools: stable 32-bit handles, elements that never move, no hitch on growth.
///
///   bw::VirtualPool<Brick> bricks(50'000'000, "bricks");   // reserves, commits nothing
///   uint32_t id = bricks.allocate(Brick{...});             // touches one page at most
///   bricks[id].material = 3;                                // &bricks[id] is stable forever
///   bricks.free(id);                                        // empty pages go back to the OS
///
/// ParallelVirtualPool<A, B, ...> keeps several element types under one index space (SoA):
/// get<0>(i) and get<1>(i) belong to the same element. See pool_index_space.h for the memory
/// policy. Thread safety: none; one writer at a time, readers only while no one writes.
#include <cstdint>
#include <new>
#include <span>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>

#include "collision/core/assert.h"
#include "collision/core/ids.h"
#include "collision/core/pool_index_space.h"

namespace bw {

template <class... Ts>
class ParallelVirtualPool {
  static_assert(sizeof...(Ts) >= 1);
  using First = std::tuple_element_t<0, std::tuple<Ts...>>;
  static_assert(sizeof(First) >= sizeof(uint32_t), "the first column holds the free list");
  static constexpr bool kTrivial = (std::is_trivially_destructible_v<Ts> && ...);

 public:
  template <size_t K>
  using Column = std::tuple_element_t<K, std::tuple<Ts...>>;

  /// Reserves address space for maxElements of each type. Throws InvalidInput / CapacityExceeded.
  explicit ParallelVirtualPool(uint32_t maxElements, std::string name = "VirtualPool")
      : space_(maxElements, {sizeof(Ts)...}, std::move(name)) {}
  ~ParallelVirtualPool() {
    if constexpr (!kTrivial) space_.forEachLive([this](uint32_t i) { destroyAll(i, std::index_sequence_for<Ts...>{}); });
  }
  ParallelVirtualPool(const ParallelVirtualPool&) = delete;
  ParallelVirtualPool& operator=(const ParallelVirtualPool&) = delete;

  /// A new element with every column value-initialised. Throws CapacityExceeded when full.
  uint32_t allocate() {
    const uint32_t i = space_.acquire();
    constructAll(i, std::index_sequence_for<Ts...>{});
    return i;
  }
  /// The handles n allocate() calls would give, in their order (PoolIndexSpace::acquireMany);
  /// CapacityExceeded, nothing allocated, if n do not fit.
  void allocateMany(uint32_t n, uint32_t* out) {
    space_.acquireMany(n, out);
    for (uint32_t k = 0; k < n; ++k) constructAll(out[k], std::index_sequence_for<Ts...>{});
  }
  /// allocateMany leaving the columns unconstructed: for implicit-lifetime columns (aggregates,
  /// trivially destructible) that the caller writes whole before reading any. A fresh slot's
  /// pages are then first touched by the thread that writes it, not here (a 50k-brick part's
  /// bricks: 400 pages, 0.7 ms of serial faults on a VM).
  void allocateManyForOverwrite(uint32_t n, uint32_t* out) {
    static_assert(kTrivial, "columns left unconstructed must not need destroying");
    space_.acquireMany(n, out);
  }
  /// Destroys the element's columns and frees its slot. Throws InvalidInput if not live.
  void free(uint32_t i) {
    space_.requireLive(i, "free");
    if constexpr (!kTrivial) destroyAll(i, std::index_sequence_for<Ts...>{});
    space_.release(i);
  }

  /// free() of each handle in turn (the same final state), for thousands at once: checked
  /// first (InvalidInput naming a dead or repeated handle, nothing freed), slots asked for
  /// ahead, and emptied pages given back in runs (PoolIndexSpace::releaseMany).
  void freeMany(std::span<const uint32_t> handles) {
    space_.requireLiveDistinct(handles, "freeMany");
    if constexpr (!kTrivial)
      for (uint32_t i : handles) destroyAll(i, std::index_sequence_for<Ts...>{});
    space_.releaseMany(handles);
  }
  /// freeMany of handles the caller has already shown live and distinct (a bulk removal that
  /// checked its list before touching anything): the same, without checking them again.
  void freeManyChecked(std::span<const uint32_t> handles) {
    if constexpr (!kTrivial)
      for (uint32_t i : handles) destroyAll(i, std::index_sequence_for<Ts...>{});
    space_.releaseMany(handles);
  }
  /// While alive, pages emptied by free() are given back in runs when it ends (a bulk edit
  /// frees hundreds of blocks: a madvise and a TLB flush each otherwise).
  using DeferPageRelease = PoolIndexSpace::DeferPageRelease;
  DeferPageRelease deferPageRelease() { return DeferPageRelease(space_); }

  template <size_t K>
  Column<K>& get(uint32_t i) {
    BW_ASSERT(i < space_.highWaterSlots());
    return *std::launder(reinterpret_cast<Column<K>*>(space_.column(K) + size_t(i) * sizeof(Column<K>)));
  }
  template <size_t K>
  const Column<K>& get(uint32_t i) const {
    BW_ASSERT(i < space_.highWaterSlots());
    return *std::launder(reinterpret_cast<const Column<K>*>(space_.column(K) + size_t(i) * sizeof(Column<K>)));
  }

  bool isLive(uint32_t i) const { return space_.isLive(i); }
  /// Asks the cache for what free(i) will write: the slot's first column (the free list's
  /// link), its live bits and its block's record. i must be live.
  void prefetchFree(uint32_t i) const {
    __builtin_prefetch(&get<0>(i), 1);
    space_.prefetchRelease(i);
  }
  uint32_t size() const { return space_.size(); }
  bool empty() const { return space_.size() == 0; }
  uint32_t capacity() const { return space_.capacity(); }
  /// One past the largest index that may be live: size arrays indexed by handle with this.
  uint32_t indexBound() const { return space_.highWaterSlots(); }
  /// f(index) for every live element, ascending.
  template <class F>
  void forEachLive(F&& f) const {
    space_.forEachLive(std::forward<F>(f));
  }
  size_t residentBytes() const { return space_.residentBytes(); }
  size_t reservedBytes() const { return space_.reservedBytes(); }
  const std::string& name() const { return space_.name(); }

 private:
  template <size_t... K>
  void constructAll(uint32_t i, std::index_sequence<K...>) {
    (::new (static_cast<void*>(space_.column(K) + size_t(i) * sizeof(Column<K>))) Column<K>(), ...);
  }
  template <size_t... K>
  void destroyAll(uint32_t i, std::index_sequence<K...>) {
    (get<K>(i).~Column<K>(), ...);
  }

  PoolIndexSpace space_;
};

/// A pool of one element type, indexed like an array.
template <class T>
class VirtualPool : public ParallelVirtualPool<T> {
 public:
  using ParallelVirtualPool<T>::ParallelVirtualPool;
  using ParallelVirtualPool<T>::allocate;

  /// A new element holding `value`.
  uint32_t allocate(const T& value) {
    const uint32_t i = ParallelVirtualPool<T>::allocate();
    (*this)[i] = value;
    return i;
  }
  T& operator[](uint32_t i) { return this->template get<0>(i); }
  const T& operator[](uint32_t i) const { return this->template get<0>(i); }
};

}  // namespace bw
