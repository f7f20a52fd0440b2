#include <bit>
#include "collision/bricks/brick_geometry.h"

#include <cmath>
#include <string>

#include "collision/core/argument_checks.h"

namespace bw {

namespace {

constexpr double kTwoPi = 6.283185307179586;

// Second moment (integral of x x^T) and volume of the tetrahedron (0-based vertices p0..p3).
void addTetra(const Vec3d& p0, const Vec3d& p1, const Vec3d& p2, const Vec3d& p3, ShapeMoments& m) {
  const double v = (p1 - p0).cross(p2 - p0).dot(p3 - p0) / 6.0;  // signed
  const Vec3d s = p0 + p1 + p2 + p3;
  Mat3d S = p0 * p0.transpose() + p1 * p1.transpose() + p2 * p2.transpose() + p3 * p3.transpose();
  m.volume += v;
  m.first += v * s / 4.0;
  m.second += v / 20.0 * (S + s * s.transpose());
}

// Moments of the prism extruding triangle (a, b, c) in the xy plane over z in [-h, h].
void addTrianglePrismZ(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c, double h, ShapeMoments& m) {
  const double area = 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());  // signed
  const Eigen::Vector2d s = a + b + c;
  const Eigen::Matrix2d S = a * a.transpose() + b * b.transpose() + c * c.transpose();
  const Eigen::Matrix2d areaSecond = area / 12.0 * (S + s * s.transpose());  // integral over the triangle
  const double len = 2 * h;
  m.volume += area * len;
  m.first.x() += area * s.x() / 3.0 * len;
  m.first.y() += area * s.y() / 3.0 * len;
  m.second(0, 0) += areaSecond(0, 0) * len;
  m.second(1, 1) += areaSecond(1, 1) * len;
  m.second(0, 1) += areaSecond(0, 1) * len;
  m.second(1, 0) += areaSecond(1, 0) * len;
  m.second(2, 2) += area * 2.0 * h * h * h / 3.0;  // integral of z^2 over [-h, h] times area
}

Eigen::Vector2d cylinderVertex(const Vec3f& h, int k, int n) {
  const double a = kTwoPi * k / n;
  return {double(h.x()) * std::cos(a), double(h.y()) * std::sin(a)};
}

}  // namespace

void validateBrick(const Brick& b, const char* context) {
  requireFinite(b.position, context, "brick.position");
  requireFinite(b.halfSize, context, "brick.halfSize");
  // note: names spelled out: building one per call allocated on every placement.
  static const char* const kHalfSize[3] = {"brick.halfSize.x", "brick.halfSize.y", "brick.halfSize.z"};
  for (int i = 0; i < 3; ++i) requireInRange(b.halfSize[i], kMinBrickHalfSize, kMaxBrickHalfSize, context, kHalfSize[i]);
  if (uint8_t(b.shape) > uint8_t(BrickShape::Cylinder))
    throw InvalidInput(std::string(context) + ": brick.shape is " + std::to_string(int(b.shape)) + ", expected 0..3");
  if (b.shape == BrickShape::Cylinder && (b.sides < 3 || b.sides > 64))
    throw InvalidInput(std::string(context) + ": brick.sides is " + std::to_string(int(b.sides)) + ", expected 3..64");
  if (b.rotation.index() >= AxisRotation::kCount)
    throw InvalidInput(std::string(context) + ": brick.rotation is out of range");
}

int canonicalBrickVertices(const Brick& b, Vec3f* out) {
  const Vec3f h = b.halfSize;
  switch (b.shape) {
    case BrickShape::Box:
      for (int i = 0; i < 8; ++i) out[i] = {(i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(), (i & 4) ? h.z() : -h.z()};
      return 8;
    case BrickShape::Wedge:
      for (int i = 0; i < 4; ++i) out[i] = {(i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(), -h.z()};
      out[4] = {-h.x(), -h.y(), h.z()};
      out[5] = {-h.x(), h.y(), h.z()};
      return 6;
    case BrickShape::CornerWedge:
      for (int i = 0; i < 4; ++i) out[i] = {(i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(), -h.z()};
      out[4] = {-h.x(), -h.y(), h.z()};
      return 5;
    case BrickShape::Cylinder: {
      const int n = b.sides;
      for (int k = 0; k < n; ++k) {
        const Eigen::Vector2d v = cylinderVertex(h, k, n);
        out[k] = {float(v.x()), float(v.y()), -h.z()};
        out[n + k] = {float(v.x()), float(v.y()), h.z()};
      }
      return 2 * n;
    }
  }
  return 0;
}

int clipBrickToBox(const Brick& b, const Aabb& region, Vec3f* out, int maxOut) {
  BrickPlane canonical[kMaxBrickPlanes];
  const int nb = canonicalBrickPlanes(b, canonical);
  Vec3f cv[kMaxBrickVertices];
  const int nv = canonicalBrickVertices(b, cv);
  // Which canonical planes each vertex lies on (in the canonical frame, where both are exact to
  // float rounding): two vertices sharing two planes bound an edge (or a segment of a face,
  // which adds points inside the part, never outside it).
  const float onPlane = 1e-5f * (1.f + b.halfSize.maxCoeff());
  uint64_t faces[kMaxBrickVertices];
  for (int i = 0; i < nv; ++i) {
    faces[i] = 0;
    for (int k = 0; k < nb && k < 64; ++k)
      if (std::abs(canonical[k].n.dot(cv[i]) - canonical[k].d) <= onPlane) faces[i] |= uint64_t(1) << k;
  }
  // Planes n . y <= d and vertices, relative to the region's centre, in double.
  const Vec3d c = region.center().cast<double>();
  const Vec3d h = region.halfExtent().cast<double>();
  const Mat3d r = b.rotation.matrix().cast<double>();
  const Vec3d offset = b.position.cast<double>() - c;
  Vec3d n[kMaxBrickPlanes];
  double d[kMaxBrickPlanes];
  for (int k = 0; k < nb; ++k) {
    n[k] = r * canonical[k].n.cast<double>();
    d[k] = double(canonical[k].d) + n[k].dot(offset);
  }
  Vec3d v[kMaxBrickVertices];
  for (int i = 0; i < nv; ++i) v[i] = r * cv[i].cast<double>() + offset;
  const double tolerance = 1e-6 * (1.0 + h.maxCoeff());
  auto inBrick = [&](const Vec3d& y) {
    for (int k = 0; k < nb; ++k)
      if (n[k].dot(y) > d[k] + tolerance) return false;
    return true;
  };
  auto inRegion = [&](const Vec3d& y) { return (y.cwiseAbs() - h).maxCoeff() <= tolerance; };
  int count = 0;
  auto add = [&](const Vec3d& y) {
    const Vec3f p = y.cast<float>();
    for (int q = 0; q < count; ++q)
      if ((out[q] - p).squaredNorm() < float(tolerance * tolerance) * 4.f) return;
    if (count < maxOut) out[count++] = p;
  };
  for (int i = 0; i < nv; ++i)
    if (inRegion(v[i])) add(v[i]);
  for (int k = 0; k < 8; ++k) {
    const Vec3d corner((k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(), (k & 4) ? h.z() : -h.z());
    if (inBrick(corner)) add(corner);
  }
  // b's edges through the region's faces.
  for (int i = 0; i < nv; ++i)
    for (int j = i + 1; j < nv; ++j) {
      if (std::popcount(faces[i] & faces[j]) < 2) continue;
      for (int a = 0; a < 3; ++a)
        for (const double side : {-h[a], h[a]}) {
          const double si = v[i][a] - side, sj = v[j][a] - side;
          if ((si < 0) == (sj < 0) || si == sj) continue;
          const Vec3d y = v[i] + (v[j] - v[i]) * (si / (si - sj));
          if (inRegion(y)) add(y);
        }
    }
  // The region's edges through b's faces: along axis a, at the other two axes' +-h.
  for (int a = 0; a < 3; ++a) {
    const int u = (a + 1) % 3, w = (a + 2) % 3;
    for (int e = 0; e < 4; ++e) {
      Vec3d p0 = Vec3d::Zero();
      p0[u] = (e & 1) ? h[u] : -h[u];
      p0[w] = (e & 2) ? h[w] : -h[w];
      for (int k = 0; k < nb; ++k) {
        if (std::abs(n[k][a]) < 1e-12) continue;
        Vec3d y = p0;
        y[a] = (d[k] - n[k].dot(p0)) / n[k][a];  // p0 has 0 along a
        if (std::abs(y[a]) <= h[a] + tolerance && inBrick(y)) add(y);
      }
    }
  }
  return count;
}

int canonicalBrickPlanes(const Brick& b, BrickPlane* out) {
  const Vec3f h = b.halfSize;
  int n = 0;
  // z slabs for every shape
  out[n++] = {{0, 0, 1}, h.z()};
  out[n++] = {{0, 0, -1}, h.z()};
  if (b.shape == BrickShape::Cylinder) {
    const int sides = b.sides;
    for (int k = 0; k < sides; ++k) {
      const Eigen::Vector2d p = cylinderVertex(h, k, sides), q = cylinderVertex(h, k + 1, sides);
      Eigen::Vector2d nrm(q.y() - p.y(), p.x() - q.x());  // outward for counter-clockwise vertices
      nrm.normalize();
      out[n++] = {{float(nrm.x()), float(nrm.y()), 0.f}, float(nrm.dot(p))};
    }
    return n;
  }
  out[n++] = {{1, 0, 0}, h.x()};
  out[n++] = {{-1, 0, 0}, h.x()};
  out[n++] = {{0, 1, 0}, h.y()};
  out[n++] = {{0, -1, 0}, h.y()};
  if (b.shape == BrickShape::Wedge || b.shape == BrickShape::CornerWedge) {
    // Slope through the bottom +x edge and the top -x edge: h.z * x + h.x * z <= 0.
    out[n++] = {Vec3f(h.z(), 0, h.x()).normalized(), 0.f};
  }
  if (b.shape == BrickShape::CornerWedge) {
    // Second slope through the bottom +y edge and the apex: h.z * y + h.y * z <= 0.
    out[n++] = {Vec3f(0, h.z(), h.y()).normalized(), 0.f};
  }
  return n;
}

int brickVertices(const Brick& b, Vec3f* out) {
  const int n = canonicalBrickVertices(b, out);
  for (int i = 0; i < n; ++i) out[i] = b.position + b.rotation.apply(out[i]);
  return n;
}

Aabb brickBounds(const Brick& b) {
  if (b.shape != BrickShape::Cylinder || b.sides % 4 == 0) {
    // Every shape touches all six faces of its box: the bounds are the rotated box.
    const Vec3f e = b.rotation.applyToExtent(b.halfSize);
    return {b.position - e, b.position + e};
  }
  Vec3f v[kMaxBrickVertices];
  const int n = brickVertices(b, v);
  Aabb box = Aabb::empty();
  for (int i = 0; i < n; ++i) box.merge(v[i]);
  return box;
}

ShapeMoments canonicalBrickMoments(const Brick& b) {
  const Vec3d h = b.halfSize.cast<double>();
  ShapeMoments m;
  switch (b.shape) {
    case BrickShape::Box: {
      m.volume = 8 * h.x() * h.y() * h.z();
      m.second = Mat3d(Eigen::DiagonalMatrix<double, 3>(m.volume * h.x() * h.x() / 3, m.volume * h.y() * h.y() / 3,
                                                       m.volume * h.z() * h.z() / 3));
      return m;
    }
    case BrickShape::Wedge: {
      // Prism along y over the right triangle (x, z): (-hx,-hz), (hx,-hz), (-hx,hz). Computed as a
      // z-prism in swapped axes (x, z, y), then permuted back.
      ShapeMoments p;
      addTrianglePrismZ({-h.x(), -h.z()}, {h.x(), -h.z()}, {-h.x(), h.z()}, h.y(), p);
      const int perm[3] = {0, 2, 1};  // prism axis k -> shape axis perm[k]
      m.volume = p.volume;
      for (int i = 0; i < 3; ++i) {
        m.first[perm[i]] = p.first[i];
        for (int j = 0; j < 3; ++j) m.second(perm[i], perm[j]) = p.second(i, j);
      }
      return m;
    }
    case BrickShape::CornerWedge: {
      const Vec3d apex(-h.x(), -h.y(), h.z());
      const Vec3d b0(-h.x(), -h.y(), -h.z()), b1(h.x(), -h.y(), -h.z()), b2(h.x(), h.y(), -h.z()), b3(-h.x(), h.y(), -h.z());
      // Two tetrahedra over the base split along b0-b2 (orientation gives positive volume).
      addTetra(b0, b2, b1, apex, m);
      addTetra(b0, b3, b2, apex, m);
      if (m.volume < 0) {  // fix orientation if the split came out clockwise
        m.volume = -m.volume;
        m.first = -m.first;
        m.second = -m.second;
      }
      return m;
    }
    case BrickShape::Cylinder: {
      const int n = b.sides;
      for (int k = 0; k < n; ++k)
        addTrianglePrismZ({0, 0}, cylinderVertex(b.halfSize, k, n), cylinderVertex(b.halfSize, k + 1, n), h.z(), m);
      return m;
    }
  }
  return m;
}

namespace {
// A box's moments straight from its half sizes and rotation's permutation: the same
// operations, in the same order, as the general formula below on a box (whose first moment is
// zero and second diagonal), so the same bits (checked on every rotation in brick_grid_test),
// at a fifth of its instructions; a grid's mass is this summed over every brick it gains or loses.
ShapeMoments boxMoments(const Brick& b, double density, const Vec3d& reference) {
  const double hx = b.halfSize.x(), hy = b.halfSize.y(), hz = b.halfSize.z();
  const double volume = 8 * hx * hy * hz;
  const double diagonal[3] = {volume * hx * hx / 3, volume * hy * hy / 3, volume * hz * hz / 3};
  ShapeMoments m;
  m.volume = density * volume;
  double p[3], vp[3];
  for (int i = 0; i < 3; ++i) {
    p[i] = double(b.position[i]) - reference[i];
    vp[i] = m.volume * p[i];
    m.first[i] = p[i] * m.volume + 0.0;  // (+ the rotated zero first moment: keeps -0 as it was)
  }
  const int8_t* axis = AxisRotation::table().axis[b.rotation.index()];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      // V p p^T + p (R first)^T + (R first) p^T + density R second R^T, with R first = 0.
      const double rotated = i == j ? density * diagonal[axis[i]] : 0.0;
      m.second(i, j) = ((vp[i] * p[j] + p[i] * 0.0) + 0.0 * p[j]) + rotated;
    }
  return m;
}
}  // namespace

ShapeMoments brickMoments(const Brick& b, double density, const Vec3d& reference) {
  if (b.shape == BrickShape::Box) return boxMoments(b, density, reference);
  return generalBrickMoments(b, density, reference);
}

ShapeMoments generalBrickMoments(const Brick& b, double density, const Vec3d& reference) {
  const ShapeMoments c = canonicalBrickMoments(b);
  const Mat3d R = b.rotation.matrix().cast<double>();
  const Vec3d p = b.position.cast<double>() - reference;
  ShapeMoments m;
  m.volume = density * c.volume;
  const Vec3d firstR = R * c.first * density;
  m.first = p * m.volume + firstR;
  // integral of (p + R x)(p + R x)^T = V p p^T + p (R first)^T + (R first) p^T + R second R^T
  m.second = m.volume * p * p.transpose() + p * firstR.transpose() + firstR * p.transpose() +
             density * R * c.second * R.transpose();
  return m;
}

bool rayBrick(const Brick& b, const Ray& gridRay, float tMax, float& t, Vec3f& normal) {
  // Into the canonical frame: exact, since the rotation is a signed permutation.
  const AxisRotation inv = b.rotation.inverse();
  const Vec3f o = inv.apply(gridRay.origin - b.position);
  const Vec3f d = inv.apply(gridRay.dir);
  BrickPlane planes[kMaxBrickPlanes];
  const int n = canonicalBrickPlanes(b, planes);
  float t0 = 0.f, t1 = tMax;
  int entry = -1;
  for (int i = 0; i < n; ++i) {
    const float denom = planes[i].n.dot(d);
    const float dist = planes[i].d - planes[i].n.dot(o);  // >= 0 when the origin is inside
    if (denom == 0.f) {
      if (dist < 0.f) return false;  // parallel and outside
      continue;
    }
    const float tp = dist / denom;
    if (denom < 0.f) {  // entering
      if (tp > t0) {
        t0 = tp;
        entry = i;
      }
    } else if (tp < t1) {
      t1 = tp;
    }
    if (t0 > t1) return false;
  }
  t = t0;
  // note: stableNormalized, because normalized() squares the direction first: a huge (1e30) or
  // tiny (1e-30, denormal) direction over/underflows and gave a zero or non-unit normal.
  normal = entry >= 0 ? b.rotation.apply(planes[entry].n) : Vec3f(-gridRay.dir.stableNormalized());
  return true;
}

bool brickContains(const Brick& b, const Vec3f& p, float tolerance) {
  const Vec3f q = b.rotation.inverse().apply(p - b.position);
  BrickPlane planes[kMaxBrickPlanes];
  const int n = canonicalBrickPlanes(b, planes);
  for (int i = 0; i < n; ++i)
    if (planes[i].n.dot(q) > planes[i].d + tolerance) return false;
  return true;
}

}  // namespace bw
