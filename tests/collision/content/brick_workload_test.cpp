// The seeded brick workload (benchmarks' and index tests' builds): deterministic, and its density
// parameter packs the same bricks tighter by the cube root.
#include <cmath>
#include <gtest/gtest.h>
#include <limits>

#include "collision/content/brick_workload.h"
#include "collision/core/errors.h"

namespace bw {
namespace {

// Root-mean-square distance of the brick centres from their mean.
double spread(const std::vector<Aabb>& boxes) {
  Vec3d mean = Vec3d::Zero();
  for (const Aabb& b : boxes) mean += b.center().cast<double>();
  mean /= double(boxes.size());
  double sum = 0;
  for (const Aabb& b : boxes) sum += (b.center().cast<double>() - mean).squaredNorm();
  return std::sqrt(sum / double(boxes.size()));
}

TEST(BrickWorkload, DensityShrinksEveryClusterByItsCubeRoot) {
  BrickWorkloadParams p;
  p.count = 20'000;
  p.clusters = 1;
  p.snap = 0.f;
  for (float density : {8.f, 64.f}) {
    BrickWorkloadParams d = p;
    d.density = density;
    const std::vector<Aabb> sparse = generateBrickWorkload(p), dense = generateBrickWorkload(d);
    ASSERT_EQ(dense.size(), sparse.size());
    for (size_t i = 0; i < sparse.size(); ++i)  // the same bricks, to the rounding of their new positions
      ASSERT_LT((dense[i].extent() - sparse[i].extent()).cwiseAbs().maxCoeff(), 1e-3f) << "brick " << i;
    EXPECT_NEAR(spread(sparse) / spread(dense), std::cbrt(double(density)), 0.02 * std::cbrt(double(density)));
    EXPECT_EQ(generateBrickWorkload(d), dense) << "deterministic";
  }
}

TEST(BrickWorkload, BadDensityIsRefused) {
  BrickWorkloadParams p;
  p.count = 10;
  for (float bad : {0.f, -1.f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    p.density = bad;
    EXPECT_THROW(generateBrickWorkload(p), InvalidInput) << bad;
  }
}

}  // namespace
}  // namespace bw
