#pragma once
/// A std::vector for per-step buffers that are sized and then written whole by parallel jobs:
/// growing it neither zero-fills the new elements nor copies the old ones.
///
///   bw::OverwriteVector<SolverContact> contacts;
///   bw::resizeForOverwrite(contacts, total);          // no stores, no copy
///   jobs.parallelFor(0, total, grain, [&](auto b, auto e) { /* writes every field of [b, e) */ });
///
/// Why: std::vector::resize value-initialises what it adds, on the calling thread, between two
/// parallel stages. The solver's contacts are 320 bytes each: a frame with 1,000 more contacts
/// than the last wrote 320 KB there, and one that outgrew the capacity also copied every old
/// contact and took the new pages' first-touch faults (crates_on_grid, traced on one thread:
/// 13 us a frame on average, up to 750 us, all of it serial time in the work/span bound).
/// Left to the jobs, the pages are first touched by the threads that fill them.
///
/// Only for types whose objects may begin life without a constructor call (aggregates and
/// other implicit-lifetime types, trivially destructible): every element the caller reads must
/// have been written first. Constructors with arguments (push_back, emplace_back) run as usual.
#include <algorithm>
#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace bw {

/// std::allocator whose argument-less construct() leaves the element as allocated.
template <class T>
struct NoInitAllocator : std::allocator<T> {
  static_assert(std::is_trivially_destructible_v<T>, "elements left unconstructed must not need destroying");
  NoInitAllocator() noexcept = default;
  template <class U>
  NoInitAllocator(const NoInitAllocator<U>&) noexcept {}
  template <class U>
  struct rebind {
    using other = NoInitAllocator<U>;
  };
  template <class U>
  void construct(U*) noexcept {}
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

template <class T>
using OverwriteVector = std::vector<T, NoInitAllocator<T>>;

/// v holds n elements of unspecified value (its old contents are not kept when it has to grow
/// past its capacity: the caller overwrites all of [0, n)).
template <class T>
void resizeForOverwrite(OverwriteVector<T>& v, size_t n) {
  if (n > v.capacity()) {
    v.clear();
    v.reserve(std::max(n, v.capacity() * 2));
  }
  v.resize(n);
}

}  // namespace bw
