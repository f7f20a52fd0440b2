#include "collision/core/virtual_reservation.h"

#include <cerrno>
#include <cstring>
#include <string>
#include <sys/mman.h>
#include <unistd.h>
#include <utility>
#include <vector>

#include "collision/core/argument_checks.h"

namespace bw {

size_t VirtualReservation::pageSize() {
  static const size_t page = size_t(sysconf(_SC_PAGESIZE));
  return page;
}

VirtualReservation::VirtualReservation(size_t bytes, const char* owner) {
  const size_t page = pageSize();
  size_ = (bytes + page - 1) / page * page;
  if (size_ == 0) return;
  void* p = mmap(nullptr, size_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
  if (p == MAP_FAILED) {
    const int err = errno;
    size_ = 0;
    throw CapacityExceeded(std::string(owner) + ": cannot reserve " + std::to_string(bytes) +
                           " bytes of virtual memory (" + std::strerror(err) + ")");
  }
  base_ = static_cast<std::byte*>(p);
}

VirtualReservation::~VirtualReservation() {
  if (base_) munmap(base_, size_);
}

VirtualReservation::VirtualReservation(VirtualReservation&& o) noexcept
    : base_(std::exchange(o.base_, nullptr)), size_(std::exchange(o.size_, 0)) {}

VirtualReservation& VirtualReservation::operator=(VirtualReservation&& o) noexcept {
  if (this != &o) {
    if (base_) munmap(base_, size_);
    base_ = std::exchange(o.base_, nullptr);
    size_ = std::exchange(o.size_, 0);
  }
  return *this;
}

void VirtualReservation::releaseInside(size_t offset, size_t bytes) {
  const size_t page = pageSize();
  const size_t first = (offset + page - 1) / page;
  const size_t last = (offset + bytes) / page;
  if (first < last) releasePages(first, last);
}

void VirtualReservation::releasePages(size_t firstPage, size_t lastPage) {
  const size_t page = pageSize();
  // note: MADV_DONTNEED on a private anonymous mapping drops the pages immediately; the next
  // touch maps a fresh zero page, so callers must not rely on the old contents.
  madvise(base_ + firstPage * page, (lastPage - firstPage) * page, MADV_DONTNEED);
}

size_t VirtualReservation::residentBytes(size_t offset, size_t bytes) const {
  if (bytes == 0 || !base_) return 0;
  const size_t page = pageSize();
  const size_t first = offset / page;
  const size_t last = (offset + bytes + page - 1) / page;
  std::vector<unsigned char> vec(last - first);
  if (mincore(base_ + first * page, (last - first) * page, vec.data()) != 0) return 0;
  size_t resident = 0;
  for (unsigned char v : vec) resident += (v & 1u) ? page : 0;
  return resident;
}

}  // namespace bw
