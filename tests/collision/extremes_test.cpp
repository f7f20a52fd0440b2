// Stability at the extremes for the collision layer (OctoBVH, brick grids, rays, sweeps, contacts).
//
// Guarantees these tests establish (seeded, deterministic; each one can fail):
// Scale
// - 4M elements (10M with BW_EXTREMES_SCALE=10000000; 1M under sanitizers) inserted one by one
//   into an OctoBVH and removed in random order leave it exactly empty: no element, leaf or
//   overflow block, one root cluster, root back to its initial level, empty root bounds;
//   resident memory back under 2% of the full tree's (pool metadata only: 2.3 MB of 236 MB at
//   4M, 5.8 MB of 592 MB at 10M). Refilled with a small set it is the fresh tree of that set
//   (same root bounds, root level, structure hash, node counts, query answers): no drift.
// Coordinates
// - OctoBVH: every coordinate with |x| < 2^30 (2^30 - 64 accepted, 2^30 refused), elements from
//   points (zero extent) to the whole range, match brute force; the root may reach level
//   kMaxLevel + 1 ([-2^31, 2^31)) when one element spans the range.
// - A grid placed anywhere up to 1e9 from the world origin (double translation, any rotation)
//   answers in grid-local terms like at the origin: contact depth and point within
//   8 eps(T), eps(T) = 2^-20 + |T| 2^-52 (local coordinates < 16), normal within 2e-4, ray hit
//   distance within 8 eps(T) / |cos(incidence)|, identical overlap sets. Measured: the
//   translation adds nothing measurable up to 1e9 (depth 2.1e-7, point 4.8e-7 at every offset).
// - Inside a grid, float spacing sets the precision: bricks at local distance L keep depth and
//   contact points within 4 ulp(L) (ulp(1e4) = 2^-10 ~ 9.8e-4), hit distances within
//   4 ulp(L) / |cos|, normals within 4 ulp(L) / radius. Keep grid-local coordinates below ~1e4
//   for millimetre-level contacts.
// Sizes
// - Brick half sizes 0.002 .. 2^28 accepted, outside refused; 0.04 microbricks, 0.04-thick
//   plates and 500-long ramps in one grid (ratio 12500) match brute force for raycasts,
//   overlaps, contacts and sweeps; a box resting on a 0.04 plate always gets its contacts
//   (depth within 1e-4), a sphere sweeping through one stops on it, and a 0.06 box touching a
//   microbrick beside a 500 ramp gets the microbrick contact.
// Rays and sweeps (BrickGrid)
// - Tie rule: brick shapes are closed, so a ray that only touches a face, edge or corner hits.
//   The grid's traversal is conservative (bounds grown by a few ulps of the largest coordinate),
//   so raycast returns exactly the smallest rayBrick() t over every brick, and among bricks tied
//   at that t the one with the lowest OctoBVH handle (= lowest brick id when bricks were only
//   placed). Sweeps return exactly the smallest sweepShapeBrick() fraction, same tie rule.
// - Directions may be unnormalised, with zero, denormal (1e-40) and huge (1e30) components: no
//   NaN, hit normals unit length, no crash or endless loop. A direction with every component
//   zero or denormal is refused.
// Bad values
// - NaN/inf positions, sizes out of range (zero, negative, NaN, inf, < 0.002, > 2^28), bounds
//   beyond 2^30, bad shapes/sides, NaN/inf/zero ray directions, NaN/negative maxT, NaN/inf
//   sweep points, non-unit rotations, bad query shapes, bad contact params (maxContacts,
//   lodFraction, speculativeMargin) and NaN overlap boxes throw InvalidInput naming the
//   argument, and leave the grid/tree unchanged (counts, edit count, structure hash, mass,
//   query answers).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <gtest/gtest.h>
#include <limits>
#include <string>

#include "collision/bricks/brick_grid.h"
#include "collision/content/brick_workload.h"
#include "collision/core/argument_checks.h"
#include "collision/core/seeded_random.h"
#include "collision/index/octobvh.h"
#include "brute_force_index.h"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define BW_EXTREMES_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define BW_EXTREMES_SANITIZED 1
#endif
#endif

namespace bw {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

template <class T>
void shuffle(std::vector<T>& v, SeededRandom& r) {
  for (uint32_t i = uint32_t(v.size()); i > 1; --i) std::swap(v[i - 1], v[r.below(i)]);
}

// ---------------------------------------------------------------- 1. scale

// note: 10M one-by-one inserts then removals in random order take ~33 s in release on the
// 2-core reference machine (generate 1.6 s, insert 9.6 s, remove 21.5 s: random-order removal is
// memory bound), over this file's 30 s budget, so the default run is 4M (~10 s) and 10M is one
// environment variable away: BW_EXTREMES_SCALE=10000000 (measured passing). Under a sanitizer the run is
// several times slower again, so sanitized builds default to 1M; the code paths are the same,
// only the pool sizes differ.
#ifdef BW_EXTREMES_SANITIZED
constexpr uint32_t kDefaultScaleCount = 1'000'000;
#else
constexpr uint32_t kDefaultScaleCount = 4'000'000;
#endif
uint32_t scaleCount() {
  const char* env = std::getenv("BW_EXTREMES_SCALE");
  return env ? uint32_t(std::strtoul(env, nullptr, 10)) : kDefaultScaleCount;
}

TEST(ExtremesOctoBvh, MillionsInsertedThenRemovedInRandomOrderLeaveNoTrace) {
  const uint32_t kScaleCount = scaleCount();
  const auto t0 = std::chrono::steady_clock::now();
  BrickWorkloadParams p;
  p.count = kScaleCount;
  p.seed = 77;
  p.extent = 20000.f;
  const std::vector<Aabb> boxes = generateBrickWorkload(p);
  const double tGen = secondsSince(t0);

  // The small set re-inserted at the end, and the fresh tree it must match.
  BrickWorkloadParams sp;
  sp.count = 400;
  sp.seed = 78;
  sp.extent = 300.f;
  const std::vector<Aabb> small = generateBrickWorkload(sp);
  OctoBvh fresh;
  for (uint32_t i = 0; i < small.size(); ++i) fresh.insert(small[i], 1u << (i % 3), i);
  const OctoBvh::MemoryStats freshMem = fresh.memoryStats();
  const size_t emptyResident = OctoBvh(OctoBvh::Config{kScaleCount}).residentBytes();

  OctoBvh tree(OctoBvh::Config{kScaleCount});
  std::vector<uint32_t> handles(boxes.size());
  Aabb all = Aabb::empty();
  for (uint32_t i = 0; i < boxes.size(); ++i) {
    handles[i] = tree.insert(boxes[i], 1u << (i % 3), i);
    all.merge(boxes[i]);
  }
  const double tInsert = secondsSince(t0) - tGen;
  ASSERT_EQ(tree.size(), kScaleCount);
  EXPECT_EQ(tree.rootBounds(), all) << "root bounds are the exact union of the elements";
  const OctoBvh::MemoryStats fullMem = tree.memoryStats();
  EXPECT_EQ(fullMem.elements, kScaleCount);
  const size_t fullResident = tree.residentBytes();
  EXPECT_GE(fullResident, fullMem.totalBytes() / 2) << "the pools must have touched their pages";

  SeededRandom r(79);
  shuffle(handles, r);
  for (uint32_t h : handles) tree.remove(h);
  const double tRemove = secondsSince(t0) - tGen - tInsert;

  EXPECT_TRUE(tree.empty());
  EXPECT_EQ(tree.size(), 0u);
  EXPECT_TRUE(tree.rootBounds().isEmpty()) << "no stale bounds in the root";
  EXPECT_EQ(tree.rootLevel(), octobvh::kMinLevel + 1) << "the root shrinks back to its initial level";
  const OctoBvh::MemoryStats emptyMem = tree.memoryStats();
  EXPECT_EQ(emptyMem.elements, 0u);
  EXPECT_EQ(emptyMem.clusters, 1u) << "only the root cluster stays allocated";
  EXPECT_EQ(emptyMem.nonEmptyNodes, 0u);
  EXPECT_EQ(emptyMem.leafBlocks, 0u);
  EXPECT_EQ(emptyMem.overflowBlocks, 0u);
  // Pages go back to the OS: what stays resident is pool metadata (block headers and live
  // bitmaps, a few bytes per reserved slot) plus one spare block per pool.
  const size_t emptiedResident = tree.residentBytes();
  EXPECT_LT(emptiedResident, fullResident / 50 + (64u << 10)) << "resident after emptying " << emptiedResident << " of " << fullResident;
  tree.validate();

  // No drift: the emptied tree, refilled with a small set, is the fresh tree of that set.
  for (uint32_t i = 0; i < small.size(); ++i) tree.insert(small[i], 1u << (i % 3), i);
  tree.validate();
  EXPECT_EQ(tree.rootBounds(), fresh.rootBounds());
  EXPECT_EQ(tree.rootLevel(), fresh.rootLevel());
  EXPECT_EQ(tree.structureHash(), fresh.structureHash());
  const OctoBvh::MemoryStats refilled = tree.memoryStats();
  EXPECT_EQ(refilled.clusters, freshMem.clusters);
  EXPECT_EQ(refilled.nonEmptyNodes, freshMem.nonEmptyNodes);
  EXPECT_EQ(refilled.leafBlocks, freshMem.leafBlocks);
  const Aabb q = Aabb::fromCenterHalf(fresh.rootBounds().center(), Vec3f::Constant(40.f));
  std::vector<uint32_t> a, b;
  tree.overlap(q, ~0u, [&](uint32_t e) { a.push_back(tree.payload(e)); });
  fresh.overlap(q, ~0u, [&](uint32_t e) { b.push_back(fresh.payload(e)); });
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  EXPECT_EQ(a, b);
  EXPECT_FALSE(a.empty());
  std::printf("[ scale    ] %u elements: generate %.2f s, insert %.2f s, remove %.2f s; resident full %.1f MB, "
              "emptied %.2f MB, fresh empty tree %.2f MB\n",
              kScaleCount, tGen, tInsert, tRemove, fullResident / 1e6, emptiedResident / 1e6, emptyResident / 1e6);
}


// The whole documented coordinate range (|x| < 2^30) and element sizes from points to the
// largest box, against brute force, then emptied back to the initial root.
TEST(ExtremesOctoBvh, WholeCoordinateRangeAndPointToHugeElementsMatchBruteForce) {
  const float edge = std::nextafter(octobvh::kMaxCoordinate, 0.f);  // 2^30 - 64, the largest accepted
  OctoBvh tree;
  test::BruteForceIndex ref;
  std::vector<uint32_t> handles;
  auto add = [&](const Aabb& b) {
    const uint32_t h = tree.insert(b, 1, uint32_t(handles.size()));
    ref.items[h] = {b, 1};
    handles.push_back(h);
  };
  for (int c = 0; c < 8; ++c) {  // points and small boxes in the eight extreme corners
    const Vec3f corner((c & 1) ? edge : -edge, (c & 2) ? edge : -edge, (c & 4) ? edge : -edge);
    add({corner, corner});
    const Vec3f in = corner * 0.5f;
    add({in, in + Vec3f::Constant(0.04f * 4096)});  // 0.04 is below float spacing out there
  }
  add({Vec3f::Constant(-edge), Vec3f::Constant(edge)});  // the largest element
  SeededRandom r(31);
  for (int i = 0; i < 600; ++i) {  // tiny elements around the origin, down to points, below 2^-10
    const Vec3f c(float(r.uniform(-0.01, 0.01)), float(r.uniform(-0.01, 0.01)), float(r.uniform(-0.01, 0.01)));
    const float h = i % 5 == 0 ? 0.f : float(r.logUniform(1e-6, 1e-2));
    add(Aabb::fromCenterHalf(c, Vec3f::Constant(h)));
  }
  tree.validate();
  // The largest element (extent ~2^31) has min level kMaxLevel, so the root's children are
  // level-31 cubes and the root spans [-2^31, 2^31): one level above kMaxLevel.
  EXPECT_EQ(tree.rootLevel(), octobvh::kMaxLevel + 1);
  for (int q = 0; q < 300; ++q) {
    const float scale = float(std::ldexp(1.0, int(r.below(60)) - 30));  // 2^-30 .. 2^29
    const Vec3f c = Vec3f(float(r.uniform(-1, 1)), float(r.uniform(-1, 1)), float(r.uniform(-1, 1))) * scale;
    const Aabb box = Aabb::fromCenterHalf(c, Vec3f::Constant(scale * float(r.uniform(0.01, 1))));
    std::vector<uint32_t> got;
    tree.overlap(box, 1, got);
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, ref.overlap(box, 1)) << "query " << q;
    Vec3f d(float(r.normal()), float(r.normal()), float(r.normal()));
    if (q % 3 == 0) d = Vec3f::Zero(), d[q % 3 == 0 ? r.below(3) : 0] = 1.f;
    const Ray ray = Ray::make(-c.normalized() * edge * 0.9f + c, d * (q % 4 == 0 ? 1e30f : 1.f));
    const auto all = ref.raycastAll(ray, 1);
    const RayHit hit = tree.raycastClosest(ray, 1);
    ASSERT_EQ(hit.hit(), !all.empty()) << "ray " << q;
    if (hit.hit()) {
      ASSERT_EQ(hit.t, all.front().t) << "ray " << q;
      ASSERT_EQ(hit.element, all.front().element) << "ray " << q;
    }
  }
  shuffle(handles, r);
  for (uint32_t h : handles) tree.remove(h);
  EXPECT_TRUE(tree.empty());
  EXPECT_EQ(tree.rootLevel(), octobvh::kMinLevel + 1);
  EXPECT_EQ(tree.memoryStats().clusters, 1u);
  tree.validate();
}

// ---------------------------------------------------------------- 2. rays and sweeps on lattice planes

// The closest exact hit over every brick (brute force), with every brick tied at that t.
struct BruteRayHit {
  float t = kInf;
  std::vector<uint32_t> tied;  // ascending ids
  bool hit() const { return !tied.empty(); }
};

BruteRayHit bruteRaycast(const BrickGrid& grid, const Ray& ray, uint32_t mask) {
  BruteRayHit best;
  grid.forEachBrick([&](uint32_t id) {
    float t;
    Vec3f n;
    if (!(grid.brick(id).filter & mask) || !rayBrick(grid.brick(id), ray, ray.maxT, t, n) || !(t <= ray.maxT)) return;
    if (t < best.t) best.t = t, best.tied.clear();
    if (t == best.t) best.tied.push_back(id);
  });
  return best;
}

struct BruteSweepHit {
  float fraction = 2.f;
  std::vector<uint32_t> tied;
  bool hit() const { return !tied.empty(); }
};

BruteSweepHit bruteSweep(const BrickGrid& grid, const QueryShape& shape, const Quatf& rot, const Vec3f& from,
                         const Vec3f& to) {
  BruteSweepHit best;
  grid.forEachBrick([&](uint32_t id) {
    float f;
    Vec3f n, p;
    if (!sweepShapeBrick(shape, rot, from, to, grid.brick(id), f, n, p)) return;
    if (f < best.fraction) best.fraction = f, best.tied.clear();
    if (f == best.fraction) best.tied.push_back(id);
  });
  return best;
}

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

// OctoBVH element handle of every brick id (ties between bricks go to the lowest handle; in a
// grid where bricks were only placed, that is also the lowest brick id).
std::vector<uint32_t> handleOfBrick(const BrickGrid& grid) {
  std::vector<uint32_t> out(grid.index().size() * 2 + 64, 0xFFFFFFFFu);
  grid.index().forEachElement([&](uint32_t e) {
    const uint32_t id = grid.index().payload(e);
    if (id >= out.size()) out.resize(id + 1, 0xFFFFFFFFu);
    out[id] = e;
  });
  return out;
}

uint32_t lowestHandleBrick(const std::vector<uint32_t>& tied, const std::vector<uint32_t>& handleOf) {
  return *std::min_element(tied.begin(), tied.end(), [&](uint32_t a, uint32_t b) { return handleOf[a] < handleOf[b]; });
}

// One ray against the grid and brute force. Tie rule: brick shapes are closed, so a ray that only
// touches a face, an edge or a corner hits (rayBrick and the index's slab tests agree on that,
// the index being conservative: every brick rayBrick hits is a candidate); the grid returns
// exactly rayBrick's smallest t and, among the bricks tied at that t, the one with the lowest
// element handle.
void expectRayMatches(const BrickGrid& grid, const std::vector<uint32_t>& handleOf, const Ray& ray,
                      const std::string& what, int& hits) {
  const GridRayHit h = grid.raycast(ray, ~0u);
  const BruteRayHit ref = bruteRaycast(grid, ray, ~0u);
  ASSERT_EQ(h.hit(), ref.hit()) << what;
  if (!h.hit()) return;
  ++hits;
  ASSERT_FALSE(std::isnan(h.t)) << what;
  ASSERT_EQ(h.t, ref.t) << what;
  ASSERT_EQ(h.brick, lowestHandleBrick(ref.tied, handleOf)) << what << ": " << ref.tied.size() << " tied";
  ASSERT_TRUE(h.normal.allFinite()) << what;
  ASSERT_NEAR(h.normal.norm(), 1.f, 1e-5f) << what << " normal " << h.normal.transpose();
}

std::string describeRay(const Ray& r) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "ray o(%.9g %.9g %.9g) d(%.9g %.9g %.9g) maxT %.9g", r.origin.x(), r.origin.y(),
                r.origin.z(), r.dir.x(), r.dir.y(), r.dir.z(), r.maxT);
  return buf;
}

TEST(ExtremesRays, AlongLatticePlanesThroughSharedEdgesAndCornersMatchBruteForce) {
  BrickGrid grid;
  buildLattice(grid);
  const std::vector<uint32_t> handleOf = handleOfBrick(grid);
  int hits = 0;
  auto check = [&](const Vec3f& o, const Vec3f& d, float maxT = kInf) {
    const Ray ray = Ray::make(o, d, maxT);
    expectRayMatches(grid, handleOf, ray, describeRay(ray), hits);
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
  const std::vector<uint32_t> handleOf = handleOfBrick(grid);
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
    ASSERT_EQ(h.brick, lowestHandleBrick(ref.tied, handleOf)) << what << ": " << ref.tied.size() << " tied";
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


// ---------------------------------------------------------------- 3. far from the origin

// A small build: a floor of plates, a wedge, a cylinder and microbricks, all shifted by `offset`
// in the grid's own frame.
void buildFarTestGrid(BrickGrid& grid, const Vec3f& offset) {
  for (int x = 0; x < 8; ++x)
    for (int y = 0; y < 8; ++y) grid.placeBrick(Brick::box(offset + Vec3f(float(x), float(y), 0.f), Vec3f(0.5f, 0.5f, 0.1f)));
  Brick w = Brick::box(offset + Vec3f(3.f, 3.f, 0.6f), Vec3f(1.f, 2.f, 0.5f));
  w.shape = BrickShape::Wedge;
  w.rotation = AxisRotation::fromIndex(5);
  grid.placeBrick(w);
  Brick c = Brick::box(offset + Vec3f(6.f, 1.f, 0.7f), Vec3f(0.4f, 0.4f, 0.6f));
  c.shape = BrickShape::Cylinder;
  c.sides = 16;
  grid.placeBrick(c);
  for (int k = 0; k < 6; ++k) grid.placeBrick(Brick::box(offset + Vec3f(1.02f + 0.04f * k, 6.f, 0.12f), Vec3f::Constant(0.02f)));
}

struct LocalQuery {
  QueryShape shape;
  Vec3f position;  // relative to the build's offset
  Quatf rotation;
};

std::vector<LocalQuery> farQueries(std::vector<Vec3f>& hullPoints) {
  hullPoints.clear();
  for (int i = 0; i < 8; ++i) hullPoints.emplace_back((i & 1) ? 0.3f : -0.3f, (i & 2) ? 0.2f : -0.2f, (i & 4) ? 0.25f : -0.25f);
  std::vector<LocalQuery> out;
  out.push_back({QueryShape::box(Vec3f(0.5f, 0.5f, 0.25f)), Vec3f(2.3f, 4.6f, 0.1f + 0.25f - 0.01f), Quatf::Identity()});
  out.push_back({QueryShape::box(Vec3f(0.05f, 0.05f, 0.05f)), Vec3f(1.1f, 6.f, 0.14f + 0.05f - 0.004f), Quatf::Identity()});
  SeededRandom r(51);
  for (int k = 0; k < 40; ++k) {
    const Vec3f p(float(r.uniform(0, 7)), float(r.uniform(0, 7)), float(r.uniform(0.05, 1.2)));
    const Quatf q(Eigen::AngleAxisf(float(r.uniform(0, 6.28)), Vec3f(float(r.normal()), float(r.normal()), float(r.normal())).normalized()));
    switch (k % 4) {
      case 0: out.push_back({QueryShape::sphere(0.3f), p, q}); break;
      case 1: out.push_back({QueryShape::box(Vec3f(0.4f, 0.3f, 0.2f)), p, q}); break;
      case 2: out.push_back({QueryShape::capsule(0.2f, 0.3f), p, q}); break;
      default: out.push_back({QueryShape::hull(hullPoints.data(), uint32_t(hullPoints.size())), p, q}); break;
    }
  }
  return out;
}

// Contacts of every query with maxContacts 64 (no reduction), in grid-local terms.
std::vector<std::vector<LocalContact>> contactsInGridTerms(const BrickGrid& grid, const RigidTransform& gridPose,
                                                           const Vec3f& offset, const std::vector<LocalQuery>& queries) {
  std::vector<std::vector<LocalContact>> out;
  ContactScratch scratch;
  ContactParams params;
  params.maxContacts = 64;  // no speculative margin: only penetrating contacts are compared
  for (const LocalQuery& q : queries) {
    const Vec3f local = offset + q.position;
    const RigidTransform shapePose{gridPose.pointToWorld(local), (gridPose.rotation * q.rotation).normalized()};
    std::vector<Contact> world;
    grid.collide(gridPose, q.shape, shapePose, params, scratch, world);
    std::vector<LocalContact> mine;
    for (const Contact& c : world) {
      // Back to the grid frame in double, relative to the build's offset.
      const Vec3d rel = gridPose.rotation.conjugate().cast<double>() * (c.position - gridPose.translation) - offset.cast<double>();
      mine.push_back({rel.cast<float>(), gridPose.directionToLocal(c.normal), c.depth, c.featureB, c.material});
    }
    out.push_back(mine);
  }
  return out;
}

// Largest differences between two contact sets (matched per feature, nearest point first).
struct ContactDiff {
  float depth = 0, normal = 0, position = 0;
  bool countMismatch = false;
};
void compareContacts(const std::vector<LocalContact>& a, const std::vector<LocalContact>& b, ContactDiff& d) {
  if (a.size() != b.size()) {
    d.countMismatch = true;
    return;
  }
  for (const LocalContact& x : a) {
    float best = kInf;
    const LocalContact* m = nullptr;
    for (const LocalContact& y : b)
      if (y.feature == x.feature && (y.position - x.position).norm() < best) best = (y.position - x.position).norm(), m = &y;
    if (!m) {
      d.countMismatch = true;
      return;
    }
    d.position = std::max(d.position, best);
    d.depth = std::max(d.depth, std::abs(m->depth - x.depth));
    d.normal = std::max(d.normal, (m->normal - x.normal).norm());
  }
}

// Tolerances (grid-local queries whose coordinates stay below M = 16):
// - world -> local: the world point carries |T| * 2^-53 of double rounding, the cast to float
//   half a float spacing at M (2^-20): one pose is off by at most eps(T) = 2^-20 + |T| 2^-52.
// - contact depth and point: the narrowphase is Lipschitz in the pose for these non-degenerate
//   cases: 8 eps(T) (measured: 2.1e-7 and 4.8e-7 at every offset, the same as a rotated pose at
//   the origin: the translation adds nothing measurable up to 1e9).
// - contact normal: 2e-4 (GJK/EPA normals of sphere/capsule/hull contacts move with the pose's
//   float rotation; measured 4e-6).
// - ray hit distance: 8 eps(T) / |cos| (slab and plane tests on a pose off by eps(T)).
// A plane offset by e moves an oblique ray's hit by e / |cos| along the ray: hit distances are
// compared after multiplying by |cos| of the angle to the hit face (grazing rays below 0.2 count
// as 0.2).
float obliquity(const Ray& ray, const GridRayHit& h) {
  return std::max(0.2f, std::abs(ray.dir.normalized().dot(h.normal)));
}

double poseEps(double translation) { return std::ldexp(1.0, -20) + translation * std::ldexp(1.0, -52); }

TEST(ExtremesFarFromOrigin, GridPlacedUpTo1e9AnswersLikeAtTheOrigin) {
  BrickGrid grid;
  buildFarTestGrid(grid, Vec3f::Zero());
  std::vector<Vec3f> hull;
  const std::vector<LocalQuery> queries = farQueries(hull);
  const RigidTransform origin{};
  const auto reference = contactsInGridTerms(grid, origin, Vec3f::Zero(), queries);
  int withContacts = 0;
  for (const auto& c : reference) withContacts += !c.empty();
  EXPECT_GT(withContacts, 15);
  ASSERT_GE(reference[0].size(), 4u) << "the resting box gets a manifold from every plate under it";
  ASSERT_FALSE(reference[1].empty()) << "the small box touches a microbrick";

  SeededRandom r(52);
  std::vector<Ray> rays;
  for (int k = 0; k < 200; ++k) {
    const Vec3f o(float(r.uniform(-2, 9)), float(r.uniform(-2, 9)), float(r.uniform(1.5, 4)));
    const Vec3f target(float(r.uniform(0, 7)), float(r.uniform(0, 7)), float(r.uniform(0, 1)));
    rays.push_back(Ray::make(o, (target - o).normalized()));
  }
  std::vector<GridRayHit> refHits;
  for (const Ray& ray : rays) refHits.push_back(grid.raycast(ray, ~0u));
  std::vector<Aabb> boxes;
  std::vector<std::vector<uint32_t>> refOverlaps;
  for (int k = 0; k < 100; ++k) {
    boxes.push_back(Aabb::fromCenterHalf(Vec3f(float(r.uniform(-1, 8)), float(r.uniform(-1, 8)), float(r.uniform(-0.5, 1.5))),
                                         Vec3f::Constant(float(r.logUniform(0.01, 2)))));
    refOverlaps.emplace_back();
    grid.overlapBricks(boxes.back(), ~0u, refOverlaps.back());
    std::sort(refOverlaps.back().begin(), refOverlaps.back().end());
  }

  const Quatf tilt(Eigen::AngleAxisf(0.7f, Vec3f(1, 2, 3).normalized()));
  for (double d : {0.0, 1e3, 1e5, 1e7, 1e9}) {
    const RigidTransform pose{Vec3d(d, -0.6 * d, 0.35 * d), tilt};
    const double eps = poseEps(d);
    const auto got = contactsInGridTerms(grid, pose, Vec3f::Zero(), queries);
    ContactDiff diff;
    for (size_t q = 0; q < queries.size(); ++q) {
      compareContacts(reference[q], got[q], diff);
      ASSERT_FALSE(diff.countMismatch) << "offset " << d << " query " << q;
    }
    EXPECT_LT(diff.depth, 8 * eps) << "offset " << d;
    EXPECT_LT(diff.position, 8 * eps) << "offset " << d;
    EXPECT_LT(diff.normal, 2e-4) << "offset " << d;
    // Rays: world ray (double origin) into the grid frame, hit distance compared.
    float rayDiff = 0;
    for (size_t k = 0; k < rays.size(); ++k) {
      const Vec3d worldOrigin = pose.pointToWorld(rays[k].origin);
      const Vec3d worldDir = pose.rotation.cast<double>() * rays[k].dir.cast<double>();
      const GridRayHit h = grid.raycast(pose.rayToLocal(worldOrigin, worldDir, kInf), ~0u);
      ASSERT_EQ(h.hit(), refHits[k].hit()) << "offset " << d << " ray " << k;
      if (h.hit()) rayDiff = std::max(rayDiff, std::abs(h.t - refHits[k].t) * obliquity(rays[k], refHits[k]));
    }
    EXPECT_LT(rayDiff, 8 * eps) << "offset " << d;
    // Overlaps: the world box centre brought into the grid frame selects the same bricks.
    for (size_t k = 0; k < boxes.size(); ++k) {
      const Vec3f c = pose.pointToLocal(pose.pointToWorld(boxes[k].center()));
      std::vector<uint32_t> ids;
      grid.overlapBricks(Aabb::fromCenterHalf(c, boxes[k].halfExtent()), ~0u, ids);
      std::sort(ids.begin(), ids.end());
      ASSERT_EQ(ids, refOverlaps[k]) << "offset " << d << " box " << k;
    }
    std::printf("[ far      ] offset %.0e: max depth diff %.2e, point %.2e, normal %.2e, ray t %.2e (eps %.2e)\n", d,
                diff.depth, diff.position, diff.normal, rayDiff, eps);
  }
}

// Bricks far from the grid's own origin: float spacing at local distance L is
// ulp(L) = 2^(floor(log2 L) - 23) (~9.8e-4 at 1e4); brick and query positions round to it, so
// depths and contact points hold to a few ulp(L) and hit distances to a few ulp(L) / |cos|:
// 4 ulp(L) asserted.
TEST(ExtremesFarFromOrigin, BricksAtLocal1e4KeepFloatSpacingPrecision) {
  BrickGrid near, far;
  const Vec3f offset(1e4f, -1e4f, 1e4f);
  buildFarTestGrid(near, Vec3f::Zero());
  buildFarTestGrid(far, offset);
  std::vector<Vec3f> hull;
  const std::vector<LocalQuery> queries = farQueries(hull);
  const auto a = contactsInGridTerms(near, RigidTransform{}, Vec3f::Zero(), queries);
  const auto b = contactsInGridTerms(far, RigidTransform{}, offset, queries);
  const double ulpL = std::ldexp(1.0, 13 - 23);
  ContactDiff diff;
  int compared = 0;
  for (size_t q = 0; q < queries.size(); ++q) {
    if (a[q].size() != b[q].size()) {
      // A contact may appear or vanish only when it is within rounding of touching.
      for (const auto* set : {&a[q], &b[q]})
        for (const LocalContact& c : *set) ASSERT_LT(std::abs(c.depth), 4 * ulpL) << "query " << q;
      continue;
    }
    compareContacts(a[q], b[q], diff);
    ASSERT_FALSE(diff.countMismatch) << "query " << q;
    compared += !a[q].empty();
  }
  EXPECT_GT(compared, 15);
  EXPECT_LT(diff.depth, 4 * ulpL);
  EXPECT_LT(diff.position, 4 * ulpL);
  EXPECT_LT(diff.normal, 4 * ulpL / 0.2) << "a point error turns a normal by error / radius (radii >= 0.2)";
  // The small box still gets its microbrick contact at 1e4.
  ASSERT_FALSE(b[1].empty());
  EXPECT_NEAR(b[1][0].depth, a[1][0].depth, 4 * ulpL);
  SeededRandom r(53);
  float rayDiff = 0;
  for (int k = 0; k < 200; ++k) {
    const Vec3f o(float(r.uniform(-2, 9)), float(r.uniform(-2, 9)), float(r.uniform(1.5, 4)));
    const Vec3f target(float(r.uniform(0, 7)), float(r.uniform(0, 7)), float(r.uniform(0, 1)));
    const Vec3f d = (target - o).normalized();
    const GridRayHit h0 = near.raycast(Ray::make(o, d), ~0u);
    const GridRayHit h1 = far.raycast(Ray::make(o + offset, d), ~0u);
    ASSERT_EQ(h0.hit(), h1.hit()) << "ray " << k;
    if (h0.hit()) rayDiff = std::max(rayDiff, std::abs(h0.t - h1.t) * obliquity(Ray::make(o, d), h0));
  }
  EXPECT_LT(rayDiff, 4 * ulpL);
  std::printf("[ local 1e4] max depth diff %.2e, point %.2e, normal %.2e, ray t %.2e (ulp %.2e)\n", diff.depth,
              diff.position, diff.normal, rayDiff, ulpL);
}


// ---------------------------------------------------------------- 4. size ratios

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
  const std::vector<uint32_t> handleOf = handleOfBrick(grid);
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
    expectRayMatches(grid, handleOf, ray, describeRay(ray), rayHits);

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
  const std::vector<uint32_t> handles = handleOfBrick(grid);
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
    ASSERT_EQ(h.brick, lowestHandleBrick(ref.tied, handles)) << "sweep " << q;
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


// ---------------------------------------------------------------- 5. bad values at the API

// Runs f, expects InvalidInput whose message contains `names` (the argument).
template <class F>
void expectRejected(F&& f, const std::string& names, const char* where) {
  try {
    f();
    ADD_FAILURE() << where << ": no InvalidInput (expected one naming \"" << names << "\")";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find(names), std::string::npos) << where << ": " << e.what();
  }
}

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

// The OctoBVH's own limits: coordinates must stay below 2^30 in magnitude (2^30 - 64 is
// accepted), nothing changes on refusal, and a refused update keeps the old element.
TEST(ExtremesBadInput, OctoBvhCoordinateLimitIsExactAndRefusalsChangeNothing) {
  OctoBvh tree;
  const uint32_t h = tree.insert({Vec3f(0, 0, 0), Vec3f(1, 1, 1)}, 1, 7);
  const uint64_t hash = tree.structureHash();
  const float limit = octobvh::kMaxCoordinate, below = std::nextafter(limit, 0.f);
  expectRejected([&] { tree.insert({Vec3f(0, 0, 0), Vec3f(1, limit, 1)}, 1, 0); }, "bounds on y", "max.y = 2^30");
  expectRejected([&] { tree.insert({Vec3f(0, 0, -limit), Vec3f(1, 1, 1)}, 1, 0); }, "bounds on z", "min.z = -2^30");
  expectRejected([&] { tree.insert({Vec3f(0, 0, 0), Vec3f(1, 1, -kInf)}, 1, 0); }, "bounds.max.z", "-inf max");
  expectRejected([&] { tree.update(h, {Vec3f(limit, 0, 0), Vec3f(limit, 1, 1)}, 1); }, "bounds on x", "update beyond 2^30");
  expectRejected([&] { tree.update(h, {Vec3f(0, 2, 0), Vec3f(1, 1, 1)}, 1); }, "bounds.min.y", "inverted update");
  EXPECT_EQ(tree.size(), 1u);
  EXPECT_EQ(tree.structureHash(), hash);
  EXPECT_EQ(tree.bounds(h), (Aabb{Vec3f(0, 0, 0), Vec3f(1, 1, 1)}));
  const uint32_t e = tree.insert({Vec3f(-below, -below, -below), Vec3f(below, below, below)}, 1, 8);
  tree.validate();
  tree.remove(e);
  EXPECT_EQ(tree.structureHash(), hash);
}

}  // namespace
}  // namespace bw
