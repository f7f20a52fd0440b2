// reduceManifold (collision/bricks/brick_narrowphase.h) directly, on seeded random contact sets:
// it keeps at most maxOut contacts, all taken from the input (no copies, no invented points), the
// deepest first, then the one farthest from it, then the one spanning the largest triangle with
// those two; on a face patch (a rectangle's four corners among interior points) it keeps exactly
// the four corners, i.e. the whole area; and it is a pure function of its input (order included).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <gtest/gtest.h>
#include <vector>

#include "collision/bricks/brick_narrowphase.h"
#include "collision/core/seeded_random.h"

namespace bw {
namespace {

bool sameContact(const LocalContact& a, const LocalContact& b) {
  return a.position == b.position && a.normal == b.normal && a.depth == b.depth && a.feature == b.feature &&
         a.material == b.material;
}

// n contacts spread over a random patch of size `scale` (a plane with some depth noise, or a
// blob), with distinct features so each keeps its identity.
std::vector<LocalContact> randomContacts(SeededRandom& r, int n, float scale) {
  std::vector<LocalContact> c;
  const Vec3f normal = Vec3f(float(r.normal()), float(r.normal()), float(r.normal())).normalized();
  const bool planar = r.below(2) == 0;
  for (int i = 0; i < n; ++i) {
    Vec3f p = Vec3f(float(r.uniform(-1, 1)), float(r.uniform(-1, 1)), float(r.uniform(-1, 1))) * scale;
    if (planar) p -= normal * normal.dot(p);
    c.push_back({p, normal, float(r.uniform(-0.01, 0.05)) * scale, uint32_t(i), uint32_t(r.below(4))});
  }
  return c;
}

TEST(ManifoldReduction, KeepsAtMostMaxOutOfTheInputDeepestFirstThenFarthestThenLargestTriangle) {
  SeededRandom r(1201);
  int reduced = 0;
  for (int k = 0; k < 2000; ++k) {
    const int n = 1 + int(r.below(40));
    const int maxOut = 1 + int(r.below(4));
    const float scale = float(r.logUniform(0.2, 500));
    const std::vector<LocalContact> input = randomContacts(r, n, scale);
    std::vector<LocalContact> c = input;
    const int kept = reduceManifold(c.data(), n, maxOut);
    ASSERT_EQ(kept, std::min(n, maxOut)) << "case " << k;
    if (n <= maxOut) {  // nothing to reduce: untouched, same order
      for (int i = 0; i < n; ++i) ASSERT_TRUE(sameContact(c[size_t(i)], input[size_t(i)])) << "case " << k;
      continue;
    }
    ++reduced;
    // Every kept contact is one input contact, each at most once (features are distinct).
    std::vector<uint32_t> features;
    for (int i = 0; i < kept; ++i) {
      const LocalContact& x = c[size_t(i)];
      ASSERT_LT(x.feature, uint32_t(n)) << "case " << k;
      ASSERT_TRUE(sameContact(x, input[x.feature])) << "case " << k << ": kept contact " << i << " was altered";
      features.push_back(x.feature);
    }
    std::sort(features.begin(), features.end());
    ASSERT_EQ(std::unique(features.begin(), features.end()), features.end()) << "case " << k << ": a contact kept twice";
    // The whole array is still a permutation of the input (nothing lost from the tail either).
    std::vector<uint32_t> all;
    for (const LocalContact& x : c) all.push_back(x.feature);
    std::sort(all.begin(), all.end());
    for (int i = 0; i < n; ++i) ASSERT_EQ(all[size_t(i)], uint32_t(i)) << "case " << k;
    // 1. the deepest contact is kept, first.
    float deepest = -1e30f;
    for (const LocalContact& x : input) deepest = std::max(deepest, x.depth);
    ASSERT_EQ(c[0].depth, deepest) << "case " << k;
    if (maxOut < 2) continue;
    // 2. then the contact farthest from it.
    float farthest = 0;
    for (const LocalContact& x : input) farthest = std::max(farthest, (x.position - c[0].position).squaredNorm());
    ASSERT_EQ((c[1].position - c[0].position).squaredNorm(), farthest) << "case " << k;
    if (maxOut < 3) continue;
    // 3. then the one spanning the largest triangle with those two.
    const Vec3f e = c[1].position - c[0].position;
    float largest = 0;
    for (const LocalContact& x : input) largest = std::max(largest, e.cross(x.position - c[0].position).squaredNorm());
    ASSERT_EQ(e.cross(c[2].position - c[0].position).squaredNorm(), largest) << "case " << k;
    if (maxOut < 4) continue;
    // 4. the fourth adds area: no dropped contact lies farther outside the kept triangle's edges.
    float fourth = 0;
    for (int a = 0; a < 3; ++a)
      fourth = std::max(fourth, (c[size_t((a + 1) % 3)].position - c[size_t(a)].position)
                                    .cross(c[3].position - c[size_t(a)].position)
                                    .squaredNorm());
    for (int i = 4; i < n; ++i) {
      float s = 0;
      for (int a = 0; a < 3; ++a)
        s = std::max(s, (c[size_t((a + 1) % 3)].position - c[size_t(a)].position)
                            .cross(c[size_t(i)].position - c[size_t(a)].position)
                            .squaredNorm());
      ASSERT_LE(s, fourth) << "case " << k << ": dropped contact " << i << " would add more area";
    }
  }
  EXPECT_GT(reduced, 1000);
}

// A box face resting on a brick: the contacts are the patch's four corners and points inside it.
// Whatever the patch's size, orientation and the interior points, with the deepest contact at a
// corner the reduction keeps exactly the four corners: the manifold keeps the patch's full area.
TEST(ManifoldReduction, FacePatchKeepsItsFourCornersAndTheirArea) {
  SeededRandom r(1301);
  for (int k = 0; k < 500; ++k) {
    const float hx = float(r.logUniform(0.1, 250)), hy = float(r.logUniform(0.1, 250));
    const Quatf q = Quatf(float(r.normal()), float(r.normal()), float(r.normal()), float(r.normal())).normalized();
    const Vec3f origin(float(r.uniform(-100, 100)), float(r.uniform(-100, 100)), float(r.uniform(-100, 100)));
    const Vec3f normal = q * Vec3f::UnitZ();
    std::vector<LocalContact> c;
    const Vec3f corners[4] = {{-hx, -hy, 0}, {hx, -hy, 0}, {hx, hy, 0}, {-hx, hy, 0}};
    const int interior = 4 + int(r.below(28));
    const uint32_t deepCorner = r.below(4);
    for (int i = 0; i < interior; ++i) {
      const Vec3f p(float(r.uniform(-0.95, 0.95)) * hx, float(r.uniform(-0.95, 0.95)) * hy, 0.f);
      c.push_back({origin + q * p, normal, float(r.uniform(0, 0.009)), 100u + uint32_t(i), 0});
    }
    for (uint32_t i = 0; i < 4; ++i) {
      const float depth = i == deepCorner ? 0.01f : float(r.uniform(0, 0.009));
      // corners at random places in the input order
      c.insert(c.begin() + r.below(uint32_t(c.size()) + 1), LocalContact{origin + q * corners[i], normal, depth, i, 0});
    }
    const int kept = reduceManifold(c.data(), int(c.size()), 4);
    ASSERT_EQ(kept, 4);
    EXPECT_EQ(c[0].feature, deepCorner) << "case " << k;
    std::vector<uint32_t> features;
    for (int i = 0; i < 4; ++i) features.push_back(c[size_t(i)].feature);
    std::sort(features.begin(), features.end());
    EXPECT_EQ(features, (std::vector<uint32_t>{0, 1, 2, 3})) << "case " << k << ": an interior point replaced a corner";
  }
}

TEST(ManifoldReduction, IsAPureFunctionOfItsInput) {
  SeededRandom r(1401);
  for (int k = 0; k < 300; ++k) {
    const int n = 5 + int(r.below(30));
    const std::vector<LocalContact> input = randomContacts(r, n, float(r.logUniform(0.2, 500)));
    std::vector<LocalContact> a = input, b = input;
    const int ka = reduceManifold(a.data(), n, 4), kb = reduceManifold(b.data(), n, 4);
    ASSERT_EQ(ka, kb);
    for (int i = 0; i < ka; ++i) ASSERT_TRUE(sameContact(a[size_t(i)], b[size_t(i)])) << "case " << k;
    // Reducing a reduced manifold again changes nothing.
    std::vector<LocalContact> again(a.begin(), a.begin() + ka);
    ASSERT_EQ(reduceManifold(again.data(), ka, 4), ka);
    for (int i = 0; i < ka; ++i) ASSERT_TRUE(sameContact(again[size_t(i)], a[size_t(i)])) << "case " << k;
  }
}

}  // namespace
}  // namespace bw

namespace bw {
namespace {

// A box falling beside a wall: four wall contacts nearer (smaller gaps) than the floor's. The
// reduction keeps each direction's own manifold, so the floor is held however near the wall is
// (reduced together, the four slots went to the wall and the box fell through the floor).
TEST(ManifoldReduction, EachNormalDirectionKeepsItsOwnContacts) {
  std::vector<LocalContact> c;
  for (int i = 0; i < 6; ++i)  // wall x = 0, normal +x, gaps 0.05..0.10
    c.push_back({Vec3f(0.f, 0.1f * float(i), 0.3f), Vec3f::UnitX(), -0.05f - 0.01f * float(i), uint32_t(i), 0});
  for (int i = 0; i < 6; ++i)  // floor z = 0, normal +z, gaps 0.40..0.45
    c.push_back({Vec3f(0.2f + 0.1f * float(i % 3), 0.1f * float(i / 3), 0.f), Vec3f::UnitZ(), -0.40f - 0.01f * float(i), uint32_t(10 + i), 0});
  // A contact of a third direction (a neighbouring brick's edge) forms a group of its own.
  c.push_back({Vec3f(0.5f, 0.5f, 0.f), Vec3f(0.f, 0.6f, 0.8f).normalized(), -0.5f, 20u, 0});
  const int kept = reduceManifold(c.data(), int(c.size()), 4);
  int wall = 0, floor = 0;
  for (int i = 0; i < kept; ++i) (c[size_t(i)].normal.x() > 0.9f ? wall : floor)++;
  EXPECT_EQ(wall, 4);
  EXPECT_GE(floor, 1);
  EXPECT_LE(kept, 4 * kManifoldNormalGroups);
  // The deepest contact of all comes first.
  EXPECT_EQ(c[0].feature, 0u);
}

}  // namespace
}  // namespace bw
