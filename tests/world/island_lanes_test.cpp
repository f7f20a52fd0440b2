// Islands solved side by side in SIMD lanes (world/island_lanes.h) must leave every body and
// every impulse with the bits of solving each island alone through the scalar reference
// (warmStartScalar, updateContactScalar, resistRolling): every state hash depends on them.
// Seeded islands of 0-40 contacts side by side (so lanes idle at either end of a pass), static
// and kinematic bodies shared by all of them, rolling contacts in some lanes only, velocities of
// -0, magnitudes from 1e-6 to 1e6, warm start on and off, the solve and the relax pass; with the
// AVX2 row kernels (where the CPU has them) and the SSE2 ones.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <span>
#include <vector>

#include "world/contact_update.h"
#include "world/island_lanes.h"
#include "world/support/random_solver_contact.h"

namespace bw {
namespace {

struct Scene {
  std::vector<SolverBody> bodies;
  std::vector<SolverContact> contacts;
  std::vector<SolverContactExtras> extras;
  std::vector<std::vector<uint32_t>> islands;  // contact indices, in solve order
};

// `shared` static or kinematic bodies every island may touch, then each island's own dynamic
// bodies; contacts between two of an island's bodies or one of them and a shared one.
Scene randomScene(std::mt19937& rng, uint32_t islandCount, float scale, uint32_t maxBodies = 12, uint32_t maxContacts = 40) {
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  auto vec = [&](float s) {
    const float x = u(rng) * s;
    const float y = u(rng) * s;
    const float z = u(rng) * s;
    return Vec3f(x, y, z);
  };
  Scene scene;
  const uint32_t shared = 1 + uint32_t(rng() % 3);
  for (uint32_t i = 0; i < shared; ++i) {
    SolverBody b{};
    b.v = i == 0 ? Vec3f(-0.f, 0.f, -0.f) : vec(scale);  // the ground still, others kinematic
    b.w = i == 0 ? Vec3f(-0.f, 0.f, -0.f) : vec(scale);
    scene.bodies.push_back(b);
  }
  for (uint32_t isl = 0; isl < islandCount; ++isl) {
    const uint32_t first = uint32_t(scene.bodies.size());
    const uint32_t own = 1 + uint32_t(rng() % maxBodies);
    for (uint32_t i = 0; i < own; ++i) {
      SolverBody b{};
      b.dynamic = 1u;
      b.invMass = 0.01f + unit(rng) * 10.f;
      b.v = rng() % 5 == 0 ? Vec3f(-0.f, -0.f, 0.f) : vec(scale);
      b.w = rng() % 4 == 0 ? Vec3f(-0.f, -0.f, -0.f) : vec(scale);
      scene.bodies.push_back(b);
    }
    std::vector<uint32_t> island;
    const uint32_t contacts = rng() % 8 == 0 ? 0 : 1 + uint32_t(rng() % maxContacts);
    for (uint32_t c = 0; c < contacts; ++c) {
      SolverContact s{};
      SolverContactExtras x{};
      x.point = Vec3d::Zero();
      x.rollA[0] = x.rollA[1] = x.rollB[0] = x.rollB[1] = Vec3f::Zero();
      s.a = first + uint32_t(rng() % own);
      const bool againstShared = own == 1 || rng() % 3 == 0;
      if (againstShared) {
        s.b = uint32_t(rng() % shared);
      } else {
        do s.b = first + uint32_t(rng() % own);
        while (s.b == s.a);
      }
      if (rng() % 2) std::swap(s.a, s.b);
      test::drawSolverContact(rng, scale, s);
      if (rng() % 6 == 0) {
        // A contact that never pushes: its steps are zeros, whose signs a lane must keep as the
        // scalar code does (a body's -0 stays -0 only if nothing adds +0 to it).
        s.massN = s.massT1 = s.massT2 = 0.f;
        s.lambdaN = s.lambdaT1 = s.lambdaT2 = 0.f;
        for (int d = 0; d < 3; ++d) s.angA[d] = s.angB[d] = Vec3f(-0.5f, -0.5f, -0.5f);
      }
      if (rng() % 3 == 0) {
        s.rolling = 0.01f + unit(rng) * 0.2f;
        for (int t = 0; t < 2; ++t) {
          x.rollA[t] = vec(unit(rng));
          x.rollB[t] = vec(unit(rng));
          x.massR[t] = unit(rng) * 5.f;
        }
        x.lambdaR1 = u(rng) * s.rolling * s.lambdaN;
        x.lambdaR2 = u(rng) * s.rolling * s.lambdaN;
      }
      island.push_back(uint32_t(scene.contacts.size()));
      scene.contacts.push_back(s);
      scene.extras.push_back(x);
    }
    // Contacts listed out of index order, as an island's contacts may be after grouping.
    std::shuffle(island.begin(), island.end(), rng);
    scene.islands.push_back(island);
  }
  return scene;
}

// The scalar reference: each island alone, as ContactSolver::solveIsland solves it.
void solveAlone(Scene& s, bool warmStart, bool relax, int iterations) {
  for (const std::vector<uint32_t>& island : s.islands) {
    const uint32_t n = uint32_t(island.size());
    if (warmStart)
      for (uint32_t k : island) warmStartScalar(s.contacts[k], s.bodies[s.contacts[k].a], s.bodies[s.contacts[k].b]);
    for (int it = 0; it < iterations; ++it)
      for (uint32_t j = 0; j < n; ++j) {
        const uint32_t k = island[(it & 1) ? n - 1 - j : j];
        SolverContact& c = s.contacts[k];
        updateContactScalar(c, relax, s.bodies[c.a], s.bodies[c.b]);
        if (c.rolling > 0.f) resistRolling(c, s.extras[k], s.bodies[c.a], s.bodies[c.b]);
      }
  }
}

bool sameBits(const void* a, const void* b, size_t n) { return std::memcmp(a, b, n) == 0; }

// Runs body with each row kernel this machine has: AVX2 (where the CPU has it), then SSE2.
template <class Body>
void forEachKernel(Body&& body) {
  if (lanes::avx2()) {
    SCOPED_TRACE("AVX2 kernels");
    body();
  }
  lanes::preferSse2ForTests(true);
  {
    SCOPED_TRACE("SSE2 kernels");
    body();
  }
  lanes::preferSse2ForTests(false);
}

TEST(IslandLanes, GiveEachIslandTheBitsOfSolvingItAlone) {
  forEachKernel([&] {
    std::mt19937 rng(58);
    IslandLanes lanes;  // one instance across trials: its rows are reused, as on a worker thread
    uint32_t trials = 0, rolled = 0, clampedCone = 0;
    for (int trial = 0; trial < 400; ++trial) {
      const float scale = std::pow(10.f, float(int(rng() % 13)) - 6.f);  // 1e-6 .. 1e6
      const uint32_t islandCount = 1 + uint32_t(rng() % IslandLanes::kLanes);
      Scene ref = randomScene(rng, islandCount, scale);
      Scene laned = ref;
      const bool relax = rng() % 3 == 0;
      const bool warmStart = !relax && rng() % 4 != 0;
      const int iterations = 1 + int(rng() % 10);
      solveAlone(ref, warmStart, relax, iterations);
      std::vector<std::span<const uint32_t>> spans;
      for (const std::vector<uint32_t>& island : laned.islands) spans.emplace_back(island);
      lanes.solve(spans, laned.contacts, laned.extras, laned.bodies, warmStart, relax, iterations);
      ++trials;
      ASSERT_TRUE(sameBits(ref.bodies.data(), laned.bodies.data(), ref.bodies.size() * sizeof(SolverBody)))
          << "trial " << trial << ": bodies differ (scale " << scale << ", " << islandCount << " islands)";
      for (size_t k = 0; k < ref.contacts.size(); ++k) {
        const SolverContact& r = ref.contacts[k];
        const SolverContact& q = laned.contacts[k];
        ASSERT_TRUE(sameBits(&r.lambdaN, &q.lambdaN, 4) && sameBits(&r.lambdaT1, &q.lambdaT1, 4) &&
                    sameBits(&r.lambdaT2, &q.lambdaT2, 4))
            << "trial " << trial << ", contact " << k;
        ASSERT_TRUE(sameBits(&ref.extras[k].lambdaR1, &laned.extras[k].lambdaR1, 4) &&
                    sameBits(&ref.extras[k].lambdaR2, &laned.extras[k].lambdaR2, 4))
            << "trial " << trial << ", contact " << k << "'s rolling impulses";
        rolled += r.rolling > 0.f;
        const float t = std::sqrt(r.lambdaT1 * r.lambdaT1 + r.lambdaT2 * r.lambdaT2);
        clampedCone += r.lambdaN > 0.f && t >= 0.999f * r.friction * r.lambdaN;
      }
    }
    // The cases meant: rolling contacts and friction at its cone, in every run of the test.
    EXPECT_GT(rolled, 1000u);
    EXPECT_GT(clampedCone, 1000u);
    EXPECT_EQ(trials, 400u);
  });
}

bool sameResults(const Scene& a, const Scene& b) {
  if (!sameBits(a.bodies.data(), b.bodies.data(), a.bodies.size() * sizeof(SolverBody))) return false;
  for (size_t k = 0; k < a.contacts.size(); ++k) {
    const SolverContact& r = a.contacts[k];
    const SolverContact& q = b.contacts[k];
    if (!sameBits(&r.lambdaN, &q.lambdaN, 4) || !sameBits(&r.lambdaT1, &q.lambdaT1, 4) || !sameBits(&r.lambdaT2, &q.lambdaT2, 4) ||
        !sameBits(&a.extras[k].lambdaR1, &b.extras[k].lambdaR1, 4) || !sameBits(&a.extras[k].lambdaR2, &b.extras[k].lambdaR2, 4))
      return false;
  }
  return true;
}

// One pile regrouped by level (solveOne): piles of 2-200 bodies and up to 600 contacts, from
// chains (every contact waits on the one before: solveOne declines) to wide heaps (most rows
// full). Whether it declines or solves, the result is the island's alone, bit for bit.
TEST(IslandLanes, RegroupAPileByLevelWithTheBitsOfSolvingItAlone) {
  forEachKernel([&] {
    std::mt19937 rng(59);
    IslandLanes lanes;
    uint32_t solved = 0, declined = 0;
    for (int trial = 0; trial < 300; ++trial) {
      const float scale = std::pow(10.f, float(int(rng() % 13)) - 6.f);
      const uint32_t bodies = 2 + uint32_t(rng() % 200);
      Scene ref = randomScene(rng, 1, scale, bodies, 1 + uint32_t(rng() % 600));
      Scene laned = ref;
      const bool relax = rng() % 3 == 0;
      const bool warmStart = !relax && rng() % 4 != 0;
      const int iterations = 1 + int(rng() % 10);
      solveAlone(ref, warmStart, relax, iterations);
      if (lanes.solveOne(laned.islands[0], laned.contacts, laned.extras, laned.bodies, warmStart, relax, iterations)) {
        ++solved;
      } else {
        ++declined;
        solveAlone(laned, warmStart, relax, iterations);  // declined: nothing may have changed
      }
      ASSERT_TRUE(sameResults(ref, laned)) << "trial " << trial << " (" << bodies << " bodies, " << ref.contacts.size()
                                           << " contacts, scale " << scale << ")";
    }
    // Both outcomes, often.
    EXPECT_GT(solved, 100u);
    EXPECT_GT(declined, 20u);
  });
}

// A static or kinematic body several islands share is read in several lanes of one row and
// must never be written, even when every lane's contact pushes on it.
TEST(IslandLanes, NeverWriteABodyThatIsNotDynamic) {
  forEachKernel([&] {
    std::mt19937 rng(7);
    for (int trial = 0; trial < 50; ++trial) {
      Scene s = randomScene(rng, IslandLanes::kLanes, 1.f);
      std::vector<SolverBody> before = s.bodies;
      std::vector<std::span<const uint32_t>> spans;
      for (const std::vector<uint32_t>& island : s.islands) spans.emplace_back(island);
      IslandLanes lanes;
      lanes.solve(spans, s.contacts, s.extras, s.bodies, true, false, 8);
      for (size_t i = 0; i < s.bodies.size(); ++i)
        if (!before[i].dynamic) {
          EXPECT_TRUE(sameBits(&before[i], &s.bodies[i], sizeof(SolverBody))) << "body " << i;
        }
    }
  });
}

}  // namespace
}  // namespace bw
