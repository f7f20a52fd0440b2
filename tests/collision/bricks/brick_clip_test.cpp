// clipBrickToBox (the part of a huge brick near a shape, for GJK) against a reference that
// intersects every triple of face planes: the same polytope (every reference vertex found,
// every point found inside both the brick and the box), for every shape, rotation and size
// ratio, boxes inside, across and beside the brick, near and far from the origin.
#include <gtest/gtest.h>

#include "collision/bricks/brick_geometry.h"
#include "collision/core/seeded_random.h"

namespace bw {
namespace {

struct Planes {
  std::vector<Vec3d> n;
  std::vector<double> d;
};

// The brick's planes and the region's, relative to the region's centre.
Planes planesOf(const Brick& b, const Aabb& region) {
  Planes p;
  BrickPlane canonical[kMaxBrickPlanes];
  const int nb = canonicalBrickPlanes(b, canonical);
  const Vec3d c = region.center().cast<double>(), h = region.halfExtent().cast<double>();
  const Mat3d r = b.rotation.matrix().cast<double>();
  for (int k = 0; k < nb; ++k) {
    p.n.push_back(r * canonical[k].n.cast<double>());
    p.d.push_back(double(canonical[k].d) + p.n.back().dot(b.position.cast<double>() - c));
  }
  for (int a = 0; a < 3; ++a) {
    p.n.push_back(Vec3d::Unit(a));
    p.d.push_back(h[a]);
    p.n.push_back(-Vec3d::Unit(a));
    p.d.push_back(h[a]);
  }
  return p;
}

std::vector<Vec3d> referenceVertices(const Planes& p, double tol) {
  std::vector<Vec3d> out;
  const size_t np = p.n.size();
  for (size_t i = 0; i < np; ++i)
    for (size_t j = i + 1; j < np; ++j)
      for (size_t k = j + 1; k < np; ++k) {
        Mat3d m;
        m << p.n[i].transpose(), p.n[j].transpose(), p.n[k].transpose();
        if (std::abs(m.determinant()) < 1e-9) continue;
        const Vec3d y = m.inverse() * Vec3d(p.d[i], p.d[j], p.d[k]);
        bool inside = true;
        for (size_t q = 0; q < np && inside; ++q) inside = p.n[q].dot(y) <= p.d[q] + tol;
        if (inside) out.push_back(y);
      }
  return out;
}

TEST(BrickClip, SamePolytopeAsEveryPlaneTriple) {
  SeededRandom r(41);
  int clipped = 0;
  for (int q = 0; q < 3000; ++q) {
    Brick b;
    b.shape = BrickShape(r.below(4));
    b.sides = uint8_t(3 + r.below(8));  // up to 10 sides: 12 planes
    b.rotation = AxisRotation::fromIndex(int(r.below(24)));
    b.halfSize = Vec3f(float(r.logUniform(0.5, 300)), float(r.logUniform(0.5, 300)), float(r.logUniform(0.5, 300)));
    const Vec3f far = q % 3 == 0 ? Vec3f(2e5f, -1e5f, 3e4f) : Vec3f::Zero();
    b.position = far + Vec3f(float(r.uniform(-5, 5)), float(r.uniform(-5, 5)), float(r.uniform(-5, 5)));
    // a region around a point near the brick's surface, inside or beside it
    const Aabb bounds = brickBounds(b);
    const Vec3f at = bounds.center() + bounds.halfExtent().cwiseProduct(Vec3f(float(r.uniform(-1.2, 1.2)), float(r.uniform(-1.2, 1.2)), float(r.uniform(-1.2, 1.2))));
    const Aabb region = Aabb::fromCenterHalf(at, Vec3f::Constant(float(r.logUniform(0.05, 4))));
    const Planes p = planesOf(b, region);
    const double tol = 1e-6 * (1.0 + region.halfExtent().maxCoeff());
    const std::vector<Vec3d> ref = referenceVertices(p, tol);
    Vec3f got[kMaxBrickVertices];
    const int n = clipBrickToBox(b, region, got, kMaxBrickVertices);
    if (ref.size() < 4) {  // they do not meet, or only in a face, edge or point
      EXPECT_LT(n, 4) << "query " << q;
      continue;
    }
    ++clipped;
    const double slack = 1e-4 * (1.0 + region.halfExtent().maxCoeff());  // float rounding of the output
    for (const Vec3d& v : ref) {
      double nearest = 1e30;
      for (int i = 0; i < n; ++i) nearest = std::min(nearest, (got[i].cast<double>() - v).norm());
      ASSERT_LT(nearest, slack) << "query " << q << ": a vertex of the part was not found";
    }
    for (int i = 0; i < n; ++i)
      for (size_t k = 0; k < p.n.size(); ++k)
        ASSERT_LE(p.n[k].dot(got[i].cast<double>()), p.d[k] + slack) << "query " << q << ": a point outside the part";
  }
  EXPECT_GT(clipped, 1000);
}

}  // namespace
}  // namespace bw
