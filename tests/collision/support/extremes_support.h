#pragma once
// Shared helpers for the collision extremes suites (index/octobvh_extremes_test.cpp and the
// bricks/grid_*_test.cpp files): non-finite constants, timing, a seeded shuffle, the
// "refused by name" check, and brute-force references for grid rays and sweeps with the tie rule.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <gtest/gtest.h>
#include <limits>
#include <string>
#include <vector>

#include "collision/bricks/brick_grid.h"
#include "collision/bricks/brick_narrowphase.h"
#include "collision/core/argument_checks.h"
#include "collision/core/seeded_random.h"

namespace bw::test {

inline constexpr float kInf = std::numeric_limits<float>::infinity();
inline constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

inline double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

template <class T>
void shuffle(std::vector<T>& v, SeededRandom& r) {
  for (uint32_t i = uint32_t(v.size()); i > 1; --i) std::swap(v[i - 1], v[r.below(i)]);
}

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

// The closest exact hit over every brick (brute force), with every brick tied at that t.
struct BruteRayHit {
  float t = kInf;
  std::vector<uint32_t> tied;  // ascending ids
  bool hit() const { return !tied.empty(); }
};

inline BruteRayHit bruteRaycast(const BrickGrid& grid, const Ray& ray, uint32_t mask) {
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

inline BruteSweepHit bruteSweep(const BrickGrid& grid, const QueryShape& shape, const Quatf& rot, const Vec3f& from,
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

// Whether `brick` is one of the bricks tied at the closest t (the grid reports the first of them
// its index meets: which one is not part of the contract).
inline bool isTied(const std::vector<uint32_t>& tied, uint32_t brick) {
  return std::find(tied.begin(), tied.end(), brick) != tied.end();
}

// One ray against the grid and brute force. Tie rule: brick shapes are closed, so a ray that only
// touches a face, an edge or a corner hits (rayBrick and the index's slab tests agree on that,
// the index being conservative: every brick rayBrick hits is a candidate); the grid returns
// exactly rayBrick's smallest t and one of the bricks tied at that t.
inline void expectRayMatches(const BrickGrid& grid, const Ray& ray, const std::string& what, int& hits) {
  const GridRayHit h = grid.raycast(ray, ~0u);
  const BruteRayHit ref = bruteRaycast(grid, ray, ~0u);
  ASSERT_EQ(h.hit(), ref.hit()) << what;
  if (!h.hit()) return;
  ++hits;
  ASSERT_FALSE(std::isnan(h.t)) << what;
  ASSERT_EQ(h.t, ref.t) << what;
  ASSERT_TRUE(isTied(ref.tied, h.brick)) << what << ": brick " << h.brick << " is not one of " << ref.tied.size() << " tied";
  ASSERT_TRUE(h.normal.allFinite()) << what;
  ASSERT_NEAR(h.normal.norm(), 1.f, 1e-5f) << what << " normal " << h.normal.transpose();
}

inline std::string describeRay(const Ray& r) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "ray o(%.9g %.9g %.9g) d(%.9g %.9g %.9g) maxT %.9g", r.origin.x(), r.origin.y(),
                r.origin.z(), r.dir.x(), r.dir.y(), r.dir.z(), r.maxT);
  return buf;
}

}  // namespace bw::test
