// Sweep and prune against brute force over all pairs: random, clustered and far-from-origin
// bodies, moving frame to frame, with static bodies that must never pair with each other.
#include <gtest/gtest.h>

#include "collision/core/argument_checks.h"
#include "collision/core/seeded_random.h"
#include "world/broadphase.h"

namespace bw {
namespace {

std::vector<BodyPair> bruteForce(const std::vector<WorldAabb>& b, const std::vector<uint8_t>& st) {
  std::vector<BodyPair> out;
  for (uint32_t i = 0; i < b.size(); ++i)
    for (uint32_t j = i + 1; j < b.size(); ++j)
      if (!(st[i] && st[j]) && b[i].overlaps(b[j])) out.push_back({i, j});
  return out;
}

TEST(SweepAndPrune, MatchesBruteForceWhileBodiesMove) {
  for (const double offset : {0.0, 1e7}) {
    SeededRandom r(offset == 0 ? 1 : 2);
    const uint32_t n = 1500;
    std::vector<WorldAabb> b(n);
    std::vector<Vec3d> vel(n);
    std::vector<uint8_t> st(n);
    for (uint32_t i = 0; i < n; ++i) {
      const Vec3d c = Vec3d(r.normal() * 30, r.normal() * 30, r.uniform(0, 40)) + Vec3d::Constant(offset);
      const Vec3d h = i % 50 == 0 ? Vec3d(60, 60, 2) : Vec3d::Constant(r.logUniform(0.1, 2));  // some huge static grids
      b[i] = {c - h, c + h};
      st[i] = i % 50 == 0 || i % 7 == 0;
      vel[i] = st[i] ? Vec3d::Zero() : Vec3d(r.normal(), r.normal(), -r.unit() * 2);
    }
    SweepAndPrune sap;
    std::vector<BodyPair> pairs;
    for (int frame = 0; frame < 30; ++frame) {
      sap.update(b, st, pairs);
      ASSERT_EQ(pairs, bruteForce(b, st)) << "frame " << frame;
      if (frame == 0) {
        EXPECT_GT(pairs.size(), 100u);
      }
      for (uint32_t i = 0; i < n; ++i) {
        b[i].min += vel[i] * 0.1;
        b[i].max += vel[i] * 0.1;
      }
    }
    // A fresh instance (no temporal coherence) gives the same pairs: output depends only on bounds.
    SweepAndPrune fresh;
    std::vector<BodyPair> again;
    fresh.update(b, st, again);
    sap.update(b, st, pairs);
    EXPECT_EQ(again, pairs);
  }
}

TEST(SweepAndPrune, BodiesThatJumpFarAreSortedInBulkWithTheSamePairs) {
  // Half the bodies teleport every frame (respawned rubble, poses set from outside): the
  // insertion sort gives up and sorts in bulk; the pairs must still equal brute force.
  SeededRandom r(5);
  const uint32_t n = 2000;
  std::vector<WorldAabb> b(n);
  std::vector<uint8_t> st(n, 0);
  auto place = [&](uint32_t i) {
    const Vec3d c(r.uniform(-50, 50), r.uniform(-50, 50), r.uniform(0, 20));
    const Vec3d h = Vec3d::Constant(r.logUniform(0.2, 3));
    b[i] = {c - h, c + h};
  };
  for (uint32_t i = 0; i < n; ++i) place(i);
  SweepAndPrune sap;
  std::vector<BodyPair> pairs;
  for (int frame = 0; frame < 10; ++frame) {
    sap.update(b, st, pairs);
    ASSERT_EQ(pairs, bruteForce(b, st)) << "frame " << frame;
    for (uint32_t i = frame % 2; i < n; i += 2) place(i);
  }
}

TEST(SweepAndPrune, BadBoundsAreRejectedNamingTheBody) {
  SweepAndPrune sap;
  std::vector<BodyPair> pairs;
  std::vector<WorldAabb> b{{Vec3d(0, 0, 0), Vec3d(1, 1, 1)}, {Vec3d(0, std::nan(""), 0), Vec3d(1, 1, 1)}};
  try {
    sap.update(b, {0, 0}, pairs);
    FAIL();
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("body 1"), std::string::npos) << e.what();
  }
  b[1] = {Vec3d(2, 0, 0), Vec3d(1, 1, 1)};
  EXPECT_THROW(sap.update(b, {0, 0}, pairs), InvalidInput);
  EXPECT_THROW(sap.update(b, {0}, pairs), InvalidInput);
}

}  // namespace
}  // namespace bw
