// The solver's inner loop (world/contact_update.h): the SSE2 update and warm start must give the
// scalar reference's bits exactly (every state hash depends on them), on islands of random
// contacts solved over many iterations, with static and kinematic bodies, sliding and sticking
// friction, and magnitudes from 1e-6 to 1e6.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#include "world/contact_update.h"
#include "world/support/random_solver_contact.h"

namespace bw {
namespace {

bool sameBits(const void* a, const void* b, size_t n) { return std::memcmp(a, b, n) == 0; }

struct Island {
  std::vector<SolverBody> bodies;
  std::vector<SolverContact> contacts;
};

// A random island: `bodyCount` bodies (about one in four static or kinematic, which must never
// be written), contacts between random pairs with random geometry at the scale `scale`.
Island randomIsland(std::mt19937& rng, uint32_t bodyCount, uint32_t contactCount, float scale) {
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  std::uniform_real_distribution<float> pos(0.f, 1.f);
  auto vec = [&](float s) { return Vec3f(u(rng) * s, u(rng) * s, u(rng) * s); };
  Island island;
  island.bodies.resize(bodyCount);
  for (SolverBody& b : island.bodies) {
    b.dynamic = pos(rng) < 0.75f ? 1u : 0u;
    b.invMass = b.dynamic ? 0.01f + pos(rng) * 10.f : 0.f;
    b.v = vec(scale);
    b.w = vec(scale);
  }
  island.contacts.resize(contactCount);
  for (SolverContact& s : island.contacts) {
    s.a = uint32_t(rng() % bodyCount);
    do s.b = uint32_t(rng() % bodyCount);
    while (s.b == s.a);
    test::drawSolverContact(rng, scale, s);
  }
  return island;
}

TEST(ContactUpdate, SseGivesTheScalarReferenceBitForBit) {
  std::mt19937 rng(38);
  uint32_t differing = 0, compared = 0, clamped = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const float scale = std::pow(10.f, float(int(rng() % 13)) - 6.f);  // 1e-6 .. 1e6
    const uint32_t bodies = 2 + uint32_t(rng() % 40);
    Island ref = randomIsland(rng, bodies, 1 + uint32_t(rng() % 120), scale);
    Island simd = ref;
    for (const SolverContact& s : ref.contacts) warmStartScalar(s, ref.bodies[s.a], ref.bodies[s.b]);
    for (const SolverContact& s : simd.contacts) warmStartContact(s, simd.bodies[s.a], simd.bodies[s.b]);
    for (int it = 0; it < 10; ++it) {
      const bool relax = it >= 8;
      for (size_t k = 0; k < ref.contacts.size(); ++k) {
        SolverContact& r = ref.contacts[k];
        SolverContact& q = simd.contacts[k];
        updateContactScalar(r, relax, ref.bodies[r.a], ref.bodies[r.b]);
        updateContact(q, relax, simd.bodies[q.a], simd.bodies[q.b]);
        clamped += r.lambdaN == 0.f;
      }
    }
    ++compared;
    // (SolverBody has no padding; a contact's padding is compared field by field, so not at all.)
    bool same = sameBits(ref.bodies.data(), simd.bodies.data(), ref.bodies.size() * sizeof(SolverBody));
    for (size_t k = 0; k < ref.contacts.size(); ++k) {
      const SolverContact& r = ref.contacts[k];
      const SolverContact& q = simd.contacts[k];
      same &= sameBits(&r.lambdaN, &q.lambdaN, sizeof(float)) && sameBits(&r.lambdaT1, &q.lambdaT1, sizeof(float)) &&
              sameBits(&r.lambdaT2, &q.lambdaT2, sizeof(float));
    }
    differing += !same;
    EXPECT_TRUE(same) << "trial " << trial << " at scale " << scale;
  }
  EXPECT_EQ(differing, 0u) << "of " << compared;
  EXPECT_GT(clamped, 1000u);  // separating contacts were among them
}

// Static and kinematic bodies are read, never written: not their velocities, and not the fields
// beside a velocity that a 16-byte load reads along (invMass, dynamic).
TEST(ContactUpdate, LeavesBodiesThatAreNotDynamicAndTheFieldsBesideUntouched) {
  std::mt19937 rng(7);
  Island island = randomIsland(rng, 12, 60, 3.f);
  const std::vector<SolverBody> before = island.bodies;
  for (int it = 0; it < 4; ++it)
    for (SolverContact& s : island.contacts) {
      if (it == 0) warmStartContact(s, island.bodies[s.a], island.bodies[s.b]);
      updateContact(s, it == 3, island.bodies[s.a], island.bodies[s.b]);
    }
  uint32_t moved = 0;
  for (size_t i = 0; i < before.size(); ++i) {
    EXPECT_EQ(island.bodies[i].dynamic, before[i].dynamic);
    EXPECT_TRUE(sameBits(&island.bodies[i].invMass, &before[i].invMass, sizeof(float)));
    if (!before[i].dynamic) {
      EXPECT_TRUE(sameBits(&island.bodies[i], &before[i], sizeof(SolverBody))) << "body " << i;
    } else {
      moved += island.bodies[i].v != before[i].v;
    }
  }
  EXPECT_GT(moved, 0u);
}

}  // namespace
}  // namespace bw
