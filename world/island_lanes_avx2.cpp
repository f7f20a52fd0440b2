// IslandLanes' row kernels in AVX2: a row of eight lanes in one register. This file alone is
// compiled with -mavx2 (world/CMakeLists.txt); lanes::avx2() runs it only on a CPU that has AVX2.
// It includes nothing whose inline functions other files also use (island_lanes_rows.h).
#include "world/island_lanes_rows.h"

#if defined(__AVX2__)
#include <immintrin.h>

#include "world/island_lanes_kernel.h"

namespace bw::lanes {
namespace {

struct AvxOps {
  using V = __m256;
  static constexpr int N = 8;
  static V load(const float* p) { return _mm256_load_ps(p); }
  static void store(float* p, V x) { _mm256_store_ps(p, x); }
  static V add(V a, V b) { return _mm256_add_ps(a, b); }
  static V sub(V a, V b) { return _mm256_sub_ps(a, b); }
  static V mul(V a, V b) { return _mm256_mul_ps(a, b); }
  static V div(V a, V b) { return _mm256_div_ps(a, b); }
  static V sqrt(V a) { return _mm256_sqrt_ps(a); }
  static V bitAnd(V a, V b) { return _mm256_and_ps(a, b); }
  static V bitOr(V a, V b) { return _mm256_or_ps(a, b); }
  static V andNot(V m, V b) { return _mm256_andnot_ps(m, b); }  // ~m & b
  // The predicates of SSE's cmpltps and cmpgtps (ordered: false where either is NaN).
  static V less(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_LT_OS); }
  static V greater(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_GT_OS); }
  static V zero() { return _mm256_setzero_ps(); }
  static V set1(float x) { return _mm256_set1_ps(x); }
  static uint32_t lanes(V m) { return uint32_t(_mm256_movemask_ps(m)); }
  static V laneMask(uint32_t bits) {
    const __m256i bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    const __m256i set = _mm256_and_si256(_mm256_set1_epi32(int(bits)), bit);
    return _mm256_castsi256_ps(_mm256_cmpeq_epi32(set, bit));
  }
  static V nonZeroWord(V w) {
    const __m256i zero = _mm256_cmpeq_epi32(_mm256_castps_si256(w), _mm256_setzero_si256());
    return _mm256_castsi256_ps(_mm256_xor_si256(zero, _mm256_set1_epi32(-1)));
  }
  // Four floats at in[l] + at of each of eight lanes, transposed: lanes 0-3 in the low halves,
  // 4-7 in the high ones, each half a 4 x 4 transpose as SSE's.
  static void gather(const float* const* in, int at, V& x, V& y, V& z, V& w) {
    const V r0 = _mm256_set_m128(_mm_loadu_ps(in[4] + at), _mm_loadu_ps(in[0] + at));
    const V r1 = _mm256_set_m128(_mm_loadu_ps(in[5] + at), _mm_loadu_ps(in[1] + at));
    const V r2 = _mm256_set_m128(_mm_loadu_ps(in[6] + at), _mm_loadu_ps(in[2] + at));
    const V r3 = _mm256_set_m128(_mm_loadu_ps(in[7] + at), _mm_loadu_ps(in[3] + at));
    transpose(r0, r1, r2, r3, x, y, z, w);
  }
  static void scatter(float* const* out, int at, uint32_t bits, V x, V y, V z, V w) {
    V b0, b1, b2, b3;
    transpose(x, y, z, w, b0, b1, b2, b3);
    const V blocks[4] = {b0, b1, b2, b3};
    for (int l = 0; l < 8; ++l) {
      if (!((bits >> l) & 1)) continue;
      const V block = blocks[l & 3];
      _mm_storeu_ps(out[l] + at, l < 4 ? _mm256_castps256_ps128(block) : _mm256_extractf128_ps(block, 1));
    }
  }
  // A 4 x 4 transpose in each 128-bit half (unpacks, then the halves' pairs), as _MM_TRANSPOSE4_PS.
  static void transpose(V r0, V r1, V r2, V r3, V& c0, V& c1, V& c2, V& c3) {
    const V t0 = _mm256_unpacklo_ps(r0, r1), t1 = _mm256_unpackhi_ps(r0, r1);
    const V t2 = _mm256_unpacklo_ps(r2, r3), t3 = _mm256_unpackhi_ps(r2, r3);
    c0 = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0));
    c1 = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2));
    c2 = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0));
    c3 = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2));
  }
};

}  // namespace

void warmStartAvx2(const Row* rows, uint32_t first, uint32_t last, float* bodies) {
  warmStartRows<AvxOps>(rows, first, last, bodies);
}
void passAvx2(Row* rows, RollRow* roll, uint32_t first, uint32_t last, bool reversed, float* bodies) {
  passRows<AvxOps>(rows, roll, first, last, reversed, bodies);
}

}  // namespace bw::lanes
#else
#include <cstdlib>

namespace bw::lanes {
// Not compiled for AVX2 (lanes::avx2() is then false and never calls these).
void warmStartAvx2(const Row*, uint32_t, uint32_t, float*) { std::abort(); }
void passAvx2(Row*, RollRow*, uint32_t, uint32_t, bool, float*) { std::abort(); }
}  // namespace bw::lanes
#endif
