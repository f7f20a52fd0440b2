// The 8-node tests behind every OctoBVH query (octobvh_queries.h): the SSE2 forms equal the
// portable ones bit for bit, and the ray form equals intersectRayAabb node by node, on seeded
// clusters with empty, flat, huge and far-from-origin nodes, rays along axes and sweeps.
#include <bit>
#include <cstring>
#include <gtest/gtest.h>
#include <limits>

#include "collision/core/seeded_random.h"
#include "collision/index/octobvh.h"

namespace bw {
namespace {

using octobvh::NodeCluster;

float coordinate(SeededRandom& r, float centre) {
  return centre + float(r.uniform(-1, 1) * std::pow(10.0, r.uniform(-2, 2.7)));
}

NodeCluster randomCluster(SeededRandom& r, float centre) {
  NodeCluster c{};
  for (int o = 0; o < 8; ++o) {
    Aabb b;
    if (r.below(8) == 0) {
      b = Aabb::empty();
    } else {
      for (int a = 0; a < 3; ++a) {
        const float x = coordinate(r, centre), y = r.below(5) == 0 ? x : coordinate(r, centre);  // flat on some axes
        b.min[a] = std::min(x, y);
        b.max[a] = std::max(x, y);
      }
    }
    c.setBounds(o, b);
    c.filter[o] = r.below(6) == 0 ? 0u : 1u << r.below(3);
  }
  return c;
}

uint32_t bitsOf(float f) { return std::bit_cast<uint32_t>(f); }

TEST(OctoBvhNodeTests, SimdFormsEqualThePortableOnesAndTheScalarSlabTest) {
  SeededRandom r(20);
  int rayHits = 0, overlapHits = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const float centre = trial % 3 == 0 ? 7.5e5f : 0.f;
    const NodeCluster c = randomCluster(r, centre);
    const uint32_t mask = trial % 4 == 0 ? ~0u : 1u << r.below(3);

    Aabb box;
    for (int a = 0; a < 3; ++a) {
      const float x = coordinate(r, centre), h = float(r.logUniform(0.01, 300));
      box.min[a] = x - h;
      box.max[a] = x + h;
    }
    unsigned candA = 0, candB = 0;
    const unsigned ovA = octobvh_detail::overlapMask(c, box, mask, candA);
    const unsigned ovB = octobvh_detail::overlapMaskPortable(c, box, mask, candB);
    ASSERT_EQ(ovA, ovB) << "trial " << trial;
    ASSERT_EQ(candA, candB);
    overlapHits += std::popcount(ovA);

    Vec3f origin(coordinate(r, centre), coordinate(r, centre), coordinate(r, centre));
    Vec3f dir(float(r.normal()), float(r.normal()), float(r.normal()));
    if (trial % 5 == 0) dir[r.below(3)] = 0.f;  // parallel to a slab
    if (trial % 11 == 0) dir = Vec3f::Zero(), dir[r.below(3)] = 1.f;
    const float limit = trial % 4 == 0 ? std::numeric_limits<float>::infinity() : float(r.logUniform(0.1, 3000));
    const Vec3f grow = trial % 2 ? Vec3f::Zero() : Vec3f(float(r.uniform(0, 3)), float(r.uniform(0, 3)), float(r.uniform(0, 3)));
    const Ray ray = Ray::make(origin, dir.normalized(), limit);
    const auto slabs = octobvh_detail::RaySlabs::of(ray, grow);
    for (bool ties : {false, true}) {
      float tA[8], tB[8];
      const unsigned hA = octobvh_detail::rayMask(c, slabs, limit, ties, mask, tA, candA);
      const unsigned hB = octobvh_detail::rayMaskPortable(c, slabs, limit, ties, mask, tB, candB);
      ASSERT_EQ(hA, hB) << "trial " << trial;
      ASSERT_EQ(candA, candB);
      for (int o = 0; o < 8; ++o) {
        if (!(candA >> o & 1u) || c.isEmpty(o) || c.bounds(o).isEmpty()) continue;
        float te = -1.f;
        const bool scalar = intersectRayAabb(ray, c.bounds(o).expanded(grow), 0.f, limit, te) && !(ties && te == limit);
        ASSERT_EQ(bool(hA >> o & 1u), scalar) << "trial " << trial << " node " << o;
        if (!scalar) continue;
        ASSERT_EQ(bitsOf(tA[o]), bitsOf(te)) << "trial " << trial << " node " << o;
        ASSERT_EQ(bitsOf(tB[o]), bitsOf(te));
        ++rayHits;
      }
    }
  }
  EXPECT_GT(rayHits, 2000);  // the cases above must include many hits, not only misses
  EXPECT_GT(overlapHits, 2000);
}

}  // namespace
}  // namespace bw
