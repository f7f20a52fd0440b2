#pragma once
/// Morton (Z-order) codes: the bits of three lattice coordinates interleaved, x highest, so
/// items sorted by code lie near each other in space and every prefix of the code is an octree
/// cell. Used by the broadphase's linear BVH build and by a coloured island's contact order.
#include <cstdint>

namespace bw {

/// Spreads the low 21 bits of v so that two zero bits follow each (bit i moves to bit 3i).
inline uint64_t spreadBits3(uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffull;
  v = (v | v << 16) & 0x1f0000ff0000ffull;
  v = (v | v << 8) & 0x100f00f00f00f00full;
  v = (v | v << 4) & 0x10c30c30c30c30c3ull;
  v = (v | v << 2) & 0x1249249249249249ull;
  return v;
}

/// The Morton code of lattice point (x, y, z), each below 2^21: bit i of x goes to bit 3i + 2,
/// of y to 3i + 1, of z to 3i.
inline uint64_t mortonCode(uint64_t x, uint64_t y, uint64_t z) {
  return spreadBits3(x) << 2 | spreadBits3(y) << 1 | spreadBits3(z);
}

}  // namespace bw
