#pragma once
/// The solver's records: one per contact point, one per body, and the impulses kept between
/// substeps for warm starting. Plain data shared by islands and the contact solver.
#include <cstddef>
#include <cstdint>

#include "collision/core/math_types.h"

namespace bw {

/// One contact point as the solver's iterations see it, with everything an iteration needs
/// precomputed, and nothing else: three cache lines a contact (it was five with the fields
/// below in SolverContactExtras; ship_refit solves ~8,600 contacts ten times a frame).
struct alignas(64) SolverContact {
  uint32_t a, b;         // a receives +impulse along normal, b the opposite
  Vec3f normal;          // from b towards a
  float bias, relaxBias, friction;
  Vec3f rA, rB, t1, t2;
  // Angular response per unit impulse along n, t1, t2 (inverse inertia x (r x d)), computed
  // once per substep so iterations are multiply-adds.
  Vec3f angA[3], angB[3];
  float massN, massT1, massT2;
  float lambdaN = 0, lambdaT1 = 0, lambdaT2 = 0;
  float rolling = 0;     // rolling resistance: coefficient x the round body's radius (m); 0: none
};
static_assert(sizeof(SolverContact) == 192);

/// What the rest of the solver reads of a contact, beside SolverContact at the same index: the
/// warm-start key and point, shock propagation's masses and order, rolling resistance. Ordered
/// so a contact without shock or rolling writes and reads only the first cache line.
struct alignas(64) SolverContactExtras {
  Vec3d point;
  uint64_t pairKey;      // the pair (a << 32 | b, as the broadphase ordered it), for warm starting
  uint32_t feature;      // the contact's feature on the pair's b side (brick, triangle)
  // Rolling resistance (a sphere or capsule in the pair): angular impulses about t1 and t2,
  // bounded by rolling x lambdaN; the bodies' angular response to each (inverse inertia x axis)
  // and the effective masses, in the second line.
  float lambdaR1 = 0, lambdaR2 = 0;
  // Shock propagation: which body is lower along gravity (0 none, 1 a, 2 b), the contact's
  // height (for the bottom-up order), and in the second line the effective masses with the
  // lower body immovable.
  uint8_t shockLower = 0;
  double height = 0;
  float massR[2];
  float shockMass[3];
  Vec3f rollA[2], rollB[2];
};
static_assert(sizeof(SolverContactExtras) == 128);
static_assert(offsetof(SolverContactExtras, massR) < 64 && offsetof(SolverContactExtras, shockMass) >= 64);

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
