// Size ratios inside one BrickGrid: microbricks, thin plates and long ramps (split from the
// former collision extremes_test.cpp).
//
// Guarantees these tests establish (seeded, deterministic; each one can fail):
// Sizes
// - Brick half sizes 0.002 .. 2^28 accepted, outside refused; 0.04 microbricks, 0.04-thick
//   plates and 500-long ramps in one grid (ratio 12500) match brute force for raycasts,
//   overlaps, contacts and sweeps; a box resting on a 0.04 plate always gets its contacts
//   (depth within 1e-4), a sphere sweeping through one stops on it, and a 0.06 box touching a
//   microbrick beside a 500 ramp gets the microbrick contact.
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

// 500-long ramps (wedges, half size 250 x 2 x 3) in several rotations, 0.04-thick plates, and
// 0.04 microbricks beside the ramps, on the plates and scattered: size ratio 12500.
struct MixedScaleBuild {
  uint32_t ramp = 0;        // the ramp along x at y in [-2, 2], z in [0, 6]
  uint32_t micro = 0;       // the microbrick at (10, 2.02, 0.02) against that ramp's +y side
  uint32_t plate = 0;       // the 10 x 10 x 0.04 plate at (100, 80, 0.02)
};

MixedScaleBuild buildMixedScale(BrickGrid& grid) {
  MixedScaleBuild ids;
  SeededRandom r(61);
  const Vec3f rampHalf(250.f, 2.f, 3.f);
  for (int k = 0; k < 4; ++k) {
    Brick w = Brick::box(Vec3f(0.f, -30.f + 30.f * k, 3.f), rampHalf);
    w.shape = BrickShape::Wedge;
    w.rotation = k == 1 ? AxisRotation::identity() : AxisRotation::fromIndex(5 * k + 2);
    if (k == 1) w.position.y() = 0.f;
    const uint32_t id = grid.placeBrick(w);
    if (k == 1) ids.ramp = id;
  }
  const Vec3f micro = Vec3f::Constant(0.02f);
  ids.micro = grid.placeBrick(Brick::box(Vec3f(10.f, 2.02f, 0.02f), micro));
  ids.plate = grid.placeBrick(Brick::box(Vec3f(100.f, 80.f, 0.02f), Vec3f(5.f, 5.f, 0.02f)));
  for (int k = 0; k < 400; ++k) {  // a row of microbricks against the ramp's side, a few layers high
    const float x = std::round(float(r.uniform(-240, 240)) / 0.04f) * 0.04f;
    if (std::abs(x - 10.f) < 1.f) continue;
    grid.placeBrick(Brick::box(Vec3f(x, 2.02f, 0.02f + 0.04f * float(r.below(3))), micro));
  }
  for (int k = 0; k < 30; ++k) {  // thin plates, some with microbricks on top
    const Vec3f c(float(r.uniform(-240, 240)), float(r.uniform(-60, 50)), float(r.uniform(0, 8)));
    const Vec3f half(float(r.logUniform(0.5, 20)), float(r.logUniform(0.5, 20)), 0.02f);
    Brick p = Brick::box(c, half);
    p.rotation = AxisRotation::fromIndex(int(r.below(24)));
    grid.placeBrick(p);
    for (int m = 0; m < 20 && p.rotation.index() == AxisRotation().index(); ++m)
      grid.placeBrick(Brick::box(c + Vec3f(float(r.uniform(-half.x(), half.x())), float(r.uniform(-half.y(), half.y())), 0.04f), micro));
  }
  for (int k = 0; k < 600; ++k) {  // scattered microbricks and small bricks of every shape
    Brick b = Brick::box(Vec3f(float(r.uniform(-250, 250)), float(r.uniform(-60, 50)), float(r.uniform(0, 8))),
                         k % 3 ? micro : Vec3f(float(r.logUniform(0.02, 1)), float(r.logUniform(0.02, 1)), float(r.logUniform(0.02, 1))));
    b.shape = BrickShape(r.below(4));
    b.rotation = AxisRotation::fromIndex(int(r.below(24)));
    grid.placeBrick(b);
  }
  return ids;
}

// A point near some brick of the grid (so queries meet geometry of every size).
Vec3f nearSomeBrick(const BrickGrid& grid, SeededRandom& r, float spread) {
  const uint32_t id = r.below(grid.brickCount());
  return grid.brick(id).position + Vec3f(float(r.normal()), float(r.normal()), float(r.normal())) * spread;
}

TEST(ExtremesSizeRatios, MicrobricksPlatesAndLongRampsMatchBruteForce) {
  BrickGrid grid;
  buildMixedScale(grid);
  SeededRandom r(62);
  int rayHits = 0, withContacts = 0;
  std::vector<Vec3f> hull;
  for (int q = 0; q < 300; ++q) {
    // Rays from anywhere to a point near a brick, some axis-aligned.
    const Vec3f target = nearSomeBrick(grid, r, q % 2 ? 0.02f : 1.f);
    const Vec3f o = target + Vec3f(float(r.normal()), float(r.normal()), float(r.normal())) * float(r.logUniform(0.05, 300));
    Vec3f d = target - o;
    if (q % 5 == 0) d = Vec3f::Zero(), d[q % 3] = (q % 2 ? 1.f : -1.f);
    if (d.isZero()) continue;
    const Ray ray = Ray::make(o, d, q % 3 ? kInf : 1.f);
    expectRayMatches(grid, ray, describeRay(ray), rayHits);

    // Overlap boxes from 0.01 to 50.
    const Aabb box = Aabb::fromCenterHalf(nearSomeBrick(grid, r, 0.5f), Vec3f::Constant(float(r.logUniform(0.005, 25))));
    std::vector<uint32_t> got, expected;
    grid.overlapBricks(box, ~0u, got);
    grid.forEachBrick([&](uint32_t id) {
      if (brickBounds(grid.brick(id)).overlaps(box)) expected.push_back(id);
    });
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, expected) << "overlap " << q;

    // Contacts of shapes 0.03 .. 3 against brute force over every brick (LOD off), and with the
    // default LOD never losing a penetrating contact.
    const float size = float(r.logUniform(0.015, 1.5));
    QueryShape shape = QueryShape::box(Vec3f(size, size * 0.7f, size * 0.5f));
    if (q % 3 == 1) shape = QueryShape::sphere(size);
    if (q % 3 == 2) shape = QueryShape::capsule(size * 0.5f, size);
    const LocalPose pose{nearSomeBrick(grid, r, size),
                         Quatf(Eigen::AngleAxisf(float(r.uniform(0, 6.28)), Vec3f(float(r.normal()), float(r.normal()), float(r.normal())).normalized()))};
    ContactParams exact;
    exact.lodFraction = 0.f;
    exact.speculativeMargin = q % 2 ? 0.01f : 0.f;
    std::vector<LocalContact> contacts;
    grid.collideLocal(shape, pose, exact, contacts);
    std::vector<std::pair<uint32_t, float>> a, b;
    for (const LocalContact& c : contacts) a.push_back({c.feature, c.depth});
    LocalContact buf[kMaxContactsPerBrick];
    bool penetrating = false;
    grid.forEachBrick([&](uint32_t id) {
      const int n = collideShapeBrick(shape, pose, grid.brick(id), id, exact.speculativeMargin, buf);
      for (int i = 0; i < n; ++i) b.push_back({buf[i].feature, buf[i].depth}), penetrating |= buf[i].depth > 0.f;
    });
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    ASSERT_EQ(a, b) << "contacts " << q;
    withContacts += !a.empty();
    std::vector<LocalContact> lod;
    grid.collideLocal(shape, pose, ContactParams{}, lod);
    if (penetrating) {
      ASSERT_TRUE(std::any_of(lod.begin(), lod.end(), [](const LocalContact& c) { return c.depth > 0.f; }))
          << "LOD lost every contact, query " << q;
    }
  }
  EXPECT_GT(rayHits, 100);
  EXPECT_GT(withContacts, 60);

  // Sweeps of small and large shapes against brute force.
  int sweepHits = 0;
  for (int q = 0; q < 40; ++q) {
    const float size = float(r.logUniform(0.02, 1));
    const QueryShape shape = q % 2 ? QueryShape::sphere(size) : QueryShape::box(Vec3f::Constant(size));
    const Vec3f to = nearSomeBrick(grid, r, 0.1f);
    const Vec3f from = to + Vec3f(float(r.normal()), float(r.normal()), float(r.normal())) * float(r.logUniform(0.1, 30));
    const GridSweepHit h = grid.sweep(shape, Quatf::Identity(), from, to, ~0u);
    const BruteSweepHit ref = bruteSweep(grid, shape, Quatf::Identity(), from, to);
    ASSERT_EQ(h.hit(), ref.hit() && ref.fraction <= 1.f) << "sweep " << q;
    if (!h.hit()) continue;
    ++sweepHits;
    ASSERT_EQ(h.fraction, ref.fraction) << "sweep " << q;
    ASSERT_TRUE(isTied(ref.tied, h.brick)) << "sweep " << q;
  }
  EXPECT_GT(sweepHits, 15);
}

TEST(ExtremesSizeRatios, BoxOnThinPlateAndSmallBoxOnMicrobrickBesideLongRampGetTheirContacts) {
  BrickGrid grid;
  const MixedScaleBuild ids = buildMixedScale(grid);
  ContactScratch scratch;
  SeededRandom r(63);
  // A box resting 0.005 deep on the 0.04 plate, anywhere on it including overhanging its edges.
  for (int k = 0; k < 40; ++k) {
    const Vec3d c(100 + r.uniform(-5.3, 5.3), 80 + r.uniform(-5.3, 5.3), 0.04 + 0.25 - 0.005);
    const Quatf spin(Eigen::AngleAxisf(float(r.uniform(0, 6.28)), Vec3f::UnitZ()));
    std::vector<Contact> contacts;
    const size_t n = grid.collide(RigidTransform{}, QueryShape::box(Vec3f(0.5f, 0.5f, 0.25f)), RigidTransform{c, spin},
                                  ContactParams{}, scratch, contacts);
    ASSERT_GE(n, 1u) << "box " << k << " on the thin plate has no contact";
    for (const Contact& ct : contacts) {
      ASSERT_EQ(ct.featureB, ids.plate) << "box " << k;
      ASSERT_GT(ct.normal.z(), 0.999f) << "box " << k;
      ASSERT_NEAR(ct.depth, 0.005f, 1e-4f) << "box " << k;
    }
  }
  // Exactly resting (depth 0) with a small speculative margin still reports the plate.
  {
    ContactParams p;
    p.speculativeMargin = 1e-3f;
    std::vector<Contact> contacts;
    grid.collide(RigidTransform{}, QueryShape::box(Vec3f(0.5f, 0.5f, 0.25f)), RigidTransform{Vec3d(101, 79, 0.29), Quatf::Identity()},
                 p, scratch, contacts);
    ASSERT_FALSE(contacts.empty());
    for (const Contact& ct : contacts) EXPECT_NEAR(ct.depth, 0.f, 1e-5f);
  }
  // A sphere falling through the 0.04 plate stops on it (no tunnelling).
  {
    const GridSweepHit h = grid.sweep(QueryShape::sphere(0.1f), Quatf::Identity(), Vec3f(101, 81, 5), Vec3f(101, 81, -5), ~0u);
    ASSERT_TRUE(h.hit());
    EXPECT_EQ(h.brick, ids.plate);
    EXPECT_NEAR(h.fraction, (5.f - 0.14f) / 10.f, 2e-4f);
  }
  // A small box (0.06) resting 0.002 deep on the microbrick that leans on the 500-long ramp,
  // and 0.01 into the ramp's side: both contacts, the microbrick's with an up normal.
  {
    const QueryShape small = QueryShape::box(Vec3f::Constant(0.03f));
    std::vector<Contact> contacts;
    grid.collide(RigidTransform{}, small, RigidTransform{Vec3d(10, 2.02, 0.04 + 0.03 - 0.002), Quatf::Identity()}, ContactParams{},
                 scratch, contacts);
    const auto micro = std::find_if(contacts.begin(), contacts.end(), [&](const Contact& c) { return c.featureB == ids.micro; });
    ASSERT_NE(micro, contacts.end()) << "the microbrick contact is lost beside the ramp";
    EXPECT_GT(micro->normal.z(), 0.999f);
    EXPECT_NEAR(micro->depth, 0.002f, 1e-4f);
    EXPECT_TRUE(std::any_of(contacts.begin(), contacts.end(), [&](const Contact& c) { return c.featureB == ids.ramp; }));
    // Touching only the microbrick's free side.
    contacts.clear();
    grid.collide(RigidTransform{}, small, RigidTransform{Vec3d(10, 2.02 + 0.02 + 0.03 - 0.002, 0.02), Quatf::Identity()},
                 ContactParams{}, scratch, contacts);
    ASSERT_FALSE(contacts.empty());
    for (const Contact& c : contacts) {
      EXPECT_EQ(c.featureB, ids.micro);
      EXPECT_GT(c.normal.y(), 0.999f);
      EXPECT_NEAR(c.depth, 0.002f, 1e-4f);
    }
  }
}

}  // namespace
}  // namespace bw
