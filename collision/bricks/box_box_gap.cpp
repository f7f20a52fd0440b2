#include "collision/bricks/box_box_gap.h"

#include <algorithm>
#include <cmath>

namespace bw {

namespace {

// A point of a and a point of b (both in b's frame) and the squared distance between them.
struct PointPair {
  double distance2 = INFINITY;
  Vec3d onA = Vec3d::Zero(), onB = Vec3d::Zero();
  void offer(const Vec3d& a, const Vec3d& b) {
    const double d2 = (a - b).squaredNorm();
    if (d2 < distance2) *this = {d2, a, b};  // ties keep the first offered
  }
};

// A float rotation made orthonormal in double (float rotations are orthonormal to ~1e-7 only, and
// the bounds below must agree to far better than that).
Mat3d orthonormal(const Mat3f& m) {
  const Vec3d x = m.col(0).cast<double>().normalized();
  const Vec3d y = (m.col(1).cast<double>() - x * x.dot(m.col(1).cast<double>())).normalized();
  Mat3d r;
  r << x, y, x.cross(y);
  return r;
}

// Separation of the boxes along the unit direction n (from b towards a), in b's frame (a's centre
// c and axes r there): a lower bound on their distance.
double separationAlong(const Vec3d& n, const Vec3d& c, const Mat3d& r, const Vec3d& a, const Vec3d& b) {
  return c.dot(n) - (r.transpose() * n).cwiseAbs().dot(a) - n.cwiseAbs().dot(b);
}

// An axis of largest separation, pointing from b towards a, and that separation (a lower bound on
// the gap when positive). For an axis across two edges, `edgeOfB` and `edgeOfA` name them.
struct Axis {
  double separation = -INFINITY;
  Vec3d direction = Vec3d::UnitZ();
  int edgeOfB = -1, edgeOfA = -1;
};

// Among b's 3 face axes and a's.
Axis largestFaceSeparation(const Vec3d& c, const Mat3d& r, const Vec3d& a, const Vec3d& b) {
  const Mat3d absR = r.cwiseAbs();
  Axis best;
  auto offer = [&](const Vec3d& u, double separation) {
    if (separation > best.separation) best.separation = separation, best.direction = c.dot(u) < 0.0 ? -u : u;
  };
  for (int k = 0; k < 3; ++k) offer(Vec3d::Unit(k), std::abs(c[k]) - b[k] - absR.row(k).dot(a));
  for (int j = 0; j < 3; ++j) offer(r.col(j), std::abs(c.dot(r.col(j))) - a[j] - absR.col(j).dot(b));
  return best;
}

// Among the 9 axes across b's edge k and a's edge j.
Axis largestEdgeSeparation(const Vec3d& c, const Mat3d& r, const Vec3d& a, const Vec3d& b) {
  Axis best;
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 3; ++j) {
      Vec3d u = Vec3d::Unit(k).cross(r.col(j));
      const double length = u.norm();
      if (length < 1e-3) continue;  // near parallel edges: the face axes bound those
      u /= length;
      const double separation = std::abs(c.dot(u)) - (r.transpose() * u).cwiseAbs().dot(a) - u.cwiseAbs().dot(b);
      if (separation > best.separation) best = {separation, c.dot(u) < 0.0 ? Vec3d(-u) : u, k, j};
    }
  }
  return best;
}

// Where segments [p1, q1] and [p2, q2] cross when seen along `n` (unit): offers that point of each
// (in pairs with p1 + (q1 - p1) s and p2 + (q2 - p2) t). Parallel segments do not cross: their
// nearest points include an end, a vertex, offered already.
void offerCrossing(const Vec3d& p1, const Vec3d& q1, const Vec3d& p2, const Vec3d& q2, const Vec3d& n, PointPair& best) {
  const Vec3d d1 = q1 - p1, d2 = q2 - p2, r = p2 - p1;
  // In the plane across n: s d1 - t d2 = r (projected), by the triple products with n.
  const double denom = n.dot(d1.cross(d2));
  if (std::abs(denom) <= 1e-12 * d1.norm() * d2.norm()) return;
  const double s = n.dot(r.cross(d2)) / denom, t = n.dot(r.cross(d1)) / denom;
  if (s < 0.0 || s > 1.0 || t < 0.0 || t > 1.0) return;
  best.offer(p1 + d1 * s, p2 + d2 * t);
}

// The 4 corners, in order around it, of a box's face whose outward normal is +-axis k.
void faceCorners(const Vec3d& half, int k, bool positive, Vec3d (&corner)[4]) {
  const int i = (k + 1) % 3, j = (k + 2) % 3;
  for (int q = 0; q < 4; ++q) {
    Vec3d v;
    v[k] = positive ? half[k] : -half[k];
    v[i] = (q == 1 || q == 2) ? half[i] : -half[i];  // (-,-) (+,-) (+,+) (-,+)
    v[j] = q >= 2 ? half[j] : -half[j];
    corner[q] = v;
  }
}

}  // namespace

bool boxesFartherApartThan(const Vec3f& halfA, const Mat3f& rotationA, const Vec3f& centreA, const Vec3f& halfB,
                           const Mat3f& rotationB, const Vec3f& centreB, float distance) {
  const Vec3f d = centreA - centreB;  // correctly rounded: within 6e-8 of its own length
  // The slack taken from d's 1-norm (>= its length: a larger slack, no square root).
  const float need = distance + 1e-4f * (std::abs(d.x()) + std::abs(d.y()) + std::abs(d.z()) + halfA.sum() + halfB.sum());
  float absR[3][3];  // |b's axis k . a's axis j|: a's axes in b's frame, a row per b axis tried
  // Any one axis over `need` settles it: b's face axes first, then a's.
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 3; ++j) absR[k][j] = std::abs(rotationB.col(k).dot(rotationA.col(j)));
    const float reach = halfB[k] + absR[k][0] * halfA[0] + absR[k][1] * halfA[1] + absR[k][2] * halfA[2];
    if (std::abs(rotationB.col(k).dot(d)) - reach > need) return true;
  }
  for (int j = 0; j < 3; ++j) {
    const float reach = halfA[j] + absR[0][j] * halfB[0] + absR[1][j] * halfB[1] + absR[2][j] * halfB[2];
    if (std::abs(rotationA.col(j).dot(d)) - reach > need) return true;
  }
  return false;
}

BoxPair boxPair(const Vec3f& halfA, const Mat3f& rotationA, const Vec3f& centreA, const Vec3f& halfB, const Mat3f& rotationB,
                const Vec3f& centreB) {
  // In double, in b's frame (a's centre c and axes r there), rotations made orthonormal: the
  // bounds below then meet to within double rounding. (In float, a candidate's direction, a
  // difference of nearby points over a small gap, was off by up to 0.1, and the rotations'
  // rounding kept lower bounds 1e-7 of the size below the gap.)
  BoxPair p;
  p.rb = orthonormal(rotationB);
  p.r = p.rb.transpose() * orthonormal(rotationA);
  p.centreB = centreB.cast<double>();
  p.c = p.rb.transpose() * (centreA.cast<double>() - p.centreB);
  p.a = halfA.cast<double>();
  p.b = halfB.cast<double>();
  p.scale = p.c.norm() + p.a.sum() + p.b.sum();
  const Axis face = largestFaceSeparation(p.c, p.r, p.a, p.b);
  p.faceSeparation = face.separation;
  p.faceDirection = face.direction;
  return p;
}

std::optional<BoxGap> separatedBoxGap(const BoxPair& pair) {
  const Mat3d& rb = pair.rb;
  const Mat3d& r = pair.r;
  const Mat3d rt = r.transpose();
  const Vec3d &c = pair.c, &a = pair.a, &b = pair.b;
  const double scale = pair.scale;
  Axis face;
  face.separation = pair.faceSeparation;
  face.direction = pair.faceDirection;
  // Candidates, each a point of a and a point of b (their distance bounds the gap from above),
  // first a's vertices against b and b's against a (each vertex's nearest point of the other box).
  PointPair best;
  const Vec3d ex = r.col(0) * a.x(), ey = r.col(1) * a.y(), ez = r.col(2) * a.z();
  for (int i = 0; i < 8; ++i) {
    const Vec3d v = c + ((i & 1) ? ex : -ex) + ((i & 2) ? ey : -ey) + ((i & 4) ? ez : -ez);
    best.offer(v, v.cwiseMax(-b).cwiseMin(b));
  }
  const Vec3d cInA = -(rt * c), fx = rt.col(0) * b.x(), fy = rt.col(1) * b.y(), fz = rt.col(2) * b.z();
  for (int i = 0; i < 8; ++i) {  // measured in a's frame (r is orthonormal); the winner taken back
    const Vec3d inA = cInA + ((i & 1) ? fx : -fx) + ((i & 2) ? fy : -fy) + ((i & 4) ? fz : -fz);
    const Vec3d clamped = inA.cwiseMax(-a).cwiseMin(a);
    const double d2 = (inA - clamped).squaredNorm();
    if (d2 < best.distance2)
      best = {d2, c + r * clamped, Vec3d((i & 1) ? b.x() : -b.x(), (i & 2) ? b.y() : -b.y(), (i & 4) ? b.z() : -b.z())};
  }
  // The best candidate is the nearest pair when a lower bound meets its distance:
  // - the separation along a face axis (a vertex, edge or face against a face) or along an axis
  //   across two edges, when the candidate lies along that axis. Float rotations turned orthonormal
  //   still differ by their rounding: "parallel" faces lie 1e-7 apart in angle, so across them the
  //   axis's separation falls short of the gap by up to 1e-7 of the faces' size. A candidate that
  //   lies along the axis within 1e-6 is the nearest pair to within that.
  // - or the separation along the candidate's own direction (a vertex against an edge or a vertex,
  //   off every axis): exact for the nearest pair, to double rounding. Near parallel faces it is
  //   ill-conditioned (a tilt of 1e-5 drops it by 1e-5 of the faces' size), so the axes come
  //   first; and a distance alone is not enough, since a pair farther than the gap by d may
  //   point sqrt(2 d / gap) off the nearest direction: the tolerance is double rounding.
  auto direction = [&] { return Vec3d((best.onA - best.onB) / std::sqrt(best.distance2)); };
  auto met = [&](const Axis& axis) {
    return axis.separation > 0.0 && axis.separation >= std::sqrt(best.distance2) - 1e-6 * scale &&
           (direction() - axis.direction).norm() < 1e-6;
  };
  auto metAlongCandidate = [&] {
    return best.distance2 > 0.0 && separationAlong(direction(), c, r, a, b) >= std::sqrt(best.distance2) - 1e-10 * scale;
  };
  auto answer = [&]() -> std::optional<BoxGap> {
    const double gap = std::sqrt(best.distance2);
    if (!(gap > 1e-9 * scale)) return std::nullopt;  // touching, to double rounding: no direction
    return BoxGap{float(gap), (pair.centreB + rb * best.onB).cast<float>(), (rb * direction()).cast<float>()};
  };
  if (met(face) || metAlongCandidate()) return answer();
  // Nearest points inside two edges, along the axis of largest separation (the nearest
  // direction, when they are), the other kind of axis tried next for near ties.
  // - Across a face axis: parallel faces overlapping in a region whose corners are crossings of
  //   their edges (or an edge lying over a face, crossing its edges): the crossings, seen along
  //   the axis, of the edges of the two faces that face each other.
  auto tryFaces = [&] {
    if (!(face.separation > 0.0)) return false;
    Vec3d cornerA[4], cornerB[4];
    const Vec3d inA = rt * face.direction;
    int ka = 0, kb = 0;
    inA.cwiseAbs().maxCoeff(&ka);
    face.direction.cwiseAbs().maxCoeff(&kb);
    faceCorners(a, ka, inA[ka] < 0.0, cornerA);             // a's face against -axis
    faceCorners(b, kb, face.direction[kb] > 0.0, cornerB);  // b's face along +axis
    for (Vec3d& v : cornerA) v = c + r * v;
    for (int p = 0; p < 4; ++p)
      for (int q = 0; q < 4; ++q) offerCrossing(cornerA[p], cornerA[(p + 1) % 4], cornerB[q], cornerB[(q + 1) % 4], face.direction, best);
    return met(face);
  };
  // - Across an axis between two edges: the two edges that lie farthest along it, b's along +axis
  //   and a's along -axis, crossing there.
  const Axis edges = largestEdgeSeparation(c, r, a, b);
  auto tryEdges = [&] {
    if (!(edges.separation > 0.0)) return false;
    const Vec3d& u = edges.direction;
    const Vec3d inA = rt * u;
    Vec3d onB, onA = c;
    for (int i = 0; i < 3; ++i) {
      onB[i] = i == edges.edgeOfB ? 0.0 : (u[i] > 0.0 ? b[i] : -b[i]);
      if (i != edges.edgeOfA) onA += r.col(i) * (inA[i] > 0.0 ? -a[i] : a[i]);
    }
    const Vec3d alongB = Vec3d::Unit(edges.edgeOfB) * b[edges.edgeOfB], alongA = r.col(edges.edgeOfA) * a[edges.edgeOfA];
    offerCrossing(onA - alongA, onA + alongA, onB - alongB, onB + alongB, u, best);
    return met(edges) || metAlongCandidate();
  };
  const bool found = edges.separation > face.separation ? tryEdges() || tryFaces() : tryFaces() || tryEdges();
  return found ? answer() : std::nullopt;
}

}  // namespace bw
