#pragma once
/// The .brs file format, below the brick records: the section reader with the .brs string
/// encoding (Latin-1 or UTF-16), zlib section reading, header 1 and header 2, and the bit stream
/// the brick records and the component data are packed in (the components section itself is
/// decoded in brs_components.h). It is kept apart from the asset mapping (brs_asset_mapping.h)
/// and the build step (brs_reader.cpp, which turns records into Bricks) so that each can be read
/// on its own; the layout itself is documented in brs_reader.h. Internal to the reader: nothing
/// here is part of the public API.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "collision/content/byte_reader.h"

namespace bw::brs {

inline constexpr int kMinVersion = 8;
inline constexpr int kMaxVersion = 10;
// Sections are small in practice (Lighthouse_Island's largest is 2 MB); a larger claim is a
// corrupt header, and refusing it keeps a bad file from allocating gigabytes.
inline constexpr int64_t kMaxSectionBytes = int64_t(1) << 30;

// A section's reader with the .brs string encoding.
class BrsReader : public ByteReader {
 public:
  using ByteReader::ByteReader;
  // Latin-1 (positive length, NUL-terminated) or UTF-16 (negative length, low bytes kept).
  std::string string(const char* what);
};

// Reads one section header and returns its uncompressed bytes.
std::vector<uint8_t> readSection(ByteReader& file, const char* name, const std::string& fileName);

// A bit stream (the brick records, each component's data): least significant bit of each byte
// first, every read bounds-checked. `where` starts every problem after the file name
// ("bricks section", "components: BCD_PointLight"); setBrick() adds "brick i: " for the records.
class BitReader {
 public:
  BitReader(const uint8_t* data, size_t size, const std::string& file, std::string where)
      : bytes_(data), file_(file), where_(std::move(where)) {
    bitCount_ = uint64_t(size) * 8;
  }
  void setBrick(uint32_t i) { brick_ = int64_t(i); }
  uint64_t bitPosition() const { return pos_; }
  uint64_t bitsLeft() const { return bitCount_ - pos_; }
  bool bit() {
    if (pos_ >= bitCount_) truncated();
    const bool b = (bytes_[size_t(pos_ >> 3)] >> (pos_ & 7)) & 1;
    ++pos_;
    return b;
  }
  uint64_t bits(int n) {
    if (pos_ + uint64_t(n) > bitCount_) truncated();
    uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= uint64_t(bit()) << i;
    return v;
  }
  void align() { pos_ = (pos_ + 7) & ~uint64_t(7); }
  // Unreal's SerializeInt: only as many bits as values below max need.
  uint32_t uintBelow(uint64_t max) {
    uint64_t value = 0;
    for (uint64_t mask = 1; value + mask < max; mask <<= 1)
      if (bit()) value |= mask;
    return uint32_t(value);
  }
  // Unreal's SerializeIntPacked: 7 bits per group, the group's first bit says "more follows".
  uint64_t packed() {
    uint64_t value = 0;
    for (int group = 0; group < 5; ++group) {
      const bool more = bit();
      value |= bits(7) << (7 * group);
      if (!more) break;
    }
    return value;
  }
  int64_t signedPacked() {
    const uint64_t v = packed();
    const int64_t magnitude = int64_t(v >> 1);
    return (v & 1) ? magnitude : -magnitude;
  }
  // 32 bits as a little-endian i32 / IEEE float (the stream's bytes need not be aligned).
  int32_t i32() { return int32_t(uint32_t(bits(32))); }
  float f32() {
    const uint32_t u = uint32_t(bits(32));
    float f;
    std::memcpy(&f, &u, 4);
    return f;
  }
  // A .brs string inside the stream, not byte aligned: i32 n, then n Latin-1 bytes (n >= 0) or
  // -n UTF-16 code units (low bytes kept); trailing NULs dropped.
  std::string string(const char* what);
  [[noreturn]] void failHere(const std::string& problem) const {
    failFile(file_, where_, brick_ >= 0 ? "brick " + std::to_string(brick_) + ": " + problem : problem);
  }

 private:
  [[noreturn]] void truncated() const {
    failHere("truncated record (bit " + std::to_string(pos_) + " of " + std::to_string(bitCount_) + ")");
  }
  const uint8_t* bytes_;
  const std::string& file_;
  std::string where_;
  uint64_t pos_ = 0, bitCount_ = 0;
  int64_t brick_ = -1;
};

struct Header1 {
  std::string map, author, description;
  uint32_t brickCount = 0;
};

Header1 readHeader1(const std::vector<uint8_t>& bytes, const std::string& file);

struct Header2 {
  std::vector<std::string> assets;
  uint32_t colors = 0, materials = 0, owners = 0, physicalMaterials = 0;
};

Header2 readHeader2(const std::vector<uint8_t>& bytes, int version, const std::string& file);

}  // namespace bw::brs
