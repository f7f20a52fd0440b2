// Real content through the brick grid and its OctoBVH: Lighthouse_Island.brs (25,427 bricks) and
// a 2 x 2 tiling of it. Every query type (AABB, OBB and LOD overlap, closest/any/all raycasts on
// bounds and on exact shapes, sweeps, contacts) against brute force over every brick, with
// seeded queries concentrated where the bricks are; then the build removed brick by brick in a
// seeded random order back to an empty index. Also tileBuild() itself.
//
// note: brute-force references that call an expensive exact test (GJK sweeps and contacts) first
// reject bricks whose bounds, grown by a slack the index does not use, miss the query: every
// brick is still visited, and the slack lets the reference find hits the index's pruning would not.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <gtest/gtest.h>
#include <limits>
#include <map>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "collision/bricks/brick_grid.h"
#include "collision/content/brs_reader.h"
#include "collision/content/build_tiling.h"
#include "collision/core/argument_checks.h"
#include "collision/core/seeded_random.h"
#include "collision/support/brute_force_index.h"

namespace bw {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// The shared data folder is a sibling of the repository: <repo>/../shared/data.
std::filesystem::path lighthousePath() {
  namespace fs = std::filesystem;
  const fs::path repo = fs::path(__FILE__).parent_path().parent_path().parent_path().parent_path();
  const fs::path candidate = repo / ".." / "shared" / "data" / "Lighthouse_Island.brs";
  if (fs::exists(candidate)) return candidate;
  const fs::path fromCwd = fs::current_path() / ".." / "shared" / "data" / "Lighthouse_Island.brs";
  return fs::exists(fromCwd) ? fromCwd : candidate;
}

const BrsLoadResult& lighthouse() {
  static const BrsLoadResult r = loadBrs(lighthousePath().string());
  return r;
}

// The save's bricks with filter bits spread over three bits (the save has one), so masks select
// real subsets of real geometry.
std::vector<Brick> withFilters(std::vector<Brick> bricks) {
  for (size_t k = 0; k < bricks.size(); ++k) bricks[k].filter = 1u << (k % 3);
  return bricks;
}
const std::vector<Brick>& lighthouseBricks() {
  static const std::vector<Brick> b = withFilters(lighthouse().bricks);
  return b;
}
const std::vector<Brick>& tiled2x2() {
  static const std::vector<Brick> b = withFilters(tileBuild(lighthouse().bricks, lighthouse().bounds, 2, 2, 4.f));
  return b;
}

class RealBuild : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(std::filesystem::exists(lighthousePath()))
        << "missing " << lighthousePath() << ": the shared data folder must sit next to the repository";
  }
};

// ---------------------------------------------------------------- brute force over a grid

// Snapshot of the bricks in a grid: ids, exact bounds and OctoBVH handles, for brute force.
struct Snapshot {
  std::vector<uint32_t> ids;
  std::vector<Aabb> bounds;
  std::vector<Vec3f> centres;
  std::map<uint32_t, uint32_t> handleOf;  // brick id -> element handle
  test::BruteForceIndex elements;         // by element handle

  explicit Snapshot(const BrickGrid& grid) {
    grid.forEachBrick([&](uint32_t id) {
      ids.push_back(id);
      bounds.push_back(brickBounds(grid.brick(id)));
      centres.push_back(grid.brick(id).position);
    });
    const OctoBvh& index = grid.index();
    index.forEachElement([&](uint32_t h) {
      handleOf[index.payload(h)] = h;
      elements.items[h] = {index.bounds(h), index.filter(h)};
    });
  }
};

uint32_t maskFor(int q) { return q % 4 == 0 ? 0xFFFFFFFFu : 1u << (q % 3); }

Vec3f randomUnit(SeededRandom& r) {
  const Vec3f v(float(r.normal()), float(r.normal()), float(r.normal()));
  return v.isZero() ? Vec3f::UnitX() : v.normalized();
}

// Query generator: centres at random brick centres (jittered), sizes log-uniform.
struct Queries {
  const Snapshot& snap;
  SeededRandom& r;
  Vec3f nearBrick() { return snap.centres[r.below(uint32_t(snap.centres.size()))] + randomUnit(r) * float(r.uniform(0, 0.3)); }
  const Aabb& someBounds() { return snap.bounds[r.below(uint32_t(snap.bounds.size()))]; }
  // Full sizes 0.04..50 per axis (cubes half the time).
  Vec3f halfSize() {
    if (r.below(2)) return Vec3f::Constant(float(r.logUniform(0.02, 25)));
    return Vec3f(float(r.logUniform(0.02, 25)), float(r.logUniform(0.02, 25)), float(r.logUniform(0.02, 25)));
  }
  // Rays between brick centres (segments or unlimited), along lattice planes (the origin on a
  // brick's face plane, the direction inside that plane or along a lattice axis), and from
  // outside the build aimed at a brick.
  Ray ray(int q) {
    const Vec3f a = snap.centres[r.below(uint32_t(snap.centres.size()))];
    const Vec3f b = snap.centres[r.below(uint32_t(snap.centres.size()))];
    switch (q % 4) {
      case 0:
        if (a == b) return Ray::make(a, Vec3f::UnitZ(), 3.f);
        return Ray::make(a, b - a, 1.f);  // exactly the segment a..b
      case 1: {
        const Aabb& f = someBounds();
        const int axis = int(r.below(3));
        Vec3f o = f.center();
        o[axis] = r.below(2) ? f.min[axis] : f.max[axis];
        Vec3f d = b - a;
        d[axis] = 0.f;
        if (r.below(3) == 0 || d.isZero()) d = Vec3f::Zero(), d[(axis + 1 + r.below(2)) % 3] = r.below(2) ? 1.f : -1.f;
        return Ray::make(o, d.normalized(), r.below(2) ? kInf : float(r.logUniform(0.1, 200)));
      }
      case 2: {
        const Vec3f d = randomUnit(r);
        return Ray::make(a - d * 300.f, d, kInf);
      }
      default: {
        const Vec3f d = randomUnit(r);
        return Ray::make(nearBrick(), d, float(r.logUniform(0.05, 100)));
      }
    }
  }
};

bool sameHits(const std::vector<RayHit>& a, const std::vector<RayHit>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i].element != b[i].element || a[i].t != b[i].t) return false;
  return true;
}

QueryShape shapeFor(int k, float scale, std::vector<Vec3f>& hullPoints) {
  switch (k % 4) {
    case 0: return QueryShape::sphere(0.7f * scale);
    case 1: return QueryShape::box(Vec3f(0.9f, 0.5f, 0.3f) * scale);
    case 2: return QueryShape::capsule(0.4f * scale, 0.8f * scale);
    default: {
      hullPoints.clear();
      for (int i = 0; i < 8; ++i)
        hullPoints.emplace_back(((i & 1) ? 0.6f : -0.6f) * scale, ((i & 2) ? 0.4f : -0.4f) * scale, ((i & 4) ? 0.5f : -0.5f) * scale);
      hullPoints.emplace_back(0.f, 0.f, 0.9f * scale);
      return QueryShape::hull(hullPoints.data(), uint32_t(hullPoints.size()));
    }
  }
}

Quatf randomRotation(SeededRandom& r) { return Quatf(Eigen::AngleAxisf(float(r.uniform(0, 6.28)), randomUnit(r))); }

// Counts of non-empty answers, so a test can insist its queries actually met bricks.
struct Coverage {
  int overlaps = 0, rays = 0, exactRays = 0, sweeps = 0, contacts = 0, lodBoxes = 0;
};

// Every query type of the grid and its OctoBVH against brute force over the grid's bricks.
void expectQueriesMatchBruteForce(const BrickGrid& grid, SeededRandom& r, int queries, int narrowphaseQueries,
                                  Coverage& cover) {
  const Snapshot snap(grid);
  ASSERT_FALSE(snap.ids.empty());
  const OctoBvh& index = grid.index();
  Queries gen{snap, r};
  std::vector<uint32_t> got;
  for (int q = 0; q < queries; ++q) {
    SCOPED_TRACE("query " + std::to_string(q));
    const uint32_t mask = maskFor(q);

    // AABB overlap: on the index (element handles) and on the grid (brick ids).
    const Aabb box = Aabb::fromCenterHalf(gen.nearBrick(), gen.halfSize());
    const std::vector<uint32_t> expected = snap.elements.overlap(box, mask);
    got.clear();
    index.overlap(box, mask, got);
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, expected) << "AABB overlap";
    cover.overlaps += !expected.empty();
    std::vector<uint32_t> expectedIds;
    for (size_t i = 0; i < snap.ids.size(); ++i)
      if ((grid.brick(snap.ids[i]).filter & mask) && snap.bounds[i].overlaps(box)) expectedIds.push_back(snap.ids[i]);
    got.clear();
    grid.overlapBricks(box, mask, got);
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, expectedIds) << "BrickGrid::overlapBricks";

    // OBB overlap.
    const Obb obb{gen.nearBrick(), gen.halfSize(), randomRotation(r).toRotationMatrix()};
    got.clear();
    index.overlap(obb, mask, got);
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, snap.elements.overlap(obb, mask)) << "OBB overlap";

    // LOD overlap: elements reported one by one overlap the box, small subtrees come back as
    // boxes, and every overlapping element is either reported or inside a LOD box.
    const float fraction = q % 3 == 0 ? 0.f : q % 3 == 1 ? 1.f / 16 : 1.f / 4;
    const float threshold = fraction * box.extent().maxCoeff();
    std::vector<uint32_t> direct;
    std::vector<LodBox> lods;
    index.overlapLod(box, mask, fraction, [&](uint32_t e) { direct.push_back(e); }, [&](const LodBox& l) { lods.push_back(l); });
    std::sort(direct.begin(), direct.end());
    ASSERT_TRUE(std::adjacent_find(direct.begin(), direct.end()) == direct.end()) << "LOD overlap reported an element twice";
    uint64_t standIns = direct.size();
    for (const LodBox& l : lods) {
      ASSERT_TRUE(l.bounds.overlaps(box));
      ASSERT_LT(l.bounds.extent().maxCoeff(), threshold) << "a LOD box larger than the fraction";
      ASSERT_TRUE(l.filter & mask);
      standIns += l.elements;
    }
    for (uint32_t e : direct) ASSERT_TRUE(std::binary_search(expected.begin(), expected.end(), e)) << "LOD overlap element " << e;
    for (uint32_t e : expected) {
      if (std::binary_search(direct.begin(), direct.end(), e)) continue;
      const Aabb eb = index.bounds(e);
      ASSERT_TRUE(std::any_of(lods.begin(), lods.end(), [&](const LodBox& l) { return l.bounds.contains(eb); }))
          << "element " << e << " overlaps the box but is neither reported nor inside a LOD box";
    }
    ASSERT_GE(standIns, expected.size());
    if (fraction == 0.f) {
      ASSERT_EQ(direct, expected) << "LOD off is a plain overlap";
    }
    cover.lodBoxes += int(lods.size());

    // Rays on element bounds: closest, any, all.
    const Ray ray = gen.ray(q);
    const std::vector<RayHit> all = snap.elements.raycastAll(ray, mask);
    const RayHit closest = index.raycastClosest(ray, mask);
    ASSERT_EQ(closest.hit(), !all.empty()) << "raycastClosest";
    if (closest.hit()) {
      ASSERT_EQ(closest.t, all.front().t);
      ASSERT_TRUE(std::any_of(all.begin(), all.end(), [&](const RayHit& h) { return h.element == closest.element && h.t == closest.t; }))
          << "the reported element is one hit at the closest t";
    }
    const RayHit any = index.raycastAny(ray, mask);
    ASSERT_EQ(any.hit(), !all.empty()) << "raycastAny";
    if (any.hit()) {
      ASSERT_TRUE(std::any_of(all.begin(), all.end(), [&](const RayHit& h) { return h.element == any.element && h.t == any.t; }));
    }
    std::vector<RayHit> gotAll;
    index.raycastAll(ray, mask, gotAll);
    ASSERT_TRUE(sameHits(gotAll, all)) << "raycastAll: " << gotAll.size() << " hits, expected " << all.size();
    cover.rays += !all.empty();

    // Rays on exact brick shapes: the grid's closest hit, and all/any hits through exact hooks.
    // note: a brick counts when the ray enters its bounds and its shape (the exact hook's
    // contract), with no slack: rays between lattice-aligned brick centres often run exactly
    // along a brick's edge, where rayBrick (brick frame) and the bounds test (grid frame) round
    // differently, so rayBrick alone can report an edge touch whose bounds the ray misses by an ulp.
    std::vector<RayHit> exactAll;  // by element handle
    for (size_t i = 0; i < snap.ids.size(); ++i) {
      const Brick& b = grid.brick(snap.ids[i]);
      float t;
      Vec3f n;
      if (!(b.filter & mask) || !intersectRayAabb(ray, snap.bounds[i], 0.f, ray.maxT, t)) continue;
      if (rayBrick(b, ray, ray.maxT, t, n)) exactAll.push_back({snap.handleOf.at(snap.ids[i]), t});
    }
    std::sort(exactAll.begin(), exactAll.end());
    auto exactHook = [&](uint32_t e, float, float tMax, float& tHit) {
      Vec3f n;
      return rayBrick(grid.brick(index.payload(e)), ray, tMax, tHit, n);
    };
    const GridRayHit gridHit = grid.raycast(ray, mask);
    ASSERT_EQ(gridHit.hit(), !exactAll.empty()) << "BrickGrid::raycast";
    if (gridHit.hit()) {
      ASSERT_EQ(gridHit.t, exactAll.front().t) << "BrickGrid::raycast";
      ASSERT_TRUE(std::any_of(exactAll.begin(), exactAll.end(), [&](const RayHit& h) {
        return h.t == gridHit.t && index.payload(h.element) == gridHit.brick;
      })) << "the reported brick is one hit at the closest t";
    }
    std::vector<RayHit> gotExact;
    index.raycastAll(ray, mask, gotExact, nullptr, exactHook);
    ASSERT_TRUE(sameHits(gotExact, exactAll)) << "exact raycastAll: " << gotExact.size() << " hits, expected " << exactAll.size();
    const RayHit anyExact = index.raycastAny(ray, mask, nullptr, exactHook);
    ASSERT_EQ(anyExact.hit(), !exactAll.empty()) << "exact raycastAny";
    if (anyExact.hit()) {
      ASSERT_TRUE(std::any_of(exactAll.begin(), exactAll.end(),
                              [&](const RayHit& h) { return h.element == anyExact.element && h.t == anyExact.t; }));
    }
    cover.exactRays += !exactAll.empty();

    if (q >= narrowphaseQueries) continue;
    std::vector<Vec3f> hull;
    const float scale = float(r.logUniform(0.05, 5));
    const QueryShape shape = shapeFor(q, scale, hull);
    const Quatf rot = randomRotation(r);
    const Vec3f grow = rot.toRotationMatrix().cwiseAbs() * shape.localHalfExtents();

    // Sweep from near one brick towards another (some straight down onto the build).
    const Vec3f from = gen.nearBrick() + Vec3f(0, 0, float(r.uniform(0, 3)));
    const Vec3f to = q % 5 == 0 ? Vec3f(from - Vec3f(0, 0, 20.f)) : Vec3f(gen.nearBrick() + randomUnit(r) * float(r.uniform(0, 2)));
    const Ray motion = Ray::make(from, to - from, 1.f);
    float best = 2.f;
    std::vector<std::pair<float, uint32_t>> sweepHits;
    for (size_t i = 0; i < snap.ids.size(); ++i) {
      const Brick& b = grid.brick(snap.ids[i]);
      float t, f;
      Vec3f n, p;
      const float slack = 0.01f + 2e-4f * (1.f + b.halfSize.maxCoeff());
      if (!(b.filter & mask) || !intersectRayAabb(motion, snap.bounds[i].expanded(grow + Vec3f::Constant(slack)), 0.f, 1.f, t)) continue;
      if (sweepShapeBrick(shape, rot, from, to, b, f, n, p)) {
        best = std::min(best, f);
        sweepHits.emplace_back(f, snap.ids[i]);
      }
    }
    const GridSweepHit sweep = grid.sweep(shape, rot, from, to, mask);
    ASSERT_EQ(sweep.hit(), best <= 1.f) << "BrickGrid::sweep";
    if (sweep.hit()) {
      ASSERT_EQ(sweep.fraction, best) << "BrickGrid::sweep";
      ASSERT_TRUE(std::find(sweepHits.begin(), sweepHits.end(), std::make_pair(best, sweep.brick)) != sweepHits.end())
          << "the reported brick is one hit at the first time of impact";
    }
    cover.sweeps += sweep.hit();

    // Contacts (LOD off): the same per-brick contacts as the narrowphase over every brick.
    ContactParams params;
    params.mask = mask;
    params.lodFraction = 0.f;
    params.speculativeMargin = q % 2 ? 0.05f : 0.f;
    const LocalPose pose{gen.nearBrick(), rot};
    std::vector<LocalContact> contacts;
    grid.collideLocal(shape, pose, params, contacts);
    const Aabb reach = Aabb::fromCenterHalf(pose.position, grow + Vec3f::Constant(params.speculativeMargin + 0.01f));
    std::vector<LocalContact> expectedContacts;
    LocalContact buf[kMaxContactsPerBrick];
    for (size_t i = 0; i < snap.ids.size(); ++i) {
      const Brick& b = grid.brick(snap.ids[i]);
      if (!(b.filter & mask) || !snap.bounds[i].overlaps(reach)) continue;
      const int n = collideShapeBrick(shape, pose, b, snap.ids[i], params.speculativeMargin, buf);
      expectedContacts.insert(expectedContacts.end(), buf, buf + n);
    }
    auto keys = [](const std::vector<LocalContact>& cs) {
      std::vector<std::pair<uint32_t, float>> k;
      for (const LocalContact& c : cs) k.emplace_back(c.feature, c.depth);
      std::sort(k.begin(), k.end());
      return k;
    };
    ASSERT_EQ(keys(contacts), keys(expectedContacts)) << "BrickGrid::collideLocal";
    cover.contacts += !contacts.empty();
  }
}

// Places the bricks, checks every query, removes them all in a seeded random order with
// checkpoints, and checks the grid ends exactly empty.
void roundTrip(const std::vector<Brick>& bricks, uint64_t seed, int queries, int narrowphaseQueries,
               int checkpointQueries) {
  BrickGrid grid(BrickGrid::Config(uint32_t(bricks.size()) + 1024));
  const OctoBvh fresh(OctoBvh::Config{uint32_t(bricks.size()) + 1024});
  const OctoBvh::MemoryStats emptyStats = fresh.memoryStats();
  std::vector<uint32_t> ids;
  for (const Brick& b : bricks) ids.push_back(grid.placeBrick(b));
  ASSERT_EQ(grid.brickCount(), bricks.size());
  const Aabb full = grid.bounds();
  const size_t peakResident = grid.index().residentBytes();
  grid.index().validate();

  SeededRandom r(seed);
  Coverage cover;
  expectQueriesMatchBruteForce(grid, r, queries, narrowphaseQueries, cover);
  if (::testing::Test::HasFatalFailure()) return;
  EXPECT_GT(cover.overlaps, queries * 3 / 4);
  EXPECT_GT(cover.rays, queries / 2);
  EXPECT_GT(cover.exactRays, queries / 3);
  EXPECT_GT(cover.sweeps, narrowphaseQueries / 4);
  EXPECT_GT(cover.contacts, narrowphaseQueries / 4);
  EXPECT_GT(cover.lodBoxes, 0);

  // Remove every brick in a seeded random order (Fisher-Yates).
  for (size_t i = ids.size(); i > 1; --i) std::swap(ids[i - 1], ids[r.below(uint32_t(i))]);
  const size_t n = ids.size();
  const std::set<size_t> checkpoints = {n * 3 / 4, n / 2, n / 4, n / 50, 7};  // bricks left
  for (size_t k = 0; k < n; ++k) {
    grid.removeBrick(ids[k]);
    const size_t left = n - k - 1;
    if (!checkpoints.count(left)) continue;
    SCOPED_TRACE(std::to_string(left) + " bricks left");
    ASSERT_EQ(grid.brickCount(), left);
    grid.index().validate();
    // Canonical: the index equals a fresh build of the bricks that are left.
    OctoBvh rebuilt(OctoBvh::Config{uint32_t(n) + 1024});
    grid.forEachBrick([&](uint32_t id) { rebuilt.insert(brickBounds(grid.brick(id)), grid.brick(id).filter, id); });
    ASSERT_EQ(grid.index().structureHash(), rebuilt.structureHash());
    Coverage c;
    expectQueriesMatchBruteForce(grid, r, checkpointQueries, checkpointQueries / 4, c);
    if (::testing::Test::HasFatalFailure()) return;
  }

  // Back to empty: no bricks, no elements, the node and block counts of a fresh index.
  EXPECT_EQ(grid.brickCount(), 0u);
  EXPECT_TRUE(grid.index().empty());
  EXPECT_EQ(grid.massProperties().mass, 0.0);
  const OctoBvh::MemoryStats m = grid.index().memoryStats();
  EXPECT_EQ(m.elements, 0u);
  EXPECT_EQ(m.nonEmptyNodes, 0u);
  EXPECT_EQ(m.leafBlocks, 0u);
  EXPECT_EQ(m.overflowBlocks, 0u);
  EXPECT_EQ(m.clusters, emptyStats.clusters);
  EXPECT_EQ(m.totalBytes(), emptyStats.totalBytes());
  EXPECT_EQ(grid.index().rootLevel(), fresh.rootLevel());
  // note: pools keep one spare block each and their block bookkeeping resident (by design, see
  // pool_index_space.h), so resident memory falls back near, not exactly to, a fresh index's.
  EXPECT_LT(grid.index().residentBytes(), peakResident / 10)
      << "pages of removed bricks go back to the system (peak " << peakResident << " bytes)";
  EXPECT_EQ(grid.index().structureHash(), fresh.structureHash());
  EXPECT_TRUE(grid.bounds().isEmpty());
  grid.index().validate();
  std::vector<uint32_t> left;
  grid.overlapBricks(full.expanded(1.f), ~0u, left);
  EXPECT_TRUE(left.empty());
  std::vector<uint32_t> elems;
  grid.index().overlap(Obb::fromAabb(full), ~0u, elems);
  EXPECT_TRUE(elems.empty());
  EXPECT_FALSE(grid.raycast(Ray::make(full.min - Vec3f::Constant(1.f), full.extent()), ~0u).hit());
  std::vector<RayHit> hits;
  grid.index().raycastAll(Ray::make(full.max + Vec3f::Constant(1.f), -full.extent()), ~0u, hits);
  EXPECT_TRUE(hits.empty());
  std::vector<LocalContact> contacts;
  grid.collideLocal(QueryShape::box(full.halfExtent()), LocalPose{full.center(), Quatf::Identity()}, ContactParams{}, contacts);
  EXPECT_TRUE(contacts.empty());
  EXPECT_FALSE(grid.sweep(QueryShape::sphere(1.f), Quatf::Identity(), full.min, full.max, ~0u).hit());
}

TEST_F(RealBuild, LighthouseQueriesMatchBruteForceAndRemovalEmptiesTheIndex) {
  roundTrip(lighthouseBricks(), 101, 400, 120, 60);
}

TEST_F(RealBuild, TiledLighthouseQueriesMatchBruteForceAndRemovalEmptiesTheIndex) {
  roundTrip(tiled2x2(), 202, 120, 40, 20);
}

// ---------------------------------------------------------------- tileBuild

TEST_F(RealBuild, LighthouseExtentsAndTiledCounts) {
  const BrsLoadResult& save = lighthouse();
  // The extents `brickworld inspect` prints (RESULTS.md), agreeing with the independent bounds
  // computation in brs_reader_test.cpp.
  EXPECT_NEAR(save.bounds.min.x(), 131.60f, 1e-3f);
  EXPECT_NEAR(save.bounds.min.y(), 21.20f, 1e-3f);
  EXPECT_NEAR(save.bounds.min.z(), 8.80f, 1e-3f);
  EXPECT_NEAR(save.bounds.max.x(), 260.40f, 1e-3f);
  EXPECT_NEAR(save.bounds.max.y(), 158.40f, 1e-3f);
  EXPECT_NEAR(save.bounds.max.z(), 45.84f, 1e-3f);
  // ~2.5M bricks, the article's build size: 10 x 10 tiles.
  EXPECT_EQ(tilesForTarget(save.bricks.size(), 2'500'000), 10);
  EXPECT_EQ(10u * 10u * save.bricks.size(), 2'542'700u);
}

TEST_F(RealBuild, TileBuildPlacesEachTileAtItsOffset) {
  const BrsLoadResult& save = lighthouse();
  const float gap = 4.f;
  const std::vector<Brick> t = tileBuild(save.bricks, save.bounds, 3, 2, gap);
  const size_t n = save.bricks.size();
  ASSERT_EQ(t.size(), 6 * n);
  const Vec3f ext = save.bounds.extent();
  Aabb all = Aabb::empty();
  for (const Brick& b : t) all.merge(brickBounds(b));
  EXPECT_NEAR(all.min.x(), save.bounds.min.x(), 1e-3f);
  EXPECT_NEAR(all.min.y(), save.bounds.min.y(), 1e-3f);
  EXPECT_NEAR(all.max.x(), save.bounds.max.x() + 2 * (ext.x() + gap), 1e-3f);
  EXPECT_NEAR(all.max.y(), save.bounds.max.y() + 1 * (ext.y() + gap), 1e-3f);
  EXPECT_EQ(all.min.z(), save.bounds.min.z());
  EXPECT_EQ(all.max.z(), save.bounds.max.z());
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 3; ++i)
      for (size_t k = 0; k < n; k += 97) {
        const Brick& a = save.bricks[k];
        const Brick& b = t[(size_t(j) * 3 + size_t(i)) * n + k];
        ASSERT_EQ(b.position.x(), float(double(a.position.x()) + i * (double(ext.x()) + gap)));
        ASSERT_EQ(b.position.y(), float(double(a.position.y()) + j * (double(ext.y()) + gap)));
        ASSERT_EQ(b.position.z(), a.position.z());
        ASSERT_EQ(b.halfSize, a.halfSize);
        ASSERT_EQ(b.rotation, a.rotation);
        ASSERT_EQ(b.shape, a.shape);
        ASSERT_EQ(b.sides, a.sides);
        ASSERT_EQ(b.filter, a.filter);
        ASSERT_EQ(b.material, a.material);
      }
  // Tiles do not overlap each other: the bounds of tile (1, 0) start a gap after tile (0, 0)'s.
  Aabb tile1 = Aabb::empty();
  for (size_t k = 0; k < n; ++k) tile1.merge(brickBounds(t[n + k]));
  EXPECT_NEAR(tile1.min.x() - save.bounds.max.x(), gap, 1e-3f);
  // One tile is the input.
  const std::vector<Brick> one = tileBuild(save.bricks, save.bounds, 1, 1, 0.f);
  ASSERT_EQ(one.size(), n);
  for (size_t k = 0; k < n; ++k) ASSERT_EQ(one[k].position, save.bricks[k].position);
}

TEST(BuildTiling, BadArgumentsAreRejected) {
  const std::vector<Brick> bricks = {Brick::box(Vec3f(0, 0, 0), Vec3f::Constant(0.5f)), Brick::box(Vec3f(2, 0, 0), Vec3f::Constant(0.5f))};
  const Aabb bounds{Vec3f(-0.5f, -0.5f, -0.5f), Vec3f(2.5f, 0.5f, 0.5f)};
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(tileBuild(bricks, bounds, 0, 1, 0.f), InvalidInput);
  EXPECT_THROW(tileBuild(bricks, bounds, 1, 0, 0.f), InvalidInput);
  EXPECT_THROW(tileBuild(bricks, bounds, -3, 2, 0.f), InvalidInput);
  EXPECT_THROW(tileBuild(bricks, bounds, kMaxTilesPerAxis + 1, 1, 0.f), InvalidInput);
  EXPECT_THROW(tileBuild(bricks, bounds, 2, 2, -0.1f), InvalidInput);
  EXPECT_THROW(tileBuild(bricks, bounds, 2, 2, nan), InvalidInput);
  EXPECT_THROW(tileBuild(bricks, bounds, 2, 2, kInf), InvalidInput);
  EXPECT_THROW(tileBuild(bricks, Aabb::empty(), 2, 2, 0.f), InvalidInput);
  EXPECT_THROW(tileBuild(bricks, Aabb{Vec3f(nan, 0, 0), Vec3f(1, 1, 1)}, 2, 2, 0.f), InvalidInput);
  // 5 bricks on 4096 x 4096 tiles would be 5 * 2^24 > kMaxTiledBricks.
  std::vector<Brick> five(5, bricks[0]);
  EXPECT_THROW(tileBuild(five, bounds, kMaxTilesPerAxis, kMaxTilesPerAxis, 0.f), InvalidInput);
  // Tiles that would leave the grid-local range.
  EXPECT_THROW(tileBuild(bricks, bounds, 3, 1, 6e8f), InvalidInput);
  EXPECT_THROW(tileBuild(bricks, bounds, 1, 3, 6e8f), InvalidInput);
  EXPECT_NO_THROW(tileBuild(bricks, bounds, 3, 1, 4e8f));
  try {
    tileBuild(bricks, bounds, 2, 0, 0.f);
    ADD_FAILURE() << "no exception";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("tilesY"), std::string::npos) << e.what();
  }
  // No bricks: nothing to tile, whatever the bounds.
  EXPECT_TRUE(tileBuild({}, Aabb::empty(), 4, 4, 1.f).empty());
  EXPECT_EQ(tileBuild(bricks, bounds, 4, 3, 1.f).size(), 24u);

  EXPECT_THROW(tilesForTarget(0, 100), InvalidInput);
  EXPECT_THROW(tilesForTarget(10, 0), InvalidInput);
  EXPECT_EQ(tilesForTarget(1000, 1), 1);
  EXPECT_EQ(tilesForTarget(100, 100), 1);
  EXPECT_EQ(tilesForTarget(100, 400), 2);
  EXPECT_EQ(tilesForTarget(100, 1200), 3);   // 900 is 300 away, 1600 is 400 away
  EXPECT_EQ(tilesForTarget(100, 1300), 4);   // 900 is 400 away, 1600 is 300 away
  EXPECT_EQ(tilesForTarget(1, size_t(1) << 40), kMaxTilesPerAxis);
}

}  // namespace
}  // namespace bw
