#pragma once
/// A bounds-checked little-endian reader over one buffer (a whole file, a section, a chunk),
/// shared by the content readers (.brs, .vox). Every read is checked against the bytes left; a
/// short or inconsistent buffer throws InvalidInput("<file>: <where>: <problem>") before
/// anything past the data is touched, so a reader never returns half-parsed content.
///
///   ByteReader r(bytes.data(), bytes.size(), "island.brs", "header1");
///   const int32_t n = r.i32("brick count");
///   const uint32_t mods = r.count("mods count", 4);   // each item takes at least 4 bytes
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>

#include "collision/core/argument_checks.h"

namespace bw {

/// Throws InvalidInput("<file>: <where>: <problem>").
[[noreturn]] inline void failFile(const std::string& file, const std::string& where, const std::string& problem) {
  throw InvalidInput(file + ": " + where + ": " + problem);
}

/// Throws InvalidInput naming the path when it is missing or is not a regular file (a
/// directory read as a file gave "larger than 2 GiB" or "not valid JSON"). `expected` says
/// what it should be ("a .vox model").
void requireRegularFile(const std::string& path, const std::string& expected);

class ByteReader {
 public:
  /// `container` names the buffer in count errors ("exceeds the data", "exceeds the chunk").
  ByteReader(const uint8_t* data, size_t size, const std::string& file, std::string where, const char* container = "the data")
      : data_(data), size_(size), file_(file), where_(std::move(where)), container_(container) {}

  size_t remaining() const { return size_ - pos_; }
  size_t position() const { return pos_; }
  /// The next n bytes.
  const uint8_t* take(size_t n, const char* what) {
    if (n > remaining())
      failHere(std::string("truncated: ") + what + " needs " + std::to_string(n) + " bytes at offset " + std::to_string(pos_) +
               ", only " + std::to_string(remaining()) + " left");
    const uint8_t* p = data_ + pos_;
    pos_ += n;
    return p;
  }
  uint8_t u8(const char* what) { return *take(1, what); }
  uint16_t u16(const char* what) {
    const uint8_t* p = take(2, what);
    return uint16_t(p[0] | (p[1] << 8));
  }
  int32_t i32(const char* what) {
    const uint8_t* p = take(4, what);
    return int32_t(uint32_t(p[0]) | (uint32_t(p[1]) << 8) | (uint32_t(p[2]) << 16) | (uint32_t(p[3]) << 24));
  }
  /// An i32 count of items taking at least minItemBytes each, checked against the bytes left
  /// (a corrupt count fails here instead of allocating ahead of the data).
  uint32_t count(const char* what, size_t minItemBytes) {
    const int32_t n = i32(what);
    if (n < 0) failHere(std::string(what) + " is negative (" + std::to_string(n) + ")");
    if (size_t(n) > remaining() / minItemBytes)
      failHere(std::string(what) + " " + std::to_string(n) + " exceeds " + container_ + " (" + std::to_string(remaining()) +
               " bytes left)");
    return uint32_t(n);
  }
  [[noreturn]] void failHere(const std::string& problem) const { failFile(file_, where_, problem); }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
  const std::string& file_;
  std::string where_;
  const char* container_;
};

}  // namespace bw
