#pragma once
/// RAII wrapper of one large virtual address range (mmap, MAP_NORESERVE). Pages become
/// resident when first touched and are given back with release() (madvise MADV_DONTNEED),
/// after which they read as zero when touched again.
#include <cstddef>
#include <cstdint>

namespace bw {

class VirtualReservation {
 public:
  VirtualReservation() = default;
  /// Reserves `bytes` (rounded up to whole pages). Throws CapacityExceeded if the OS refuses.
  explicit VirtualReservation(size_t bytes, const char* owner);
  ~VirtualReservation();
  VirtualReservation(VirtualReservation&& o) noexcept;
  VirtualReservation& operator=(VirtualReservation&& o) noexcept;
  VirtualReservation(const VirtualReservation&) = delete;
  VirtualReservation& operator=(const VirtualReservation&) = delete;

  std::byte* data() const { return base_; }
  size_t size() const { return size_; }

  /// Gives back the whole pages inside [offset, offset + bytes): the range is widened to
  /// nothing, only pages entirely inside it are released.
  void releaseInside(size_t offset, size_t bytes);
  /// Gives back pages [firstPage, lastPage).
  void releasePages(size_t firstPage, size_t lastPage);
  /// Resident bytes of the pages overlapping [offset, offset + bytes), by mincore().
  size_t residentBytes(size_t offset, size_t bytes) const;

  static size_t pageSize();

 private:
  std::byte* base_ = nullptr;
  size_t size_ = 0;
};

}  // namespace bw
