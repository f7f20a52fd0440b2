// IslandLanes' row kernels in SSE2 (every x86-64): a row of eight lanes as two registers of four,
// and the run-time choice between these and the AVX2 ones.
#include <atomic>

#include "world/island_lanes_rows.h"

#if defined(__SSE2__)
#include <emmintrin.h>

#include "world/island_lanes_kernel.h"

namespace bw::lanes {
namespace {

struct SseOps {
  using V = __m128;
  static constexpr int N = 4;
  static V load(const float* p) { return _mm_load_ps(p); }
  static void store(float* p, V x) { _mm_store_ps(p, x); }
  static V add(V a, V b) { return _mm_add_ps(a, b); }
  static V sub(V a, V b) { return _mm_sub_ps(a, b); }
  static V mul(V a, V b) { return _mm_mul_ps(a, b); }
  static V div(V a, V b) { return _mm_div_ps(a, b); }
  static V sqrt(V a) { return _mm_sqrt_ps(a); }
  static V bitAnd(V a, V b) { return _mm_and_ps(a, b); }
  static V bitOr(V a, V b) { return _mm_or_ps(a, b); }
  static V andNot(V m, V b) { return _mm_andnot_ps(m, b); }  // ~m & b
  static V less(V a, V b) { return _mm_cmplt_ps(a, b); }
  static V greater(V a, V b) { return _mm_cmpgt_ps(a, b); }
  static V zero() { return _mm_setzero_ps(); }
  static V set1(float x) { return _mm_set1_ps(x); }
  static uint32_t lanes(V m) { return uint32_t(_mm_movemask_ps(m)); }
  static V laneMask(uint32_t bits) {
    return _mm_castsi128_ps(_mm_set_epi32(-int((bits >> 3) & 1), -int((bits >> 2) & 1), -int((bits >> 1) & 1), -int(bits & 1)));
  }
  // All ones where the word is not zero (the dynamic flag, read as its bits).
  static V nonZeroWord(V w) {
    const __m128i zero = _mm_cmpeq_epi32(_mm_castps_si128(w), _mm_setzero_si128());
    return _mm_castsi128_ps(_mm_xor_si128(zero, _mm_set1_epi32(-1)));
  }
  // Four floats at in[l] + at of each lane, transposed: x holds lane l's first, and so on.
  static void gather(const float* const* in, int at, V& x, V& y, V& z, V& w) {
    __m128 r0 = _mm_loadu_ps(in[0] + at), r1 = _mm_loadu_ps(in[1] + at), r2 = _mm_loadu_ps(in[2] + at),
           r3 = _mm_loadu_ps(in[3] + at);
    _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
    x = r0, y = r1, z = r2, w = r3;
  }
  // The inverse, stored to the lanes whose bit is set.
  static void scatter(float* const* out, int at, uint32_t bits, V x, V y, V z, V w) {
    _MM_TRANSPOSE4_PS(x, y, z, w);
    const V blocks[4] = {x, y, z, w};
    for (int l = 0; l < 4; ++l)
      if ((bits >> l) & 1) _mm_storeu_ps(out[l] + at, blocks[l]);
  }
};

std::atomic<bool> preferSse2{false};

}  // namespace

void warmStartSse2(const Row* rows, uint32_t first, uint32_t last, float* bodies) {
  warmStartRows<SseOps>(rows, first, last, bodies);
}
void passSse2(Row* rows, RollRow* roll, uint32_t first, uint32_t last, bool reversed, float* bodies) {
  passRows<SseOps>(rows, roll, first, last, reversed, bodies);
}

bool avx2() {
#if defined(BW_AVX2_KERNELS)
  static const bool cpu = __builtin_cpu_supports("avx2");
  return cpu && !preferSse2.load(std::memory_order_relaxed);
#else
  return false;
#endif
}
void preferSse2ForTests(bool on) { preferSse2.store(on, std::memory_order_relaxed); }

}  // namespace bw::lanes
#else
namespace bw::lanes {
bool avx2() { return false; }
void preferSse2ForTests(bool) {}
}  // namespace bw::lanes
#endif
