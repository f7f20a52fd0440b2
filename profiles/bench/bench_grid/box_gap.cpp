// bench_grid, the gap between a box and a box brick it does not touch (a speculative contact):
// 4,096 seeded pairs, a box of 0.2-2 m against a brick of 0.1-2 m, random rotations, apart by
// 0-5 cm along one of the brick's face normals tilted up to ~30 degrees (a crate near bricks
// within the world's speculative margin). Both rows measure the same pairs in the same run.
//
// BoxGap_ClosedForm: separatedBoxGap (collision/bricks/box_box_gap.h), what collideBoxes runs
//   now: time per pair, answered (the share it answers; the rest would go to GJK).
// BoxGap_btGjkEpa: btGjkEpaSolver2::Distance on two zero-margin btBoxShapes, what collideBoxes
//   ran before (our before/after, not Bullet as its experts run it): time per pair, and its
//   accuracy against the closed form (exact to float rounding:
//   tests/collision/bricks/box_box_gap_test.cpp checks it against brute force), gap_err_max (m)
//   and normal_err_max.
// BoxGap_btGjkPairDetector/margin_mm:M: the path Bullet's own world runs for a convex pair that
//   wants closest points (btConvexConvexAlgorithm: btGjkPairDetector with a
//   btVoronoiSimplexSolver and a btGjkEpaPenetrationDepthSolver made once and reused, the
//   detector made per pair as the algorithm makes it per call, the shapes built beforehand as a
//   world holds them), on btBoxShapes with margin 0 and with Bullet's default 0.04 m (the core shrunk by the margin,
//   then swept by a sphere of it: rounded edges and corners, so its gap differs from the box's
//   where the nearest feature is an edge or a corner). Same counters as the row above. Note: a
//   Bullet world's box-box pairs go to btBoxBoxCollisionAlgorithm instead, which reports no
//   contact for separated boxes at all: no speculative contact to compare.
#include <BulletCollision/NarrowPhaseCollision/btGjkEpa2.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkPairDetector.h>
#include <BulletCollision/NarrowPhaseCollision/btPointCollector.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>
#include <benchmark/benchmark.h>
#include <btBulletCollisionCommon.h>
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include "collision/bricks/box_box_gap.h"
#include "collision/core/seeded_random.h"

namespace bw {
namespace {

struct BoxPair {
  Vec3f halfA, halfB, centreA, centreB;
  Mat3f rotationA, rotationB;
};

Mat3f seededRotation(SeededRandom& r) {
  const float w = float(r.normal()), x = float(r.normal()), y = float(r.normal()), z = float(r.normal());
  return Quatf(w, x, y, z).normalized().toRotationMatrix();
}

Vec3f seededVector(SeededRandom& r, double lo, double hi) {
  const float x = float(r.uniform(lo, hi)), y = float(r.uniform(lo, hi)), z = float(r.uniform(lo, hi));
  return {x, y, z};
}

const std::vector<BoxPair>& pairs() {
  static const std::vector<BoxPair> all = [] {
    SeededRandom r(77);
    std::vector<BoxPair> out;
    while (out.size() < 4096) {
      BoxPair p;
      p.halfA = seededVector(r, 0.1, 1.0);
      p.halfB = seededVector(r, 0.05, 1.0);
      p.rotationA = seededRotation(r);
      p.rotationB = seededRotation(r);
      p.centreB = seededVector(r, -50, 50);
      // Apart along a tilted face normal of b by the boxes' projected radii plus the gap: their
      // separation along that direction is the gap, so they are that far apart or more.
      Vec3f n = p.rotationB.col(int(r.below(3))) * (r.below(2) ? 1.f : -1.f) + seededVector(r, -0.3, 0.3);
      n.normalize();
      const float radii = (p.rotationA.transpose() * n).cwiseAbs().dot(p.halfA) + (p.rotationB.transpose() * n).cwiseAbs().dot(p.halfB);
      p.centreA = p.centreB + n * (radii + float(r.uniform(0.0005, 0.05)));
      out.push_back(p);
    }
    return out;
  }();
  return all;
}

btTransform transformOf(const Mat3f& m, const Vec3f& c) {
  btMatrix3x3 basis(m(0, 0), m(0, 1), m(0, 2), m(1, 0), m(1, 1), m(1, 2), m(2, 0), m(2, 1), m(2, 2));
  return btTransform(basis, btVector3(c.x(), c.y(), c.z()));
}

void BoxGap_ClosedForm(benchmark::State& state) {
  const std::vector<BoxPair>& all = pairs();
  size_t i = 0, answered = 0, asked = 0;
  for (auto _ : state) {
    const BoxPair& p = all[i++ & (all.size() - 1)];
    const std::optional<BoxGap> g = separatedBoxGap(p.halfA, p.rotationA, p.centreA, p.halfB, p.rotationB, p.centreB);
    benchmark::DoNotOptimize(g);
    answered += g.has_value();
    ++asked;
  }
  state.counters["answered"] = double(answered) / double(asked);
  state.SetItemsProcessed(int64_t(asked));
}

void BoxGap_btGjkEpa(benchmark::State& state) {
  const std::vector<BoxPair>& all = pairs();
  size_t i = 0;
  for (auto _ : state) {
    const BoxPair& p = all[i++ & (all.size() - 1)];
    btBoxShape a(btVector3(p.halfA.x(), p.halfA.y(), p.halfA.z())), b(btVector3(p.halfB.x(), p.halfB.y(), p.halfB.z()));
    a.setMargin(0);
    b.setMargin(0);
    const btTransform trA = transformOf(p.rotationA, p.centreA), trB = transformOf(p.rotationB, p.centreB);
    btGjkEpaSolver2::sResults res;
    benchmark::DoNotOptimize(btGjkEpaSolver2::Distance(&a, trA, &b, trB, trA.getOrigin() - trB.getOrigin(), res));
    benchmark::DoNotOptimize(res);
  }
  // Accuracy, untimed: GJK's gap and normal against the closed form on every pair it answers.
  double gapErr = 0, normalErr = 0;
  for (const BoxPair& p : all) {
    const std::optional<BoxGap> g = separatedBoxGap(p.halfA, p.rotationA, p.centreA, p.halfB, p.rotationB, p.centreB);
    btBoxShape a(btVector3(p.halfA.x(), p.halfA.y(), p.halfA.z())), b(btVector3(p.halfB.x(), p.halfB.y(), p.halfB.z()));
    a.setMargin(0);
    b.setMargin(0);
    const btTransform trA = transformOf(p.rotationA, p.centreA), trB = transformOf(p.rotationB, p.centreB);
    btGjkEpaSolver2::sResults res;
    if (!g || !btGjkEpaSolver2::Distance(&a, trA, &b, trB, trA.getOrigin() - trB.getOrigin(), res)) continue;
    // Bullet's normal comes back in a's frame (see gjkEpa in brick_narrowphase.cpp).
    const btVector3 n = (trA.getBasis() * res.normal).normalized();
    gapErr = std::max(gapErr, std::abs(double(res.distance) - double(g->gap)));
    normalErr = std::max(normalErr, double((Vec3f(n.x(), n.y(), n.z()) - g->normal).norm()));
  }
  state.counters["gap_err_max"] = gapErr;
  state.counters["normal_err_max"] = normalErr;
  state.SetItemsProcessed(int64_t(state.iterations()));
}

// One pair through btGjkPairDetector as btConvexConvexAlgorithm runs it (no distance cap: every
// pair here is within a speculative margin). Gap and normal (from b towards a) when it answers.
struct DetectorAnswer {
  bool answered;
  double gap;
  Vec3f normal;
};
// A pair's two boxes as Bullet shapes with the given margin, built once per run.
struct BulletBoxes {
  std::unique_ptr<btBoxShape> a, b;
};
std::vector<BulletBoxes> bulletBoxes(const std::vector<BoxPair>& all, float margin) {
  std::vector<BulletBoxes> out;
  for (const BoxPair& p : all) {
    out.push_back({std::make_unique<btBoxShape>(btVector3(p.halfA.x(), p.halfA.y(), p.halfA.z())),
                   std::make_unique<btBoxShape>(btVector3(p.halfB.x(), p.halfB.y(), p.halfB.z()))});
    out.back().a->setMargin(margin);
    out.back().b->setMargin(margin);
  }
  return out;
}

DetectorAnswer gjkPairDetector(const BoxPair& p, const BulletBoxes& shapes, btVoronoiSimplexSolver& simplex,
                               btGjkEpaPenetrationDepthSolver& epa) {
  btGjkPairDetector detector(shapes.a.get(), shapes.b.get(), &simplex, &epa);
  btGjkPairDetector::ClosestPointInput input;
  input.m_transformA = transformOf(p.rotationA, p.centreA);
  input.m_transformB = transformOf(p.rotationB, p.centreB);
  btPointCollector out;
  detector.getClosestPoints(input, out, nullptr);
  const btVector3& n = out.m_normalOnBInWorld;
  return {out.m_hasResult, double(out.m_distance), Vec3f(n.x(), n.y(), n.z())};
}

void BoxGap_btGjkPairDetector(benchmark::State& state) {
  const std::vector<BoxPair>& all = pairs();
  const std::vector<BulletBoxes> shapes = bulletBoxes(all, float(state.range(0)) * 1e-3f);
  btVoronoiSimplexSolver simplex;
  btGjkEpaPenetrationDepthSolver epa;
  size_t i = 0;
  for (auto _ : state) {
    const size_t k = i++ & (all.size() - 1);
    benchmark::DoNotOptimize(gjkPairDetector(all[k], shapes[k], simplex, epa));
  }
  // Accuracy, untimed, against the closed form on every pair both answer.
  double gapErr = 0, normalErr = 0, answered = 0;
  for (size_t k = 0; k < all.size(); ++k) {
    const BoxPair& p = all[k];
    const std::optional<BoxGap> g = separatedBoxGap(p.halfA, p.rotationA, p.centreA, p.halfB, p.rotationB, p.centreB);
    const DetectorAnswer d = gjkPairDetector(p, shapes[k], simplex, epa);
    answered += d.answered;
    if (!g || !d.answered) continue;
    gapErr = std::max(gapErr, std::abs(d.gap - double(g->gap)));
    normalErr = std::max(normalErr, double((d.normal.normalized() - g->normal).norm()));
  }
  state.counters["answered"] = answered / double(all.size());
  state.counters["gap_err_max"] = gapErr;
  state.counters["normal_err_max"] = normalErr;
  state.SetItemsProcessed(int64_t(state.iterations()));
}

BENCHMARK(BoxGap_ClosedForm);
BENCHMARK(BoxGap_btGjkEpa);
BENCHMARK(BoxGap_btGjkPairDetector)->ArgName("margin_mm")->Arg(0)->Arg(40);

}  // namespace
}  // namespace bw
