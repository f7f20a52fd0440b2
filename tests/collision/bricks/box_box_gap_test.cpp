// separatedBoxGap (collision/bricks/box_box_gap.h) against the exact distance between the two
// boxes, brute force in double: the least of every vertex of either box against the other box
// and every edge of one against every edge of the other (144 segment pairs). Seeded cases: box
// sizes 0.2 .. 500 on each axis (thin plates and long bars among them), random rotations and
// rotations sharing an axis (a box resting near a brick, the common case in the world), gaps from
// 1e-4 of the size to the size, positions up to 1e4 from the origin. Where it answers, the gap,
// its points and its normal must be the exact ones; where the nearest points lie inside two edges
// it must decline (the caller's GJK measures those); overlapping boxes always decline.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <gtest/gtest.h>
#include <optional>
#include <utility>

#include "collision/bricks/box_box_gap.h"
#include "collision/core/seeded_random.h"
#include "collision/support/sequenced_draws.h"

namespace bw {
namespace {

struct Box {
  Vec3f half;
  Mat3f rotation;
  Vec3f centre;
  // A float rotation is orthonormal to ~1e-7 only: over a 500 m bar that is 5e-5 m, more than the
  // smallest gaps here. The function reads it as its orthonormal neighbour (Gram-Schmidt on the
  // first two columns, the third their cross product), and so does this reference.
  Eigen::Matrix3d axes;
  void setRotation(const Mat3f& m) {
    rotation = m;
    const Eigen::Vector3d x = m.col(0).cast<double>().normalized();
    const Eigen::Vector3d y = (m.col(1).cast<double>() - x * x.dot(m.col(1).cast<double>())).normalized();
    axes << x, y, x.cross(y);
  }
  Eigen::Vector3d axis(int i) const { return axes.col(i); }
  Eigen::Vector3d vertex(int signs) const {
    Eigen::Vector3d v = centre.cast<double>();
    for (int i = 0; i < 3; ++i) v += axis(i) * double(half[i]) * ((signs >> i & 1) ? 1.0 : -1.0);
    return v;
  }
  // The box's nearest point to p, and the distance, in double.
  Eigen::Vector3d nearestPoint(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d d = p - centre.cast<double>();
    Eigen::Vector3d q = centre.cast<double>();
    for (int i = 0; i < 3; ++i) q += axis(i) * std::clamp(d.dot(axis(i)), -double(half[i]), double(half[i]));
    return q;
  }
  double distance(const Eigen::Vector3d& p) const { return (p - nearestPoint(p)).norm(); }
  // The 12 edges as vertex pairs (vertices differing in one sign bit).
  std::array<std::array<int, 2>, 12> edges() const {
    std::array<std::array<int, 2>, 12> e{};
    int n = 0;
    for (int v = 0; v < 8; ++v)
      for (int bit = 1; bit < 8; bit <<= 1)
        if (!(v & bit)) e[n++] = {v, v | bit};
    return e;
  }
};

// Closest points of segments [p1, q1] and [p2, q2] (the clamped closest points of their lines).
void closestOnSegments(const Eigen::Vector3d& p1, const Eigen::Vector3d& q1, const Eigen::Vector3d& p2,
                       const Eigen::Vector3d& q2, Eigen::Vector3d& c1, Eigen::Vector3d& c2) {
  const Eigen::Vector3d d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r), c = d1.dot(r), b = d1.dot(d2);
  const double denom = a * e - b * b;
  double s = denom > 1e-12 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
  double t = (b * s + f) / e;
  if (t < 0) t = 0, s = std::clamp(-c / a, 0.0, 1.0);
  else if (t > 1) t = 1, s = std::clamp((b - c) / a, 0.0, 1.0);
  c1 = p1 + d1 * s;
  c2 = p2 + d2 * t;
}

// The exact distance and the direction from b's nearest point to a's (unique for separated
// convex sets, whichever nearest pair is found).
struct Nearest {
  double distance = INFINITY;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  void offer(const Eigen::Vector3d& onA, const Eigen::Vector3d& onB) {
    const double d = (onA - onB).norm();
    if (d < distance) distance = d, direction = (onA - onB) / d;
  }
};

Nearest exactNearest(const Box& a, const Box& b) {
  Nearest best;
  for (int v = 0; v < 8; ++v) {
    best.offer(a.vertex(v), b.nearestPoint(a.vertex(v)));
    best.offer(a.nearestPoint(b.vertex(v)), b.vertex(v));
  }
  for (const auto& ea : a.edges()) {
    for (const auto& eb : b.edges()) {
      Eigen::Vector3d onA, onB;
      closestOnSegments(a.vertex(ea[0]), a.vertex(ea[1]), b.vertex(eb[0]), b.vertex(eb[1]), onA, onB);
      best.offer(onA, onB);
    }
  }
  return best;
}

// Separated along one of the 15 axes (double): the boxes do not overlap.
bool separated(const Box& a, const Box& b) {
  std::array<Eigen::Vector3d, 15> axes;
  int n = 0;
  for (int i = 0; i < 3; ++i) axes[n++] = a.axis(i), axes[n++] = b.axis(i);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) axes[n++] = a.axis(i).cross(b.axis(j));
  const Eigen::Vector3d d = (a.centre - b.centre).cast<double>();
  for (const Eigen::Vector3d& u : axes) {
    if (u.squaredNorm() < 1e-12) continue;
    double ra = 0, rb = 0;
    for (int i = 0; i < 3; ++i) ra += double(a.half[i]) * std::abs(u.dot(a.axis(i))), rb += double(b.half[i]) * std::abs(u.dot(b.axis(i)));
    if (std::abs(d.dot(u)) > ra + rb) return true;
  }
  return false;
}

Mat3f randomRotation(SeededRandom& r) {
  return test::drawQuat([&] { return r.normal(); }).normalized().toRotationMatrix();
}

// a pushed away from b along `dir` until it just stops overlapping (bisection on the double
// separating-axis test), then `extra` further.
Vec3f placeApart(Box a, const Box& b, const Vec3f& dir, float extra) {
  double lo = 0, hi = double((a.half.norm() + b.half.norm()) * 1.01f);
  for (int it = 0; it < 80; ++it) {
    const double mid = 0.5 * (lo + hi);
    a.centre = (b.centre.cast<double>() + dir.cast<double>() * mid).cast<float>();
    (separated(a, b) ? hi : lo) = mid;
  }
  return (b.centre.cast<double>() + dir.cast<double>() * (hi + double(extra))).cast<float>();
}

struct Tally {
  int cases = 0, answered = 0;
  double worstGap = 0, worstPoints = 0, worstNormal = 0;
  void report(const char* what) const {
    std::printf("[ box gap   ] %s: %d of %d answered; worst relative gap error %.2e, points %.2e, normal %.2f of its "
                "tolerance\n",
                what, answered, cases, worstGap, worstPoints, worstNormal);
  }
};

// One case: answered or declined, and when answered, exact.
void check(const Box& a, const Box& b, Tally& t, int k) {
  const Nearest exact = exactNearest(a, b);
  const double scale = double((a.centre - b.centre).norm() + a.half.sum() + b.half.sum());
  const std::optional<BoxGap> g = separatedBoxGap(a.half, a.rotation, a.centre, b.half, b.rotation, b.centre);
  if (!separated(a, b)) {  // a placement rounded into b (a float 1e4 from the origin is 1e-3 apart)
    EXPECT_FALSE(g.has_value()) << "case " << k << ": overlapping boxes";
    return;
  }
  ++t.cases;
  if (!g) return;
  ++t.answered;
  const double gapErr = std::abs(double(g->gap) - exact.distance) / scale;
  // onB on b, onB + normal * gap on a: both within rounding of the surfaces. A point is a float
  // where the boxes are (1e4 from the origin: a float's spacing there is 1e-3), so its rounding
  // there is taken out of its error.
  const Eigen::Vector3d onB = g->onB.cast<double>(), onA = onB + g->normal.cast<double>() * double(g->gap);
  const double placement = 4 * double(std::numeric_limits<float>::epsilon()) * double(b.centre.norm());
  const double pointErr = std::max(0.0, std::max(b.distance(onB), a.distance(onA)) - placement) / scale;
  // The normal against the exact direction: the output is float (1e-7), and a gap is the
  // difference of coordinates rounded in double, over the gap.
  const double normalErr = (g->normal.cast<double>() - exact.direction).norm();
  const double normalTol = 1e-6 + 1e-9 * scale / exact.distance;
  t.worstGap = std::max(t.worstGap, gapErr), t.worstPoints = std::max(t.worstPoints, pointErr),
  t.worstNormal = std::max(t.worstNormal, normalErr / normalTol);
  EXPECT_GT(g->gap, 0.f) << "case " << k;
  EXPECT_LT(gapErr, 2e-7) << "case " << k << ": gap " << g->gap << ", exact " << exact.distance;
  EXPECT_LT(pointErr, 2e-7) << "case " << k;
  EXPECT_LT(normalErr, normalTol) << "case " << k << ": gap / scale " << exact.distance / scale;
}

Box randomBox(SeededRandom& r, float far) {
  Box b;
  b.half = test::drawVec3([&](int) { return r.logUniform(0.1, 250); });
  b.setRotation(randomRotation(r));
  b.centre = test::drawVec3([&](int) { return r.uniform(-1, 1); }) * far;
  return b;
}

// Case k of a random pair: b near the origin or (every third case) 1e4 from it, a beside it
// along a random direction, `drawExtra()` of the larger box's size beyond the first touch
// (negative: inside). Draws in this order, so a seed gives the same cases.
template <class DrawExtra>
std::pair<Box, Box> randomPair(SeededRandom& r, int k, DrawExtra&& drawExtra) {
  const Box b = randomBox(r, k % 3 == 0 ? 1e4f : 10.f);
  Box a = randomBox(r, 0.f);
  const Vec3f dir = test::drawVec3([&](int) { return r.normal(); }).normalized();
  const float size = std::max(a.half.maxCoeff(), b.half.maxCoeff());
  a.centre = placeApart(a, b, dir, float(drawExtra()) * size);
  return {a, b};
}

TEST(BoxBoxGap, RandomPosesAnswerExactlyOrDecline) {
  SeededRandom r(4101);
  Tally t;
  for (int k = 0; k < 3000; ++k) {
    const auto [a, b] = randomPair(r, k, [&] { return r.logUniform(1e-4, 1.0); });
    check(a, b, t, k);
  }
  t.report("random poses");
  // The candidates hold a nearest pair of every separated pair of boxes; only a near tie of two
  // axes (in float) may pick other faces' edges and decline.
  EXPECT_GE(t.answered, t.cases * 99 / 100);
}

// The world's common case: a box near a brick, sharing an axis with it (a crate standing on a
// deck beside a wall), separated along the brick's face normal or diagonally past an edge.
TEST(BoxBoxGap, BoxesSharingAnAxisAreAnsweredAndExact) {
  SeededRandom r(4102);
  Tally alongNormal, tilted;
  for (int k = 0; k < 3000; ++k) {
    const Box b = randomBox(r, k % 3 == 0 ? 1e4f : 10.f);
    Box a = randomBox(r, 0.f);
    const int shared = int(r.below(3));
    const float yaw = float(r.uniform(0, 6.2831853));
    a.setRotation(b.rotation * Eigen::AngleAxisf(yaw, Vec3f::Unit(shared)).toRotationMatrix());
    // Along one of b's face normals, or tilted up to ~30 degrees off it.
    Vec3f dir = b.rotation.col(int(r.below(3))) * (r.below(2) ? 1.f : -1.f);
    if (k % 2) dir = (dir + test::drawVec3([&](int) { return r.uniform(-1, 1); }) * 0.5f).normalized();
    const float size = std::max(a.half.maxCoeff(), b.half.maxCoeff());
    a.centre = placeApart(a, b, dir, float(r.logUniform(1e-4, 0.1)) * size);
    check(a, b, k % 2 ? tilted : alongNormal, k);
  }
  alongNormal.report("sharing an axis, apart along b's face normal");
  tilted.report("sharing an axis, apart along a tilted direction");
  EXPECT_GE(alongNormal.answered, alongNormal.cases * 99 / 100);
  EXPECT_GE(tilted.answered, tilted.cases * 99 / 100);
}

// A box hovering flat across a long bar (or a bar across a bar): their faces overlap in a
// region whose corners are all crossings of edges, no vertex of either box over the other's face.
TEST(BoxBoxGap, FacesCrossingLikeBarsAreAnsweredExactly) {
  SeededRandom r(4104);
  Tally t;
  for (int k = 0; k < 500; ++k) {
    Box bar;
    bar.half = Vec3f(float(r.logUniform(5, 500)), float(r.logUniform(0.1, 0.4)), float(r.logUniform(0.1, 2)));
    bar.setRotation(randomRotation(r));
    bar.centre = test::drawVec3([&](int) { return r.uniform(-1, 1); }) * (k % 2 ? 1e4f : 10.f);
    Box a;
    const float w = float(r.logUniform(0.6, 3));  // wider than the bar: its corners miss it
    a.half = Vec3f(w, w, float(r.logUniform(0.2, 3)));
    const float yaw = float(r.uniform(0.3, 1.27));  // 17 to 73 degrees: corners off the bar
    a.setRotation(bar.rotation * Eigen::AngleAxisf(yaw, Vec3f::UnitZ()).toRotationMatrix());
    const float gap = float(r.logUniform(1e-4, 0.5));
    const float along = float(r.uniform(-0.5, 0.5)) * bar.half.x();
    a.centre = bar.centre + bar.rotation * Vec3f(along, 0.f, bar.half.z() + a.half.z() + gap);
    check(a, bar, t, k);
  }
  t.report("faces crossing like bars");
  EXPECT_GE(t.answered, t.cases * 99 / 100);
}

TEST(BoxBoxGap, OverlappingOrTouchingBoxesDecline) {
  SeededRandom r(4103);
  for (int k = 0; k < 2000; ++k) {
    const Box b = randomBox(r, k % 2 ? 1e4f : 10.f);
    Box a = randomBox(r, 0.f);
    const Vec3f dir = test::drawVec3([&](int) { return r.normal(); }).normalized();
    // From deep inside to exactly at the first touch.
    const Vec3f touch = placeApart(a, b, dir, 0.f);
    a.centre = b.centre + (touch - b.centre) * float(r.uniform(0, 1));
    if (separated(a, b)) continue;  // rounding put it just outside
    EXPECT_FALSE(separatedBoxGap(a.half, a.rotation, a.centre, b.half, b.rotation, b.centre).has_value()) << "case " << k;
  }
  // Identical boxes in the same place.
  const Box b = randomBox(r, 10.f);
  EXPECT_FALSE(separatedBoxGap(b.half, b.rotation, b.centre, b.half, b.rotation, b.centre).has_value());
}

// The face axes' separation a speculative caller stops at (collideBoxes: beyond its margin, no
// contact is asked for) must be a lower bound on the exact gap, reach it when a face axis is the
// nearest direction, and never be positive for boxes that overlap.
TEST(BoxBoxGap, FaceSeparationIsALowerBoundOnTheGap) {
  SeededRandom r(3801);
  int close = 0, cases = 0;
  for (int k = 0; k < 3000; ++k) {
    const auto [a, b] = randomPair(r, k, [&] { return r.uniform(-0.5, 1.0); });
    const BoxPair pair = boxPair(a.half, a.rotation, a.centre, b.half, b.rotation, b.centre);
    if (!separated(a, b)) {
      EXPECT_LE(pair.faceSeparation, 1e-9 * pair.scale) << "case " << k << ": overlapping boxes";
      continue;
    }
    ++cases;
    const Nearest exact = exactNearest(a, b);
    EXPECT_LE(pair.faceSeparation, exact.distance + 1e-9 * pair.scale) << "case " << k << ": not a lower bound";
    close += pair.faceSeparation >= exact.distance - 1e-6 * pair.scale;
  }
  EXPECT_GT(cases, 1000);
  EXPECT_GT(close, cases / 10);  // face against face or vertex over a face: the bound is the gap
}

// The float first test must reject only pairs the double one rejects (collideBoxes relies on
// it to keep the same contacts): whenever it says "farther than d", the exact face separation is
// over d + 1e-5 of the pair's size, and so is the exact gap.
TEST(BoxBoxGap, TheFloatFirstTestRejectsOnlyWhatTheExactOneDoes) {
  SeededRandom r(3802);
  int rejected = 0, kept = 0;
  for (int k = 0; k < 6000; ++k) {
    const auto [a, b] = randomPair(r, k, [&] { return r.uniform(-0.2, 0.5); });
    const BoxPair pair = boxPair(a.half, a.rotation, a.centre, b.half, b.rotation, b.centre);
    // Distances around the face separation, so both answers occur near the edge.
    const float d = float(std::max(0.0, pair.faceSeparation * r.uniform(0.9, 1.1)));
    if (boxesFartherApartThan(a.half, a.rotation, a.centre, b.half, b.rotation, b.centre, d)) {
      ++rejected;
      EXPECT_GE(pair.faceSeparation, double(d) + 1e-5 * pair.scale) << "case " << k;
      if (separated(a, b)) EXPECT_GT(exactNearest(a, b).distance, double(d)) << "case " << k;
    } else {
      ++kept;
    }
  }
  EXPECT_GT(rejected, 1000);
  EXPECT_GT(kept, 1000);
}

}  // namespace
}  // namespace bw
