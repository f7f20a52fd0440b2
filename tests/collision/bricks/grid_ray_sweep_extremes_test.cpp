// Rays and sweeps through a BrickGrid at the extremes: lattice planes, shared edges and corners,
// degenerate and huge directions (split from the former collision extremes_test.cpp).
//
// Guarantees these tests establish (seeded, deterministic; each one can fail):
// Rays and sweeps (BrickGrid)
// - Tie rule: brick shapes are closed, so a ray that only touches a face, edge or corner hits.
//   The grid's traversal is conservative (bounds grown by a few ulps of the largest coordinate),
//   so raycast returns exactly the smallest rayBrick() t over every brick, and among bricks tied
//   at that t the one with the lowest OctoBVH handle (= lowest brick id when bricks were only
//   placed). Sweeps return exactly the smallest sweepShapeBrick() fraction, same tie rule.
// - Directions may be unnormalised, with zero, denormal (1e-40) and huge (1e30) components: no
//   NaN, hit normals unit length, no crash or endless loop. A direction with every component
//   zero or denormal is refused.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <gtest/gtest.h>
#include <string>
#include <vector>

#include "collision/bricks/brick_grid.h"
#include "collision/core/argument_checks.h"
#include "collision/core/seeded_random.h"
#include "collision/support/extremes_support.h"

namespace bw {
namespace {

using namespace test;  // the shared brute-force helpers (collision/support/extremes_support.h)

// Unit cubes [x,x+1]x[y,y+1]x[z,z+1] on a 6x6x3 lattice with seeded holes; a solid 2x2x2 block
// over [10,12]x[0,2]x[0,2] whose centre (11,1,1) is a corner shared by 8 bricks; a row of unit
// wedges in every rotation along y in [-3,-2]. Every face lies on an integer lattice plane.
void buildLattice(BrickGrid& grid) {
  SeededRandom r(41);
  for (int x = 0; x < 6; ++x)
    for (int y = 0; y < 6; ++y)
      for (int z = 0; z < 3; ++z)
        if (r.unit() > 0.15) grid.placeBrick(Brick::box(Vec3f(x + 0.5f, y + 0.5f, z + 0.5f), Vec3f::Constant(0.5f)));
  for (int i = 0; i < 8; ++i)
    grid.placeBrick(Brick::box(Vec3f(10.5f + (i & 1), 0.5f + ((i >> 1) & 1), 0.5f + (i >> 2)), Vec3f::Constant(0.5f)));
  for (int k = 0; k < 24; ++k) {
    Brick w = Brick::box(Vec3f(k * 0.5f + 0.5f, -2.5f, 0.5f), Vec3f::Constant(0.5f));  // overlapping neighbours
    w.shape = k % 3 == 0 ? BrickShape::CornerWedge : BrickShape::Wedge;
    w.rotation = AxisRotation::fromIndex(k);
    grid.placeBrick(w);
  }
}

TEST(ExtremesRays, AlongLatticePlanesThroughSharedEdgesAndCornersMatchBruteForce) {
  BrickGrid grid;
  buildLattice(grid);
  int hits = 0;
  auto check = [&](const Vec3f& o, const Vec3f& d, float maxT = kInf) {
    const Ray ray = Ray::make(o, d, maxT);
    expectRayMatches(grid, ray, describeRay(ray), hits);
  };
  // Along face planes and edge lines of the lattice (origins on integer planes, axis directions).
  for (int y = -3; y <= 6; ++y)
    for (int z = 0; z <= 3; ++z)
      for (float off : {0.f, 0.5f}) {
        check(Vec3f(-2, y + off, float(z)), Vec3f(1, 0, 0));
        check(Vec3f(14, y + off, float(z)), Vec3f(-1, -0.f, 0));
        check(Vec3f(-2, float(y), z + off), Vec3f(1, 0, 0));
        check(Vec3f(y + off, -4, float(z)), Vec3f(0, 1, 0));
        check(Vec3f(-2, y - 2.f, float(z)), Vec3f(1, 1, 0));  // diagonal inside a z plane
      }
  // Aimed exactly at a top edge shared by two bricks, and at a top corner shared by four:
  // origin P + 6 (-1, 0, 1), direction (1, 0, -1) reaches P at t = 6 in exact arithmetic.
  for (int x = 1; x < 6; ++x)
    for (int y = 1; y < 6; ++y) {
      check(Vec3f(x - 6.f, y + 0.5f, 9.f), Vec3f(1, 0, -1));
      check(Vec3f(x - 6.f, float(y), 9.f), Vec3f(1, 0, -1));
      check(Vec3f(x - 6.f, y - 6.f, 9.f), Vec3f(1, 1, -1));
    }
  // The corner shared by 8 bricks: rays from it (t = 0 on all 8) and along the 4-brick edge
  // lines through it (entering where 4 bricks meet).
  for (const Vec3f& d : {Vec3f(1, 0, 0), Vec3f(-1, -1, 0), Vec3f(1, 1, 1), Vec3f(1e-40f, 0, -1), Vec3f(1e30f, 0, 1)})
    check(Vec3f(11, 1, 1), d);
  check(Vec3f(7, 1, 1), Vec3f(1, 0, 0));
  check(Vec3f(11, 1, -5), Vec3f(0, 0, 1));
  check(Vec3f(11, 5, 1), Vec3f(0, -1, 0));
  check(Vec3f(7, -3, 1), Vec3f(1, 1, 0));  // through the edge line (10,0..2,1) at its end corner

  // Random lattice rays: origins and targets on the half-integer lattice, so many rays run in
  // face planes and through shared edges and corners; directions with zero, denormal (1e-40)
  // and huge (1e30) components, not normalised.
  SeededRandom r(42);
  auto lattice = [&](double lo, double hi) { return float(std::floor(r.uniform(lo, hi) * 2) / 2); };
  for (int k = 0; k < 3000; ++k) {
    const Vec3f o(lattice(-3, 14), lattice(-4, 8), lattice(-2, 5));
    const Vec3f target(lattice(0, 12.5), lattice(-3, 6.5), lattice(0, 3.5));
    Vec3f d = target - o;
    if (d.isZero()) continue;
    float scale = 1.f;
    switch (k % 6) {
      case 1:
        for (int i = 0; i < 3; ++i)
          if (d[i] == 0.f) d[i] = (r.below(2) ? 1e-40f : -1e-40f);
        break;
      case 2: scale = 1e30f; break;
      case 3: scale = 1e-30f; break;
      case 4: {
        int a;
        d.cwiseAbs().maxCoeff(&a);
        d[a] = d[a] > 0 ? 1e30f : -1e30f;
        break;
      }
      case 5: {
        const int a = int(r.below(3));
        d = Vec3f::Zero();
        d[a] = r.below(2) ? 1.f : -1.f;
        break;
      }
      default: break;
    }
    d *= scale;
    const float maxT = k % 4 == 0 ? float(r.uniform(0.2, 1.5)) / scale : kInf;
    check(o, d, maxT);
  }
  EXPECT_GT(hits, 1500);

  // Overlap boxes whose faces lie on the same lattice planes: closed boxes, so touching counts.
  int touching = 0;
  for (int k = 0; k < 2000; ++k) {
    const Vec3f a(lattice(-2, 13), lattice(-4, 7), lattice(-1, 4));
    const Vec3f b = a + Vec3f(lattice(0, 3), lattice(0, 3), lattice(0, 3));
    const Aabb box{a, b};
    std::vector<uint32_t> got, expected;
    grid.overlapBricks(box, ~0u, got);
    grid.forEachBrick([&](uint32_t id) {
      const Aabb bb = brickBounds(grid.brick(id));
      if (bb.overlaps(box)) expected.push_back(id);
      touching += bb.overlaps(box) && (bb.min.array() == box.max.array() || bb.max.array() == box.min.array()).any();
    });
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, expected) << "box " << a.transpose() << " .. " << b.transpose();
  }
  EXPECT_GT(touching, 1000);
}

TEST(ExtremesSweeps, AlongLatticePlanesAndWithExtremeMotionsMatchBruteForce) {
  BrickGrid grid;
  buildLattice(grid);
  int hits = 0;
  auto check = [&](const QueryShape& shape, const Quatf& rot, const Vec3f& from, const Vec3f& to) {
    char what[200];
    std::snprintf(what, sizeof what, "sweep from (%.9g %.9g %.9g) to (%.9g %.9g %.9g)", from.x(), from.y(), from.z(),
                  to.x(), to.y(), to.z());
    const GridSweepHit h = grid.sweep(shape, rot, from, to, ~0u);
    const BruteSweepHit ref = bruteSweep(grid, shape, rot, from, to);
    ASSERT_EQ(h.hit(), ref.hit() && ref.fraction <= 1.f) << what;
    if (!h.hit()) return;
    ++hits;
    ASSERT_FALSE(std::isnan(h.fraction)) << what;
    ASSERT_EQ(h.fraction, ref.fraction) << what;
    ASSERT_TRUE(isTied(ref.tied, h.brick)) << what << ": " << ref.tied.size() << " tied";
    ASSERT_TRUE(h.normal.allFinite() && h.point.allFinite()) << what;
  };
  const Quatf id = Quatf::Identity();
  const QueryShape cube = QueryShape::box(Vec3f::Constant(0.5f));
  const QueryShape ball = QueryShape::sphere(0.5f);
  // A cube sliding with its bottom face exactly in the lattice's top plane (z = 3), and with its
  // side face in the y = 0 plane: it touches the first brick's edge, it is never inside.
  for (int y = 0; y < 6; ++y) {
    check(cube, id, Vec3f(-3, y + 0.5f, 3.5f), Vec3f(15, y + 0.5f, 3.5f));
    check(cube, id, Vec3f(-3, y + 0.5f, 3.5f), Vec3f(-3 + 1e30f, y + 0.5f, 3.5f));  // huge motion
  }
  check(cube, id, Vec3f(-3, -0.5f, 1.5f), Vec3f(15, -0.5f, 1.5f));
  // Denormal and zero motion components (the ray underneath flags them parallel).
  check(ball, id, Vec3f(-3, 0, 1.5f), Vec3f(15, 1e-40f, 1.5f));
  check(ball, id, Vec3f(0, -3, 0), Vec3f(-1e-40f, 15, 1e-40f));
  check(ball, id, Vec3f(11, 1, 6), Vec3f(11, 1, -6));          // onto the 4-brick top corner
  check(ball, id, Vec3f(11, 1, 6), Vec3f(11 + 1e-40f, 1, -1e30f));
  check(cube, id, Vec3f(8, 1, 1), Vec3f(20, 1, 1));             // along the 4-brick edge line
  check(ball, id, Vec3f(5, 5, 5), Vec3f(5, 5, 5));              // zero motion, not touching
  check(ball, id, Vec3f(5.5f, 5.5f, 3.5f), Vec3f(5.5f, 5.5f, 3.5f));  // zero motion, touching
  SeededRandom r(43);
  auto lattice = [&](double lo, double hi) { return float(std::floor(r.uniform(lo, hi) * 2) / 2); };
  const QueryShape capsule = QueryShape::capsule(0.25f, 0.5f);
  for (int k = 0; k < 160; ++k) {
    const QueryShape& shape = k % 3 == 0 ? cube : (k % 3 == 1 ? ball : capsule);
    const Vec3f from(lattice(-3, 14), lattice(-5, 8), lattice(-2, 6));
    Vec3f to(lattice(-3, 14), lattice(-5, 8), lattice(-2, 6));
    if (k % 4 == 1) to = from + (to - from) * 1e20f;
    if (k % 4 == 2)
      for (int i = 0; i < 3; ++i)
        if (to[i] == from[i] && from[i] == 0.f) to[i] = 1e-40f;
    check(shape, k % 2 ? id : Quatf(Eigen::AngleAxisf(1.5707964f, Vec3f::UnitZ())), from, to);
  }
  EXPECT_GT(hits, 60);
}

}  // namespace
}  // namespace bw
