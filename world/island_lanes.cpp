#include "world/island_lanes.h"

#include <algorithm>
#include <cstring>

#include "collision/core/assert.h"
#include "world/contact_update.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace bw {

#if defined(__SSE2__)
namespace {

// What an idle lane reads as its bodies: static and still.
const SolverBody kIdle{Vec3f::Zero(), 0.f, Vec3f::Zero(), 0u};

// Each operation below is the scalar reference's, lane by lane (see the header).
struct V3 {
  __m128 x, y, z;
};
inline __m128 load(const float (&f)[4]) { return _mm_load_ps(f); }
inline V3 load3(const float (&f)[3][4]) { return {_mm_load_ps(f[0]), _mm_load_ps(f[1]), _mm_load_ps(f[2])}; }
inline V3 add(V3 a, V3 b) { return {_mm_add_ps(a.x, b.x), _mm_add_ps(a.y, b.y), _mm_add_ps(a.z, b.z)}; }
inline V3 sub(V3 a, V3 b) { return {_mm_sub_ps(a.x, b.x), _mm_sub_ps(a.y, b.y), _mm_sub_ps(a.z, b.z)}; }
inline V3 mul(V3 a, __m128 s) { return {_mm_mul_ps(a.x, s), _mm_mul_ps(a.y, s), _mm_mul_ps(a.z, s)}; }
// m ? a : b, lane by lane (m all ones or all zeros).
inline __m128 select(__m128 m, __m128 a, __m128 b) { return _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b)); }
inline V3 select(__m128 m, V3 a, V3 b) { return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)}; }
// Eigen's cross product: (a.y b.z - a.z b.y, a.z b.x - a.x b.z, a.x b.y - a.y b.x).
inline V3 cross(V3 a, V3 b) {
  return {_mm_sub_ps(_mm_mul_ps(a.y, b.z), _mm_mul_ps(a.z, b.y)), _mm_sub_ps(_mm_mul_ps(a.z, b.x), _mm_mul_ps(a.x, b.z)),
          _mm_sub_ps(_mm_mul_ps(a.x, b.y), _mm_mul_ps(a.y, b.x))};
}
// Eigen's dot product of 3-vectors: x + (y + z).
inline __m128 dot(V3 a, V3 b) {
  return _mm_add_ps(_mm_mul_ps(a.x, b.x), _mm_add_ps(_mm_mul_ps(a.y, b.y), _mm_mul_ps(a.z, b.z)));
}
// std::max(x, 0.f): x unless x < 0, so -0 and NaN come out as they went in.
inline __m128 maxZero(__m128 x) { return _mm_andnot_ps(_mm_cmplt_ps(x, _mm_setzero_ps()), x); }
// clampToFrictionCone: (t1, t2) scaled back to length `limit` when longer.
inline void clampToCone(__m128 t1, __m128 t2, __m128 limit, __m128& out1, __m128& out2) {
  const __m128 length2 = _mm_add_ps(_mm_mul_ps(t1, t1), _mm_mul_ps(t2, t2));
  const __m128 over = _mm_cmpgt_ps(length2, _mm_mul_ps(limit, limit));
  const __m128 scale = select(over, _mm_div_ps(limit, _mm_sqrt_ps(length2)), _mm_set1_ps(1.f));
  out1 = _mm_mul_ps(t1, scale);
  out2 = _mm_mul_ps(t2, scale);
}
// All ones in the lanes whose bit is set.
inline __m128 laneMask(uint32_t bits) {
  return _mm_castsi128_ps(_mm_set_epi32(-int((bits >> 3) & 1), -int((bits >> 2) & 1), -int((bits >> 1) & 1), -int(bits & 1)));
}

// One side (a or b) of a row's four contacts: the four bodies' velocity records transposed into
// lanes, and written back to the dynamic ones. A SolverBody is two 16-byte blocks, (v, invMass)
// and (w, dynamic): the transposes carry invMass and the dynamic word through unchanged.
struct LaneBodies {
  SolverBody* at[4];  // nullptr in an idle lane
  V3 v, w;
  __m128 invMass, dynamicWord, dynamic;  // dynamic: all ones where the body is dynamic
  uint32_t dynamicBits;

  LaneBodies(const uint32_t (&index)[4], uint32_t idle, SolverBody* bodies) {
    const float* in[4];
    for (int l = 0; l < 4; ++l) {
      at[l] = index[l] == idle ? nullptr : &bodies[index[l]];
      in[l] = (at[l] ? at[l] : &kIdle)->v.data();
    }
    __m128 r0 = _mm_loadu_ps(in[0]), r1 = _mm_loadu_ps(in[1]), r2 = _mm_loadu_ps(in[2]), r3 = _mm_loadu_ps(in[3]);
    _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
    v = {r0, r1, r2};
    invMass = r3;
    __m128 s0 = _mm_loadu_ps(in[0] + 4), s1 = _mm_loadu_ps(in[1] + 4), s2 = _mm_loadu_ps(in[2] + 4), s3 = _mm_loadu_ps(in[3] + 4);
    _MM_TRANSPOSE4_PS(s0, s1, s2, s3);
    w = {s0, s1, s2};
    dynamicWord = s3;
    const __m128i still = _mm_cmpeq_epi32(_mm_castps_si128(s3), _mm_setzero_si128());
    dynamic = _mm_castsi128_ps(_mm_xor_si128(still, _mm_set1_epi32(-1)));
    dynamicBits = uint32_t(_mm_movemask_ps(dynamic));
  }
  // Impulse `lambda` along dir with angular response ang: + for side a, - for side b.
  template <bool kPlus>
  void apply(V3 dir, V3 ang, __m128 lambda) {
    const __m128 scaled = _mm_mul_ps(lambda, invMass);
    if constexpr (kPlus) {
      v = select(dynamic, add(v, mul(dir, scaled)), v);
      w = select(dynamic, add(w, mul(ang, lambda)), w);
    } else {
      v = select(dynamic, sub(v, mul(dir, scaled)), v);
      w = select(dynamic, sub(w, mul(ang, lambda)), w);
    }
  }
  void store() const {
    if (!dynamicBits) return;
    __m128 r0 = v.x, r1 = v.y, r2 = v.z, r3 = invMass;
    _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
    __m128 s0 = w.x, s1 = w.y, s2 = w.z, s3 = dynamicWord;
    _MM_TRANSPOSE4_PS(s0, s1, s2, s3);
    const __m128 first[4] = {r0, r1, r2, r3}, second[4] = {s0, s1, s2, s3};
    for (int l = 0; l < 4; ++l) {
      if (!((dynamicBits >> l) & 1)) continue;
      float* out = at[l]->v.data();
      _mm_storeu_ps(out, first[l]);
      _mm_storeu_ps(out + 4, second[l]);
    }
  }
};

// The velocity of a's contact point relative to b's: ((vA + wA x rA) - vB) - wB x rB.
inline V3 relative(const LaneBodies& a, const LaneBodies& b, V3 rA, V3 rB) {
  return sub(sub(add(a.v, cross(a.w, rA)), b.v), cross(b.w, rB));
}

}  // namespace
#endif

void IslandLanes::fillRows(std::span<const std::span<const uint32_t>> islands, std::span<const SolverContact> contacts,
                           std::span<const SolverContactExtras> extras, bool relax, uint32_t longest) {
  rows_.resize(longest);
  std::memset(static_cast<void*>(rows_.data()), 0, size_t(longest) * sizeof(Row));
  bool anyRolls = false;
  for (uint32_t r = 0; r < longest; ++r)
    for (int l = 0; l < 4; ++l) rows_[r].a[l] = rows_[r].b[l] = kIdleBody;
  for (uint32_t l = 0; l < uint32_t(islands.size()); ++l) {
    const std::span<const uint32_t> island = islands[l];
    for (uint32_t r = 0; r < uint32_t(island.size()); ++r) {
      const SolverContact& s = contacts[island[r]];
      Row& row = rows_[r];
      row.a[l] = s.a;
      row.b[l] = s.b;
      for (int k = 0; k < 3; ++k) {
        row.n[k][l] = s.normal[k];
        row.rA[k][l] = s.rA[k];
        row.rB[k][l] = s.rB[k];
        row.t1[k][l] = s.t1[k];
        row.t2[k][l] = s.t2[k];
        for (int d = 0; d < 3; ++d) {
          row.angA[d][k][l] = s.angA[d][k];
          row.angB[d][k][l] = s.angB[d][k];
        }
      }
      row.bias[l] = relax ? s.relaxBias : s.bias;
      row.friction[l] = s.friction;
      row.mass[0][l] = s.massN;
      row.mass[1][l] = s.massT1;
      row.mass[2][l] = s.massT2;
      row.lambda[0][l] = s.lambdaN;
      row.lambda[1][l] = s.lambdaT1;
      row.lambda[2][l] = s.lambdaT2;
      if (s.rolling > 0.f) {
        row.rolls |= 1u << l;
        anyRolls = true;
      }
    }
  }
  if (!anyRolls) {
    roll_.clear();
    return;
  }
  roll_.resize(longest);
  std::memset(static_cast<void*>(roll_.data()), 0, size_t(longest) * sizeof(RollRow));
  for (uint32_t l = 0; l < uint32_t(islands.size()); ++l) {
    const std::span<const uint32_t> island = islands[l];
    for (uint32_t r = 0; r < uint32_t(island.size()); ++r) {
      const SolverContact& s = contacts[island[r]];
      if (!(s.rolling > 0.f)) continue;
      const SolverContactExtras& x = extras[island[r]];
      RollRow& row = roll_[r];
      row.rolling[l] = s.rolling;
      for (int t = 0; t < 2; ++t) {
        row.massR[t][l] = x.massR[t];
        for (int k = 0; k < 3; ++k) {
          row.rollA[t][k][l] = x.rollA[t][k];
          row.rollB[t][k][l] = x.rollB[t][k];
        }
      }
      row.lambdaR[0][l] = x.lambdaR1;
      row.lambdaR[1][l] = x.lambdaR2;
    }
  }
}

#if defined(__SSE2__)
void IslandLanes::warmStartRow(const Row& row, SolverBody* bodies) const {
  LaneBodies a(row.a, kIdleBody, bodies), b(row.b, kIdleBody, bodies);
  const V3 dirs[3] = {load3(row.n), load3(row.t1), load3(row.t2)};
  for (int d = 0; d < 3; ++d) {
    const __m128 lambda = load(row.lambda[d]);
    a.apply<true>(dirs[d], load3(row.angA[d]), lambda);
    b.apply<false>(dirs[d], load3(row.angB[d]), lambda);
  }
  a.store();
  b.store();
}

// updateContact (then resistRolling where the lane's contact rolls), lane by lane.
void IslandLanes::updateRow(Row& row, RollRow* roll, SolverBody* bodies) const {
  LaneBodies a(row.a, kIdleBody, bodies), b(row.b, kIdleBody, bodies);
  const V3 n = load3(row.n), rA = load3(row.rA), rB = load3(row.rB);
  const __m128 oldN = load(row.lambda[0]);
  const __m128 lambdaN =
      maxZero(_mm_add_ps(oldN, _mm_mul_ps(load(row.mass[0]), _mm_sub_ps(load(row.bias), dot(relative(a, b, rA, rB), n)))));
  const __m128 stepN = _mm_sub_ps(lambdaN, oldN);
  a.apply<true>(n, load3(row.angA[0]), stepN);
  b.apply<false>(n, load3(row.angB[0]), stepN);
  const __m128 limit = _mm_mul_ps(load(row.friction), lambdaN);
  const V3 v = relative(a, b, rA, rB);
  const V3 t1 = load3(row.t1), t2 = load3(row.t2);
  const __m128 o1 = load(row.lambda[1]), o2 = load(row.lambda[2]);
  __m128 lambdaT1, lambdaT2;
  clampToCone(_mm_sub_ps(o1, _mm_mul_ps(load(row.mass[1]), dot(v, t1))),
              _mm_sub_ps(o2, _mm_mul_ps(load(row.mass[2]), dot(v, t2))), limit, lambdaT1, lambdaT2);
  const __m128 step1 = _mm_sub_ps(lambdaT1, o1), step2 = _mm_sub_ps(lambdaT2, o2);
  a.apply<true>(t1, load3(row.angA[1]), step1);
  b.apply<false>(t1, load3(row.angB[1]), step1);
  a.apply<true>(t2, load3(row.angA[2]), step2);
  b.apply<false>(t2, load3(row.angB[2]), step2);
  _mm_store_ps(row.lambda[0], lambdaN);
  _mm_store_ps(row.lambda[1], lambdaT1);
  _mm_store_ps(row.lambda[2], lambdaT2);
  if (row.rolls) {
    // resistRolling on the bodies as the update left them; lanes that do not roll keep theirs.
    const __m128 rolls = laneMask(row.rolls);
    const V3 w = sub(a.w, b.w);
    const __m128 r1 = load(roll->lambdaR[0]), r2 = load(roll->lambdaR[1]);
    __m128 lambdaR1, lambdaR2;
    clampToCone(_mm_sub_ps(r1, _mm_mul_ps(load(roll->massR[0]), dot(w, t1))),
                _mm_sub_ps(r2, _mm_mul_ps(load(roll->massR[1]), dot(w, t2))), _mm_mul_ps(load(roll->rolling), lambdaN),
                lambdaR1, lambdaR2);
    const __m128 d1 = _mm_sub_ps(lambdaR1, r1), d2 = _mm_sub_ps(lambdaR2, r2);
    const V3 turnA = add(mul(load3(roll->rollA[0]), d1), mul(load3(roll->rollA[1]), d2));
    const V3 turnB = add(mul(load3(roll->rollB[0]), d1), mul(load3(roll->rollB[1]), d2));
    a.w = select(_mm_and_ps(rolls, a.dynamic), add(a.w, turnA), a.w);
    b.w = select(_mm_and_ps(rolls, b.dynamic), sub(b.w, turnB), b.w);
    _mm_store_ps(roll->lambdaR[0], select(rolls, lambdaR1, r1));
    _mm_store_ps(roll->lambdaR[1], select(rolls, lambdaR2, r2));
  }
  a.store();
  b.store();
}
#endif

void IslandLanes::solve(std::span<const std::span<const uint32_t>> islands, std::span<SolverContact> contacts,
                        std::span<SolverContactExtras> extras, std::span<SolverBody> bodies, bool warmStart, bool relax,
                        int iterations) {
  BW_ASSERT(islands.size() <= kLanes);
#if defined(__SSE2__)
  uint32_t longest = 0;
  for (const std::span<const uint32_t>& island : islands) longest = std::max(longest, uint32_t(island.size()));
  if (longest == 0) return;
  fillRows(islands, contacts, extras, relax, longest);
  SolverBody* const body = bodies.data();
  const bool rolls = !roll_.empty();
  if (warmStart)
    for (uint32_t r = 0; r < longest; ++r) warmStartRow(rows_[r], body);
  for (int it = 0; it < iterations; ++it) {
    // Reversed passes run the rows from the longest island's end (see the header).
    for (uint32_t j = 0; j < longest; ++j) {
      const uint32_t r = (it & 1) ? longest - 1 - j : j;
      updateRow(rows_[r], rolls ? &roll_[r] : nullptr, body);
    }
  }
  for (uint32_t l = 0; l < uint32_t(islands.size()); ++l) {
    const std::span<const uint32_t> island = islands[l];
    for (uint32_t r = 0; r < uint32_t(island.size()); ++r) {
      SolverContact& s = contacts[island[r]];
      s.lambdaN = rows_[r].lambda[0][l];
      s.lambdaT1 = rows_[r].lambda[1][l];
      s.lambdaT2 = rows_[r].lambda[2][l];
      if (rolls && ((rows_[r].rolls >> l) & 1)) {
        extras[island[r]].lambdaR1 = roll_[r].lambdaR[0][l];
        extras[island[r]].lambdaR2 = roll_[r].lambdaR[1][l];
      }
    }
  }
#else
  // One island after another, as ContactSolver solves an island alone.
  for (const std::span<const uint32_t>& island : islands) {
    const uint32_t n = uint32_t(island.size());
    if (warmStart)
      for (uint32_t k : island) warmStartContact(contacts[k], bodies[contacts[k].a], bodies[contacts[k].b]);
    for (int it = 0; it < iterations; ++it)
      for (uint32_t j = 0; j < n; ++j) {
        SolverContact& s = contacts[island[(it & 1) ? n - 1 - j : j]];
        updateContact(s, relax, bodies[s.a], bodies[s.b]);
        if (s.rolling > 0.f) resistRolling(s, extras[island[(it & 1) ? n - 1 - j : j]], bodies[s.a], bodies[s.b]);
      }
  }
#endif
}

}  // namespace bw
