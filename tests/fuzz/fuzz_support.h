#pragma once
// What every fuzz target shares: FuzzInput turns the fuzzer's bytes into choices (each read
// past the end gives 0, so every byte string is a valid program), and FUZZ_CHECK reports a
// broken property the way libFuzzer records a crash (message, then abort).
//
// A target defines LLVMFuzzerTestOneInput and may throw only the errors its API documents for
// bad input (it catches those); anything else escaping is a finding: std::terminate aborts.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <span>

#define FUZZ_CHECK(cond, ...)                                              \
  do {                                                                     \
    if (!(cond)) {                                                         \
      std::fprintf(stderr, "FUZZ_CHECK failed at %s:%d: %s\n  ", __FILE__, \
                   __LINE__, #cond);                                       \
      std::fprintf(stderr, __VA_ARGS__);                                   \
      std::fprintf(stderr, "\n");                                          \
      std::abort();                                                        \
    }                                                                      \
  } while (0)

namespace bw::fuzz {

class FuzzInput {
 public:
  FuzzInput(const uint8_t* data, size_t size) : data_(data), size_(size) {}

  bool done() const { return at_ >= size_; }
  size_t remaining() const { return done() ? 0 : size_ - at_; }

  uint8_t byte() { return at_ < size_ ? data_[at_++] : 0; }
  uint16_t u16() { return uint16_t(byte() | (uint16_t(byte()) << 8)); }
  uint32_t u32() { return uint32_t(u16()) | (uint32_t(u16()) << 16); }
  /// A value in [0, n) (n > 0; n <= 65536 keeps it uniform enough for choosing).
  uint32_t below(uint32_t n) { return n <= 256 ? byte() % n : u16() % n; }
  bool flag() { return byte() & 1; }
  /// One of the given values.
  template <class T>
  T pick(std::span<const T> values) { return values[below(uint32_t(values.size()))]; }
  /// A float from the next four bytes as they are: NaN, infinities and denormals included.
  float rawFloat() {
    const uint32_t bits = u32();
    float f;
    std::memcpy(&f, &bits, sizeof f);
    return f;
  }
  /// A value in [lo, hi] on a 1/256 lattice (fuzzers mutate such bytes far better than floats).
  float lattice(float lo, float hi) { return lo + (hi - lo) * float(byte()) / 255.f; }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t at_ = 0;
};

}  // namespace bw::fuzz
