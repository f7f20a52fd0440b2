// Sweep and prune against brute force over all pairs: random, clustered and far-from-origin
// bodies, moving frame to frame, with static bodies that must never pair with each other.
#include <gtest/gtest.h>

#include "collision/core/argument_checks.h"
#include "collision/core/seeded_random.h"
#include "world/broadphase.h"
#include "world/static_bounds_tree.h"

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

// Random boxes from 0.2 m to 500 m, thin plates, identical copies, far from the origin.
std::vector<WorldAabb> adversarialBoxes(SeededRandom& r, uint32_t n, double offset) {
  std::vector<WorldAabb> b;
  for (uint32_t i = 0; i < n; ++i) {
    const Vec3d c = Vec3d(r.normal() * 200, r.normal() * 200, r.uniform(-20, 60)) + Vec3d::Constant(offset);
    Vec3d h = Vec3d::Constant(r.logUniform(0.1, 250));
    if (i % 9 == 0) h[i % 3] = 0.001;  // a thin plate
    b.push_back({c - h, c + h});
    if (i % 17 == 0 && !b.empty()) b.push_back(b.front());  // identical boxes
  }
  return b;
}

TEST(StaticBoundsTree, QueriesMatchBruteForce) {
  for (const double offset : {0.0, 1e7}) {
    SeededRandom r(offset == 0 ? 21 : 22);
    for (const uint32_t n : {0u, 1u, 4u, 5u, 1000u}) {
      const std::vector<WorldAabb> boxes = adversarialBoxes(r, n, offset);
      std::vector<uint32_t> ids;
      for (uint32_t k = 0; k < boxes.size(); ++k) ids.push_back(1000 + 3 * k);
      StaticBoundsTree tree;
      tree.build(boxes, ids);
      EXPECT_EQ(tree.size(), boxes.size());
      for (const WorldAabb& q : adversarialBoxes(r, 200, offset)) {
        std::vector<uint32_t> found, expected;
        tree.query(q, [&](uint32_t id) { found.push_back(id); });
        for (uint32_t k = 0; k < boxes.size(); ++k)
          if (boxes[k].overlaps(q)) expected.push_back(ids[k]);
        std::sort(found.begin(), found.end());
        ASSERT_EQ(found, expected) << n << " boxes, offset " << offset;
      }
    }
  }
  StaticBoundsTree tree;
  EXPECT_THROW(tree.build({WorldAabb{}}, {}), InvalidInput);
}

// Proxies with owners (a static grid enters as many cover boxes): pairs of owners, each once,
// none of an owner with itself, equal to brute force over the proxies mapped to owners; the
// static tree is rebuilt exactly when a static box or the static set changes.
TEST(SweepAndPrune, OwnersOfSeveralProxiesPairOnceAndStaticChangesRebuildTheTree) {
  SeededRandom r(31);
  std::vector<WorldAabb> b;
  std::vector<uint8_t> st;
  std::vector<uint32_t> owner;
  uint32_t owners = 0;
  for (uint32_t body = 0; body < 600; ++body, ++owners) {
    const bool grid = body % 100 == 0;  // a static grid: 40 cover boxes along a street
    const uint32_t boxes = grid ? 40 : body % 37 == 0 ? 3 : 1;  // some moving bodies with 3 proxies
    const Vec3d base(r.uniform(-40, 40), r.uniform(-40, 40), r.uniform(0, 8));
    for (uint32_t k = 0; k < boxes; ++k) {
      const Vec3d c = base + Vec3d(grid ? 4.0 * k : 0.3 * k, 0, 0);
      const Vec3d h = grid ? Vec3d(2.5, 3, 1) : Vec3d::Constant(r.logUniform(0.2, 3));
      b.push_back({c - h, c + h});
      st.push_back(grid || body % 13 == 0);
      owner.push_back(body);
    }
  }
  auto expected = [&] {
    std::vector<BodyPair> out;
    for (uint32_t i = 0; i < b.size(); ++i)
      for (uint32_t j = i + 1; j < b.size(); ++j)
        if (!(st[i] && st[j]) && owner[i] != owner[j] && b[i].overlaps(b[j]))
          out.push_back({std::min(owner[i], owner[j]), std::max(owner[i], owner[j])});
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  };
  SweepAndPrune sap;
  std::vector<BodyPair> pairs;
  sap.update(b, st, pairs, nullptr, nullptr, -1, &owner);
  EXPECT_EQ(pairs, expected());
  EXPECT_GT(pairs.size(), 50u);
  EXPECT_EQ(sap.staticBuilds(), 1u);
  for (int frame = 0; frame < 5; ++frame) {
    for (uint32_t i = 0; i < b.size(); ++i)
      if (!st[i]) {
        const Vec3d d(r.normal() * 0.3, r.normal() * 0.3, -0.2);
        b[i].min += d;
        b[i].max += d;
      }
    sap.update(b, st, pairs, nullptr, nullptr, -1, &owner);
    ASSERT_EQ(pairs, expected()) << "frame " << frame;
  }
  EXPECT_EQ(sap.staticBuilds(), 1u);  // moving bodies only: the tree stays
  b[0].max.x() += 5;                   // a static grid edited: one cover box grew
  sap.update(b, st, pairs, nullptr, nullptr, -1, &owner);
  EXPECT_EQ(pairs, expected());
  EXPECT_EQ(sap.staticBuilds(), 2u);
  uint32_t moving = 0;
  while (st[moving]) ++moving;
  st[moving] = 1;  // a body came to rest as static: both the sweep's set and the tree change
  sap.update(b, st, pairs, nullptr, nullptr, -1, &owner);
  EXPECT_EQ(pairs, expected());
  EXPECT_EQ(sap.staticBuilds(), 3u);
  std::vector<uint32_t> shortOwners(b.size() - 1, 0);
  EXPECT_THROW(sap.update(b, st, pairs, nullptr, nullptr, -1, &shortOwners), InvalidInput);
}

}  // namespace
}  // namespace bw
