#pragma once
/// The inner loop of the contact solver: one contact's warm start and one Gauss-Seidel update of
/// its normal and friction impulses, on its two bodies' velocity records. Two versions with
/// bit-identical results: the scalar reference (Eigen 3-vectors, as the solver was written) and
/// the SSE2 one the solver runs, which does each 3-vector operation on the three lanes at once in
/// the same order (products and differences lane by lane, dot products summed x + (y + z) as
/// Eigen's unrolled sum does; -ffp-contract=off, so no fused multiply-adds on either side).
/// Every state hash depends on these bits; contact_update_test checks them on random contacts.
#include <algorithm>
#include <cmath>

#include "world/solver_contact.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace bw {

/// Coulomb's cone: the friction impulse (t1, t2) is scaled back to length `limit` when longer.
/// note: clamping each tangent on its own (a pyramid) pushes sideways to the sliding direction:
/// a capsule landing on its end came away rolling about its own axis at up to 4 rad/s.
inline void clampToFrictionCone(float t1, float t2, float limit, float& out1, float& out2) {
  const float length2 = t1 * t1 + t2 * t2;
  const float scale = length2 > limit * limit ? limit / std::sqrt(length2) : 1.f;
  out1 = t1 * scale;
  out2 = t2 * scale;
}

namespace scalar_contact {

// A contact's two bodies in locals while the contact is solved: the compiler then keeps them in
// registers, where stores through the bodies' records could alias the contact's floats and made
// it load them again after every store. Impulses change dynamic bodies only (static and
// kinematic bodies are read, never written); store() writes back only those.
struct ContactBodies {
  SolverBody& bodyA;
  SolverBody& bodyB;
  Vec3f vA = bodyA.v, wA = bodyA.w, vB = bodyB.v, wB = bodyB.w;

  // The velocity of a's point relative to b's.
  Vec3f relative(const SolverContact& s) const { return Vec3f(vA + wA.cross(s.rA) - vB - wB.cross(s.rB)); }
  // Impulse `lambda` along direction d (0 normal, 1 and 2 tangents): a receives +, b -.
  void apply(const SolverContact& s, int d, const Vec3f& dir, float lambda) {
    if (bodyA.dynamic) {
      vA += dir * (lambda * bodyA.invMass);
      wA += s.angA[d] * lambda;
    }
    if (bodyB.dynamic) {
      vB -= dir * (lambda * bodyB.invMass);
      wB -= s.angB[d] * lambda;
    }
  }
  void store() const {
    if (bodyA.dynamic) bodyA.v = vA, bodyA.w = wA;
    if (bodyB.dynamic) bodyB.v = vB, bodyB.w = wB;
  }
};

}  // namespace scalar_contact

/// The scalar reference: the contact's cached impulses applied to its bodies.
inline void warmStartScalar(const SolverContact& s, SolverBody& a, SolverBody& b) {
  scalar_contact::ContactBodies ab{a, b};
  ab.apply(s, 0, s.normal, s.lambdaN);
  ab.apply(s, 1, s.t1, s.lambdaT1);
  ab.apply(s, 2, s.t2, s.lambdaT2);
  ab.store();
}

/// The scalar reference: one Gauss-Seidel update of one contact, the normal impulse clamped at
/// zero, then friction clamped by the Coulomb cone (`relax`: the bias without push-out).
inline void updateContactScalar(SolverContact& s, bool relax, SolverBody& a, SolverBody& b) {
  scalar_contact::ContactBodies ab{a, b};
  const float oldN = s.lambdaN;
  const float lambdaN = std::max(oldN + s.massN * ((relax ? s.relaxBias : s.bias) - ab.relative(s).dot(s.normal)), 0.f);
  ab.apply(s, 0, s.normal, lambdaN - oldN);
  const float limit = s.friction * lambdaN;
  const Vec3f v = ab.relative(s);
  const float o1 = s.lambdaT1, o2 = s.lambdaT2;
  float lambdaT1, lambdaT2;
  clampToFrictionCone(o1 - s.massT1 * v.dot(s.t1), o2 - s.massT2 * v.dot(s.t2), limit, lambdaT1, lambdaT2);
  ab.apply(s, 1, s.t1, lambdaT1 - o1);
  ab.apply(s, 2, s.t2, lambdaT2 - o2);
  ab.store();
  s.lambdaN = lambdaN;
  s.lambdaT1 = lambdaT1;
  s.lambdaT2 = lambdaT2;
}

/// Rolling resistance, after the contact's update: the relative spin about the two tangent axes
/// (rolling, not spinning about the normal) is opposed by an angular impulse within a cone of
/// rolling x lambdaN, as friction opposes sliding. Without it a capsule that lands spinning about
/// its axis rolls forever and never sleeps.
inline void resistRolling(const SolverContact& s, SolverContactExtras& x, SolverBody& a, SolverBody& b) {
  const Vec3f w = a.w - b.w;
  const float o1 = x.lambdaR1, o2 = x.lambdaR2;
  clampToFrictionCone(o1 - x.massR[0] * w.dot(s.t1), o2 - x.massR[1] * w.dot(s.t2), s.rolling * s.lambdaN, x.lambdaR1, x.lambdaR2);
  const float d1 = x.lambdaR1 - o1, d2 = x.lambdaR2 - o2;
  if (a.dynamic) a.w += x.rollA[0] * d1 + x.rollA[1] * d2;
  if (b.dynamic) b.w -= x.rollB[0] * d1 + x.rollB[1] * d2;
}

#if defined(__SSE2__)
namespace sse_contact {

// A Vec3f in lanes 0-2 of a register. The load reads the 4 bytes after the vector too (every
// Vec3f the solver loads has a field of its record after it); lane 3 is zeroed, so a body's
// `dynamic` word (a denormal read as a float, slow to multiply) never enters the arithmetic.
// Lane 3 of every result is ignored.
inline __m128 load3(const Vec3f& v) {
  const __m128 lanes012 = _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1));
  return _mm_and_ps(_mm_loadu_ps(v.data()), lanes012);
}
// Writes lanes 0-2 only (the record's next field stays as it is).
inline void store3(Vec3f& v, __m128 x) {
  _mm_storel_pi(reinterpret_cast<__m64*>(v.data()), x);
  _mm_store_ss(v.data() + 2, _mm_shuffle_ps(x, x, _MM_SHUFFLE(2, 2, 2, 2)));
}
template <int I0, int I1, int I2>
inline __m128 swizzle(__m128 x) {
  return _mm_shuffle_ps(x, x, _MM_SHUFFLE(3, I2, I1, I0));
}
// Eigen's cross product lane by lane: (a.y b.z - a.z b.y, a.z b.x - a.x b.z, a.x b.y - a.y b.x).
inline __m128 cross(__m128 a, __m128 b) {
  return _mm_sub_ps(_mm_mul_ps(swizzle<1, 2, 0>(a), swizzle<2, 0, 1>(b)), _mm_mul_ps(swizzle<2, 0, 1>(a), swizzle<1, 2, 0>(b)));
}
// Eigen's dot product of 3-vectors: its unrolled sum splits the three products as x + (y + z).
inline float dot(__m128 a, __m128 b) {
  const __m128 p = _mm_mul_ps(a, b);
  const __m128 yz = _mm_add_ss(swizzle<1, 1, 1>(p), swizzle<2, 2, 2>(p));
  return _mm_cvtss_f32(_mm_add_ss(p, yz));
}

struct ContactBodies {
  SolverBody& bodyA;
  SolverBody& bodyB;
  __m128 vA = load3(bodyA.v), wA = load3(bodyA.w), vB = load3(bodyB.v), wB = load3(bodyB.w);

  __m128 relative(const SolverContact& s) const {
    return _mm_sub_ps(_mm_sub_ps(_mm_add_ps(vA, cross(wA, load3(s.rA))), vB), cross(wB, load3(s.rB)));
  }
  void apply(const SolverContact& s, int d, __m128 dir, float lambda) {
    if (bodyA.dynamic) {
      vA = _mm_add_ps(vA, _mm_mul_ps(dir, _mm_set1_ps(lambda * bodyA.invMass)));
      wA = _mm_add_ps(wA, _mm_mul_ps(load3(s.angA[d]), _mm_set1_ps(lambda)));
    }
    if (bodyB.dynamic) {
      vB = _mm_sub_ps(vB, _mm_mul_ps(dir, _mm_set1_ps(lambda * bodyB.invMass)));
      wB = _mm_sub_ps(wB, _mm_mul_ps(load3(s.angB[d]), _mm_set1_ps(lambda)));
    }
  }
  void store() const {
    if (bodyA.dynamic) store3(bodyA.v, vA), store3(bodyA.w, wA);
    if (bodyB.dynamic) store3(bodyB.v, vB), store3(bodyB.w, wB);
  }
};

}  // namespace sse_contact
#endif

/// What the solver runs: warmStartScalar's result, bit for bit.
inline void warmStartContact(const SolverContact& s, SolverBody& a, SolverBody& b) {
#if defined(__SSE2__)
  sse_contact::ContactBodies ab{a, b};
  ab.apply(s, 0, sse_contact::load3(s.normal), s.lambdaN);
  ab.apply(s, 1, sse_contact::load3(s.t1), s.lambdaT1);
  ab.apply(s, 2, sse_contact::load3(s.t2), s.lambdaT2);
  ab.store();
#else
  warmStartScalar(s, a, b);
#endif
}

/// What the solver runs: updateContactScalar's result, bit for bit.
inline void updateContact(SolverContact& s, bool relax, SolverBody& a, SolverBody& b) {
#if defined(__SSE2__)
  using namespace sse_contact;
  ContactBodies ab{a, b};
  const __m128 normal = load3(s.normal);
  const float oldN = s.lambdaN;
  const float lambdaN = std::max(oldN + s.massN * ((relax ? s.relaxBias : s.bias) - dot(ab.relative(s), normal)), 0.f);
  ab.apply(s, 0, normal, lambdaN - oldN);
  const float limit = s.friction * lambdaN;
  const __m128 v = ab.relative(s);
  const __m128 t1 = load3(s.t1), t2 = load3(s.t2);
  const float o1 = s.lambdaT1, o2 = s.lambdaT2;
  float lambdaT1, lambdaT2;
  clampToFrictionCone(o1 - s.massT1 * dot(v, t1), o2 - s.massT2 * dot(v, t2), limit, lambdaT1, lambdaT2);
  ab.apply(s, 1, t1, lambdaT1 - o1);
  ab.apply(s, 2, t2, lambdaT2 - o2);
  ab.store();
  s.lambdaN = lambdaN;
  s.lambdaT1 = lambdaT1;
  s.lambdaT2 = lambdaT2;
#else
  updateContactScalar(s, relax, a, b);
#endif
}

}  // namespace bw
