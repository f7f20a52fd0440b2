// Bad values at the BrickGrid API (split from the former collision extremes_test.cpp).
//
// Guarantees these tests establish (each one can fail):
// Bad values
// - NaN/inf positions, sizes out of range (zero, negative, NaN, inf, < 0.002, > 2^28), bounds
//   beyond 2^30, bad shapes/sides, NaN/inf/zero ray directions, NaN/negative maxT, NaN/inf
//   sweep points, non-unit rotations, bad query shapes, bad contact params (maxContacts,
//   lodFraction, speculativeMargin) and NaN overlap boxes throw InvalidInput naming the
//   argument, and leave the grid/tree unchanged (counts, edit count, structure hash, mass,
//   query answers).
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

using test::expectRejected;
using test::kInf;
using test::kNaN;

// What a grid looks like from outside: brick count, edit count, index structure, mass, and a
// raycast and a contact query.
struct GridSnapshot {
  uint32_t bricks;
  uint64_t edits, hash;
  double mass;
  uint32_t rayBrick;
  float rayT;
  size_t contacts;
  bool operator==(const GridSnapshot&) const = default;
};
GridSnapshot snapshot(const BrickGrid& g) {
  const GridRayHit h = g.raycast(Ray::make(Vec3f(-5, 0.2f, 0.1f), Vec3f(1, 0, 0)), ~0u);
  std::vector<LocalContact> c;
  g.collideLocal(QueryShape::sphere(0.6f), LocalPose{Vec3f(0, 0, 0.9f), Quatf::Identity()}, ContactParams{}, c);
  return {g.brickCount(), g.editCount(), g.index().structureHash(), g.massProperties().mass, h.brick, h.t, c.size()};
}

// Covered in brick_grid_test / spatial_index_test already: placeBrick with NaN position, negative
// or zero half size, position beyond 2^30, a 2-sided cylinder, unknown remove id, NaN half size
// (message); collide with a NaN shape pose and a negative sphere radius; OctoBVH insert with
// NaN/inf/inverted/out-of-range bounds, update with NaN, remove of an unknown handle. Added here:
// everything else the API takes, each checked for the argument's name and for no change.
TEST(ExtremesBadInput, EveryBadValueIsRefusedByNameAndChangesNothing) {
  BrickGrid grid;
  grid.placeBrick(Brick::box(Vec3f(0, 0, 0), Vec3f::Constant(0.5f)));
  Brick w = Brick::box(Vec3f(2, 0, 0), Vec3f(0.5f, 1, 0.5f));
  w.shape = BrickShape::Wedge;
  grid.placeBrick(w);
  const GridSnapshot before = snapshot(grid);
  ASSERT_TRUE(grid.raycast(Ray::make(Vec3f(-5, 0.2f, 0.1f), Vec3f(1, 0, 0)), ~0u).hit());

  auto place = [&](Vec3f pos, Vec3f half) { return [&grid, pos, half] { grid.placeBrick(Brick::box(pos, half)); }; };
  const Vec3f h = Vec3f::Constant(0.5f);
  expectRejected(place(Vec3f(kInf, 0, 0), h), "brick.position.x", "+inf position");
  expectRejected(place(Vec3f(0, 0, -kInf), h), "brick.position.z", "-inf position");
  expectRejected(place(Vec3f(0, 0, 0), Vec3f(kInf, 0.5f, 0.5f)), "brick.halfSize.x", "inf half size");
  expectRejected(place(Vec3f(0, 0, 0), Vec3f(0.5f, 0.5f, kNaN)), "brick.halfSize.z", "NaN half size");
  expectRejected(place(Vec3f(0, 0, 0), Vec3f(0.5f, 0.5f, 0.001f)), "brick.halfSize.z", "half size below 0.002");
  expectRejected(place(Vec3f(0, 0, 0), Vec3f(0.5f, 3e8f, 0.5f)), "brick.halfSize.y", "half size above 2^28");
  expectRejected(place(Vec3f(0, 0, 0), Vec3f(0.5f, -0.f, 0.5f)), "brick.halfSize.y", "negative zero half size");
  // Centre in range, bounds beyond the grid-local range: refused by the index, nothing kept.
  expectRejected(place(Vec3f(1.07e9f, 0, 0), Vec3f(1e7f, 1, 1)), "bounds on x", "bounds beyond 2^30");
  {
    Brick b = Brick::box(Vec3f(0, 0, 0), h);
    b.shape = BrickShape(9);
    expectRejected([&] { grid.placeBrick(b); }, "brick.shape", "unknown shape");
    b.shape = BrickShape::Cylinder;
    b.sides = 65;
    expectRejected([&] { grid.placeBrick(b); }, "brick.sides", "65 sides");
  }
  expectRejected([&] { grid.removeBrick(0xFFFFFFFEu); }, "brick 4294967294", "remove of an unknown id");

  // Rays.
  auto ray = [&](Vec3f o, Vec3f d, float maxT) { return [&grid, o, d, maxT] { grid.raycast(Ray::make(o, d, maxT), ~0u); }; };
  expectRejected(ray(Vec3f(kNaN, 0, 0), Vec3f(1, 0, 0), kInf), "ray.origin.x", "NaN origin");
  expectRejected(ray(Vec3f(0, -kInf, 0), Vec3f(1, 0, 0), kInf), "ray.origin.y", "inf origin");
  expectRejected(ray(Vec3f(-5, 0, 0), Vec3f(1, 0, kNaN), kInf), "ray.dir.z", "NaN direction");
  expectRejected(ray(Vec3f(-5, 0, 0), Vec3f(kInf, 0, 0), kInf), "ray.dir.x", "inf direction");
  expectRejected(ray(Vec3f(-5, 0, 0), Vec3f(0, 0, 0), kInf), "ray.dir has zero length", "zero direction");
  expectRejected(ray(Vec3f(-5, 0, 0), Vec3f(1e-40f, -1e-41f, 0), kInf), "ray.dir has zero length", "denormal direction");
  expectRejected(ray(Vec3f(-5, 0, 0), Vec3f(1, 0, 0), kNaN), "ray.maxT", "NaN maxT");
  expectRejected(ray(Vec3f(-5, 0, 0), Vec3f(1, 0, 0), -1.f), "ray.maxT", "negative maxT");
  EXPECT_NO_THROW(grid.raycast(Ray::make(Vec3f(-5, 0, 0), Vec3f(1e-40f, 1, 0), 0.f), ~0u)) << "maxT 0 and one denormal component are fine";

  // Sweeps.
  const Quatf id = Quatf::Identity();
  auto sweep = [&](QueryShape s, Quatf q, Vec3f from, Vec3f to) { return [&grid, s, q, from, to] { grid.sweep(s, q, from, to, ~0u); }; };
  const QueryShape ball = QueryShape::sphere(0.3f);
  expectRejected(sweep(ball, id, Vec3f(0, kNaN, 0), Vec3f(1, 0, 0)), "from.y", "NaN from");
  expectRejected(sweep(ball, id, Vec3f(0, 0, 0), Vec3f(1, 0, kInf)), "to.z", "inf to");
  expectRejected(sweep(ball, Quatf(2, 0, 0, 0), Vec3f(0, 0, 0), Vec3f(1, 0, 0)), "rotation", "non-unit rotation");
  expectRejected(sweep(ball, Quatf(kNaN, 0, 0, 0), Vec3f(0, 0, 0), Vec3f(1, 0, 0)), "rotation", "NaN rotation");
  expectRejected(sweep(QueryShape::sphere(kNaN), id, Vec3f(0, 0, 0), Vec3f(1, 0, 0)), "sphere radius", "NaN radius");
  expectRejected(sweep(QueryShape::box(Vec3f(0.5f, 0.f, 0.5f)), id, Vec3f(0, 0, 0), Vec3f(1, 0, 0)), "box half extent", "zero box");
  expectRejected(sweep(QueryShape::box(Vec3f(0.5f, 2e7f, 0.5f)), id, Vec3f(0, 0, 0), Vec3f(1, 0, 0)), "box half extent", "huge box");
  expectRejected(sweep(QueryShape::capsule(-0.1f, 1.f), id, Vec3f(0, 0, 0), Vec3f(1, 0, 0)), "capsule radius", "negative capsule");
  expectRejected(sweep(QueryShape::capsule(0.1f, kNaN), id, Vec3f(0, 0, 0), Vec3f(1, 0, 0)), "capsule half height", "NaN capsule");
  const Vec3f badHull[4] = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, kNaN, 0), Vec3f(0, 0, 1)};
  expectRejected(sweep(QueryShape::hull(badHull, 4), id, Vec3f(0, 0, 0), Vec3f(1, 0, 0)), "hull point", "NaN hull point");
  expectRejected(sweep(QueryShape::hull(badHull, 3), id, Vec3f(0, 0, 0), Vec3f(1, 0, 0)), "at least 4 points", "3-point hull");

  // Contacts.
  ContactScratch scratch;
  std::vector<Contact> out;
  auto collide = [&](RigidTransform gp, QueryShape s, RigidTransform sp, ContactParams p) {
    return [&grid, &scratch, &out, gp, s, sp, p] { grid.collide(gp, s, sp, p, scratch, out); };
  };
  const RigidTransform at{Vec3d(0, 0, 0.9), id};
  RigidTransform bad;
  bad.translation.y() = std::numeric_limits<double>::infinity();
  expectRejected(collide(bad, ball, at, ContactParams{}), "translation.y", "inf grid translation");
  bad = RigidTransform{};
  bad.rotation = Quatf(0.5f, 0.5f, 0.5f, 0.6f);
  expectRejected(collide(bad, ball, at, ContactParams{}), "rotation", "non-unit grid rotation");
  expectRejected(collide(RigidTransform{}, ball, bad, ContactParams{}), "rotation", "non-unit shape rotation");
  expectRejected(collide(RigidTransform{}, QueryShape::box(Vec3f(kNaN, 1, 1)), at, ContactParams{}), "box half extent", "NaN box");
  expectRejected(collide(RigidTransform{}, QueryShape::sphere(0.f), at, ContactParams{}), "sphere radius", "zero radius");
  ContactParams p;
  p.maxContacts = 0;
  expectRejected(collide(RigidTransform{}, ball, at, p), "params.maxContacts", "0 contacts");
  p = ContactParams{};
  p.lodFraction = kNaN;
  expectRejected(collide(RigidTransform{}, ball, at, p), "params.lodFraction", "NaN LOD fraction");
  p = ContactParams{};
  p.speculativeMargin = kNaN;
  expectRejected(collide(RigidTransform{}, ball, at, p), "params.speculativeMargin", "NaN margin");
  p.speculativeMargin = kInf;
  expectRejected(collide(RigidTransform{}, ball, at, p), "params.speculativeMargin", "inf margin");
  EXPECT_TRUE(out.empty());

  // Overlap boxes.
  std::vector<uint32_t> ids;
  expectRejected([&] { grid.overlapBricks(Aabb{Vec3f(0, kNaN, 0), Vec3f(1, 1, 1)}, ~0u, ids); }, "box.min.y", "NaN box");
  EXPECT_TRUE(ids.empty());
  grid.overlapBricks(Aabb{Vec3f::Constant(-kInf), Vec3f::Constant(kInf)}, ~0u, ids);
  EXPECT_EQ(ids.size(), 2u) << "an unbounded box is a valid query: it overlaps everything";

  EXPECT_TRUE(snapshot(grid) == before) << "a refused call changed the grid";
  grid.index().validate();

  // The documented limits themselves are accepted.
  const uint32_t tiny = grid.placeBrick(Brick::box(Vec3f(5, 5, 5), Vec3f::Constant(kMinBrickHalfSize)));
  const uint32_t huge = grid.placeBrick(Brick::box(Vec3f(0, 0, 0), Vec3f::Constant(kMaxBrickHalfSize)));
  const float edge = std::nextafter(octobvh::kMaxCoordinate, 0.f);
  const uint32_t far = grid.placeBrick(Brick::box(Vec3f(edge - 0.5f * 128, 0, 0), Vec3f(32, 1, 1)));
  EXPECT_EQ(grid.brickCount(), 5u);
  grid.index().validate();
  for (uint32_t b : {tiny, huge, far}) grid.removeBrick(b);
  EXPECT_EQ(grid.index().structureHash(), before.hash);
}

}  // namespace
}  // namespace bw
