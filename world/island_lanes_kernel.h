#pragma once
// The row kernels of IslandLanes, written once for any register width: included by the SSE2
// kernels' file and by the AVX2 one (compiled with -mavx2), each with its own `Ops` (the
// register type, its lane count N and its operations). Everything here has internal linkage, so
// the two files' copies never meet at link time (see island_lanes_rows.h).
//
// Each operation is the scalar reference's (world/contact_update.h) lane by lane, in its order:
// products and sums as written, 3-vector dot products summed x + (y + z) as Eigen's unrolled
// sum does, std::max(x, 0) as a compare (so -0 and NaN come out as the scalar code's do), the
// cone's scale as a select, a body that is not dynamic never changed (the scalar code's
// `if (dynamic)`). -ffp-contract=off: no fused multiply-adds on either side.
#include <cstdint>

#include "world/island_lanes_rows.h"

namespace bw::lanes {
namespace {

// What an idle lane reads as its bodies: static and still (eight zero floats).
alignas(32) const float kIdleBodyRecord[8] = {};

template <class O>
struct V3 {
  typename O::V x, y, z;
};
template <class O>
inline V3<O> load3(const float (&f)[3][kWidth], uint32_t off) {
  return {O::load(f[0] + off), O::load(f[1] + off), O::load(f[2] + off)};
}
template <class O>
inline V3<O> add(V3<O> a, V3<O> b) {
  return {O::add(a.x, b.x), O::add(a.y, b.y), O::add(a.z, b.z)};
}
template <class O>
inline V3<O> sub(V3<O> a, V3<O> b) {
  return {O::sub(a.x, b.x), O::sub(a.y, b.y), O::sub(a.z, b.z)};
}
template <class O>
inline V3<O> mul(V3<O> a, typename O::V s) {
  return {O::mul(a.x, s), O::mul(a.y, s), O::mul(a.z, s)};
}
// m ? a : b, lane by lane (m all ones or all zeros).
template <class O>
inline typename O::V select(typename O::V m, typename O::V a, typename O::V b) {
  return O::bitOr(O::bitAnd(m, a), O::andNot(m, b));
}
// Eigen's cross product: (a.y b.z - a.z b.y, a.z b.x - a.x b.z, a.x b.y - a.y b.x).
template <class O>
inline V3<O> cross(V3<O> a, V3<O> b) {
  return {O::sub(O::mul(a.y, b.z), O::mul(a.z, b.y)), O::sub(O::mul(a.z, b.x), O::mul(a.x, b.z)),
          O::sub(O::mul(a.x, b.y), O::mul(a.y, b.x))};
}
// Eigen's dot product of 3-vectors: x + (y + z).
template <class O>
inline typename O::V dot(V3<O> a, V3<O> b) {
  return O::add(O::mul(a.x, b.x), O::add(O::mul(a.y, b.y), O::mul(a.z, b.z)));
}
// std::max(x, 0.f): x unless x < 0, so -0 and NaN come out as they went in.
template <class O>
inline typename O::V maxZero(typename O::V x) {
  return O::andNot(O::less(x, O::zero()), x);
}
// clampToFrictionCone: (t1, t2) scaled back to length `limit` when longer.
template <class O>
inline void clampToCone(typename O::V t1, typename O::V t2, typename O::V limit, typename O::V& out1, typename O::V& out2) {
  const typename O::V length2 = O::add(O::mul(t1, t1), O::mul(t2, t2));
  const typename O::V over = O::greater(length2, O::mul(limit, limit));
  const typename O::V scale = select<O>(over, O::div(limit, O::sqrt(length2)), O::set1(1.f));
  out1 = O::mul(t1, scale);
  out2 = O::mul(t2, scale);
}

// One side (a or b) of a row's N lanes starting at lane `off`: the bodies' records transposed
// into lanes, and written back to the dynamic ones. A record is two 16-byte blocks, (v, invMass)
// and (w, dynamic): the transposes carry invMass and the dynamic word through unchanged.
template <class O>
struct LaneBodies {
  using V = typename O::V;
  float* at[O::N];  // nullptr in an idle lane
  V3<O> v, w;
  V invMass, dynamicWord, dynamic;  // dynamic: all ones where the body is dynamic
  V stillNegZero;                   // -0 where a lane's body is not dynamic, else +0
  uint32_t dynamicBits;
  bool masked;  // some lane holds a real body that is not dynamic (idle lanes' results are dropped)

  LaneBodies(const uint32_t* index, float* bodies) {
    const float* in[O::N];
    uint32_t real = 0;
    for (int l = 0; l < O::N; ++l) {
      at[l] = index[l] == kIdleBody ? nullptr : bodies + size_t(index[l]) * 8;
      in[l] = at[l] ? at[l] : kIdleBodyRecord;
      real |= uint32_t(at[l] != nullptr) << l;
    }
    O::gather(in, 0, v.x, v.y, v.z, invMass);
    O::gather(in, 4, w.x, w.y, w.z, dynamicWord);
    dynamic = O::nonZeroWord(dynamicWord);
    stillNegZero = O::andNot(dynamic, O::set1(-0.f));
    dynamicBits = O::lanes(dynamic);
    masked = (real & ~dynamicBits) != 0;
  }
  // Impulse `lambda` along dir with angular response ang: + for side a, - for side b. A body
  // that is not dynamic keeps its velocity bits: it gains -0 (x + -0 == x for every x, +0 and
  // -0 included) or loses +0 (x - +0 == x), as the scalar code's `if (dynamic)` leaves it.
  template <bool kPlus>
  void apply(V3<O> dir, V3<O> ang, V lambda) {
    const V scaled = O::mul(lambda, invMass);
    V3<O> dv = mul<O>(dir, scaled), dw = mul<O>(ang, lambda);
    if (masked) {
      if constexpr (kPlus) {
        dv = {O::bitOr(O::bitAnd(dynamic, dv.x), stillNegZero), O::bitOr(O::bitAnd(dynamic, dv.y), stillNegZero),
              O::bitOr(O::bitAnd(dynamic, dv.z), stillNegZero)};
        dw = {O::bitOr(O::bitAnd(dynamic, dw.x), stillNegZero), O::bitOr(O::bitAnd(dynamic, dw.y), stillNegZero),
              O::bitOr(O::bitAnd(dynamic, dw.z), stillNegZero)};
      } else {
        dv = {O::bitAnd(dynamic, dv.x), O::bitAnd(dynamic, dv.y), O::bitAnd(dynamic, dv.z)};
        dw = {O::bitAnd(dynamic, dw.x), O::bitAnd(dynamic, dw.y), O::bitAnd(dynamic, dw.z)};
      }
    }
    if constexpr (kPlus) {
      v = add<O>(v, dv);
      w = add<O>(w, dw);
    } else {
      v = sub<O>(v, dv);
      w = sub<O>(w, dw);
    }
  }
  void store() const {
    if (!dynamicBits) return;
    O::scatter(at, 0, dynamicBits, v.x, v.y, v.z, invMass);
    O::scatter(at, 4, dynamicBits, w.x, w.y, w.z, dynamicWord);
  }
};

// The velocity of a's contact point relative to b's: ((vA + wA x rA) - vB) - wB x rB.
template <class O>
inline V3<O> relative(const LaneBodies<O>& a, const LaneBodies<O>& b, V3<O> rA, V3<O> rB) {
  return sub<O>(sub<O>(add<O>(a.v, cross<O>(a.w, rA)), b.v), cross<O>(b.w, rB));
}

// warmStartContact on lanes off .. off + N - 1 of a row.
template <class O>
void warmStartRow(const Row& row, float* bodies, uint32_t off) {
  LaneBodies<O> a(row.a + off, bodies), b(row.b + off, bodies);
  const V3<O> dirs[3] = {load3<O>(row.n, off), load3<O>(row.t1, off), load3<O>(row.t2, off)};
  for (int d = 0; d < 3; ++d) {
    const typename O::V lambda = O::load(row.lambda[d] + off);
    a.template apply<true>(dirs[d], load3<O>(row.angA[d], off), lambda);
    b.template apply<false>(dirs[d], load3<O>(row.angB[d], off), lambda);
  }
  a.store();
  b.store();
}

// updateContact (then resistRolling where the lane's contact rolls) on lanes off .. off + N - 1.
template <class O>
void updateRow(Row& row, RollRow& roll, float* bodies, uint32_t off) {
  using V = typename O::V;
  LaneBodies<O> a(row.a + off, bodies), b(row.b + off, bodies);
  const V3<O> n = load3<O>(row.n, off), rA = load3<O>(row.rA, off), rB = load3<O>(row.rB, off);
  const V oldN = O::load(row.lambda[0] + off);
  const V lambdaN = maxZero<O>(
      O::add(oldN, O::mul(O::load(row.mass[0] + off), O::sub(O::load(row.bias + off), dot<O>(relative<O>(a, b, rA, rB), n)))));
  const V stepN = O::sub(lambdaN, oldN);
  a.template apply<true>(n, load3<O>(row.angA[0], off), stepN);
  b.template apply<false>(n, load3<O>(row.angB[0], off), stepN);
  const V limit = O::mul(O::load(row.friction + off), lambdaN);
  const V3<O> v = relative<O>(a, b, rA, rB);
  const V3<O> t1 = load3<O>(row.t1, off), t2 = load3<O>(row.t2, off);
  const V o1 = O::load(row.lambda[1] + off), o2 = O::load(row.lambda[2] + off);
  V lambdaT1, lambdaT2;
  clampToCone<O>(O::sub(o1, O::mul(O::load(row.mass[1] + off), dot<O>(v, t1))),
                 O::sub(o2, O::mul(O::load(row.mass[2] + off), dot<O>(v, t2))), limit, lambdaT1, lambdaT2);
  const V step1 = O::sub(lambdaT1, o1), step2 = O::sub(lambdaT2, o2);
  a.template apply<true>(t1, load3<O>(row.angA[1], off), step1);
  b.template apply<false>(t1, load3<O>(row.angB[1], off), step1);
  a.template apply<true>(t2, load3<O>(row.angA[2], off), step2);
  b.template apply<false>(t2, load3<O>(row.angB[2], off), step2);
  O::store(row.lambda[0] + off, lambdaN);
  O::store(row.lambda[1] + off, lambdaT1);
  O::store(row.lambda[2] + off, lambdaT2);
  const uint32_t rollBits = (row.rolls >> off) & ((1u << O::N) - 1);
  if (rollBits) {
    // resistRolling on the bodies as the update left them; lanes that do not roll keep theirs.
    const V rolls = O::laneMask(rollBits);
    const V3<O> w = sub<O>(a.w, b.w);
    const V r1 = O::load(roll.lambdaR[0] + off), r2 = O::load(roll.lambdaR[1] + off);
    V lambdaR1, lambdaR2;
    clampToCone<O>(O::sub(r1, O::mul(O::load(roll.massR[0] + off), dot<O>(w, t1))),
                   O::sub(r2, O::mul(O::load(roll.massR[1] + off), dot<O>(w, t2))),
                   O::mul(O::load(roll.rolling + off), lambdaN), lambdaR1, lambdaR2);
    const V d1 = O::sub(lambdaR1, r1), d2 = O::sub(lambdaR2, r2);
    const V3<O> turnA = add<O>(mul<O>(load3<O>(roll.rollA[0], off), d1), mul<O>(load3<O>(roll.rollA[1], off), d2));
    const V3<O> turnB = add<O>(mul<O>(load3<O>(roll.rollB[0], off), d1), mul<O>(load3<O>(roll.rollB[1], off), d2));
    const V turnsA = O::bitAnd(rolls, a.dynamic), turnsB = O::bitAnd(rolls, b.dynamic);
    a.w = {select<O>(turnsA, O::add(a.w.x, turnA.x), a.w.x), select<O>(turnsA, O::add(a.w.y, turnA.y), a.w.y),
           select<O>(turnsA, O::add(a.w.z, turnA.z), a.w.z)};
    b.w = {select<O>(turnsB, O::sub(b.w.x, turnB.x), b.w.x), select<O>(turnsB, O::sub(b.w.y, turnB.y), b.w.y),
           select<O>(turnsB, O::sub(b.w.z, turnB.z), b.w.z)};
    O::store(roll.lambdaR[0] + off, select<O>(rolls, lambdaR1, r1));
    O::store(roll.lambdaR[1] + off, select<O>(rolls, lambdaR2, r2));
  }
  a.store();
  b.store();
}

// The two kernels of one width: rows in order, each in kWidth / N register widths.
template <class O>
void warmStartRows(const Row* rows, uint32_t first, uint32_t last, float* bodies) {
  for (uint32_t r = first; r < last; ++r)
    for (uint32_t off = 0; off < kWidth; off += O::N)
      if ((rows[r].active >> off) & ((1u << O::N) - 1)) warmStartRow<O>(rows[r], bodies, off);
}
template <class O>
void passRows(Row* rows, RollRow* roll, uint32_t first, uint32_t last, bool reversed, float* bodies) {
  for (uint32_t j = first; j < last; ++j) {
    const uint32_t r = reversed ? first + last - 1 - j : j;
    for (uint32_t off = 0; off < kWidth; off += O::N)
      if ((rows[r].active >> off) & ((1u << O::N) - 1)) updateRow<O>(rows[r], roll[r], bodies, off);
  }
}

}  // namespace
}  // namespace bw::lanes
