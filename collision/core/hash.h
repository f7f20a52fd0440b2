#pragma once
/// The project's one hash mixer, for state and structure hashes (World::stateHash,
/// OctoBvh::structureHash, RenderScene::stateHash) and counter-based random streams.
/// Fully specified, so a hash is the same on every platform and standard library.
#include <algorithm>
#include <cstdint>
#include <cstring>

namespace bw {

inline constexpr uint64_t kGoldenGamma = 0x9E3779B97F4A7C15ull;  ///< 2^64 / golden ratio

/// splitmix64: a well-spread 64-bit value from a counter (the output of step x of the stream).
inline uint64_t splitmix64(uint64_t x) {
  x += kGoldenGamma;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

/// Folds `v` into the running hash `h`; order-sensitive (h(a, b) != h(b, a)).
inline uint64_t hashCombine(uint64_t h, uint64_t v) {
  h ^= v + kGoldenGamma + (h << 6) + (h >> 2);
  h *= 0xBF58476D1CE4E5B9ull;
  return h ^ (h >> 31);
}

/// The bit pattern of a float, double or integer (low bytes of a 64-bit word): hashes compare
/// values bit for bit, so -0.0 and 0.0 differ and a NaN hashes as its payload.
template <class T>
uint64_t bitsOf(const T& v) {
  static_assert(sizeof(T) <= sizeof(uint64_t));
  uint64_t out = 0;
  std::memcpy(&out, &v, sizeof(T));
  return out;
}

/// Folds `bytes` bytes at `data` into `h`, eight at a time (the tail zero-padded).
inline uint64_t hashBytes(uint64_t h, const void* data, size_t bytes) {
  const unsigned char* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < bytes; i += 8) {
    uint64_t word = 0;
    std::memcpy(&word, p + i, std::min<size_t>(8, bytes - i));
    h = hashCombine(h, word);
  }
  return h;
}

}  // namespace bw
