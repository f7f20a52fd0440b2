#pragma once
/// The solver's records: one per contact point, one per body, and the impulses kept between
/// substeps for warm starting. Plain data shared by islands and the contact solver.
#include <cstdint>

#include "collision/core/math_types.h"

namespace bw {

/// One contact point as the solver sees it, with everything an iteration needs precomputed.
struct SolverContact {
  uint32_t a, b;         // a receives +impulse along normal, b the opposite
  Vec3d point;
  Vec3f normal;          // from b towards a
  float depth;
  uint64_t pairKey;      // the pair (a << 32 | b, as the broadphase ordered it), for warm starting
  uint32_t feature;      // the contact's feature on the pair's b side (brick, triangle)
  Vec3f rA, rB, t1, t2;
  // Angular response per unit impulse along n, t1, t2 (inverse inertia x (r x d)), computed
  // once per substep so iterations are multiply-adds.
  Vec3f angA[3], angB[3];
  float massN, massT1, massT2, bias, relaxBias, friction;
  // Shock propagation: effective masses with the lower body immovable, which body is lower
  // along gravity (0 none, 1 a, 2 b) and the contact's height (for the bottom-up order).
  float shockMass[3];
  uint8_t shockLower = 0;
  double height = 0;
  float lambdaN = 0, lambdaT1 = 0, lambdaT2 = 0;
  // Rolling resistance (a sphere or capsule in the pair): angular impulses about t1 and t2,
  // bounded by rolling x lambdaN; the bodies' angular response to each (inverse inertia x axis).
  float rolling = 0;     // coefficient x the round body's radius (m); 0: none
  Vec3f rollA[2], rollB[2];
  float massR[2];
  float lambdaR1 = 0, lambdaR2 = 0;
};

/// A body's velocities as the solver reads and writes them: one 32-byte record per body
/// instead of five arrays.
struct SolverBody {
  Vec3f v;            // 12 linear velocity
  float invMass;      // 4
  Vec3f w;            // 12 angular velocity (world)
  uint32_t dynamic;   // 4  0: static or kinematic (read, never written)
};
static_assert(sizeof(SolverBody) == 32);

/// A contact's final impulses, kept for the next substep. The key is the pair and the
/// feature, each at full width, so brick ids above 2^20 and body ids above 2^20 never collide.
struct CachedImpulse {
  uint64_t pairKey;
  uint32_t feature;
  uint32_t contact;  // the contact's index this substep: orders a pair's repeated features
  Vec3d point;
  float n, t1, t2;
  bool operator<(const CachedImpulse& o) const { return pairKey < o.pairKey || (pairKey == o.pairKey && feature < o.feature); }
};

}  // namespace bw
