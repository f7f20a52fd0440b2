#include "collision/bricks/query_shape.h"

#include <LinearMath/btConvexHullComputer.h>
#include <cmath>
#include <numbers>
#include <string>

#include "collision/core/argument_checks.h"

namespace bw {

Vec3f QueryShape::localHalfExtents() const {
  switch (kind) {
    case Kind::Sphere: return Vec3f::Constant(radius);
    case Kind::Box: return halfExtents;
    case Kind::Capsule: return Vec3f(radius, radius, radius + halfHeight);
    case Kind::Hull: return hullHalfExtents;
  }
  return Vec3f::Zero();
}

void QueryShape::validate(const char* context) const {
  switch (kind) {
    case Kind::Sphere: requireInRange(radius, 1e-4, 1e7, context, "sphere radius"); break;
    case Kind::Box:
      for (int i = 0; i < 3; ++i) requireInRange(halfExtents[i], 1e-4, 1e7, context, "box half extent");
      break;
    case Kind::Capsule:
      requireInRange(radius, 1e-4, 1e7, context, "capsule radius");
      requireInRange(halfHeight, 0, 1e7, context, "capsule half height");
      break;
    case Kind::Hull:
      if (!points || pointCount < 4) throw InvalidInput(std::string(context) + ": a hull needs at least 4 points");
      for (uint32_t i = 0; i < pointCount; ++i) requireFinite(points[i], context, "hull point");
      break;
  }
}

float convexHullVolume(const Vec3f* points, uint32_t count) {
  btConvexHullComputer hull;
  hull.compute(&points[0].x(), int(sizeof(Vec3f)), int(count), 0.f, 0.f);
  double volume = 0;
  for (int f = 0; f < hull.faces.size(); ++f) {
    const btConvexHullComputer::Edge* first = &hull.edges[hull.faces[f]];
    const btVector3& a = hull.vertices[first->getSourceVertex()];
    for (const btConvexHullComputer::Edge* e = first->getNextEdgeOfFace(); e != first; e = e->getNextEdgeOfFace()) {
      const btVector3& b = hull.vertices[e->getSourceVertex()];
      const btVector3& c = hull.vertices[e->getTargetVertex()];
      volume += double(a.dot(b.cross(c))) / 6.0;
    }
  }
  return float(std::abs(volume));
}

float QueryShape::volume() const {
  constexpr float pi = std::numbers::pi_v<float>;
  switch (kind) {
    case Kind::Sphere: return 4.f / 3.f * pi * radius * radius * radius;
    case Kind::Capsule: return pi * radius * radius * (4.f / 3.f * radius + 2.f * halfHeight);
    case Kind::Box: return 8.f * halfExtents.prod();
    case Kind::Hull: return hullVolume > 0.f ? hullVolume : convexHullVolume(points, pointCount);
  }
  return 0.f;
}

}  // namespace bw
