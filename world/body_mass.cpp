#include "world/body_mass.h"

#include <Eigen/Eigenvalues>

namespace bw {

void primitiveMass(const QueryShape& s, float density, float& inverseMass, Vec3f& inverseInertia) {
  float m;
  Vec3f I;
  switch (s.kind) {
    case QueryShape::Kind::Sphere:
      m = density * 4.f / 3.f * 3.14159265f * s.radius * s.radius * s.radius;
      I = Vec3f::Constant(0.4f * m * s.radius * s.radius);
      break;
    case QueryShape::Kind::Capsule: {
      // Cylinder of the core plus two hemispheres (a sphere), about the centre.
      const float r = s.radius, h = 2 * s.halfHeight;
      const float mc = density * 3.14159265f * r * r * h, ms = density * 4.f / 3.f * 3.14159265f * r * r * r;
      m = mc + ms;
      const float iz = mc * r * r / 2 + ms * 0.4f * r * r;
      const float ix = mc * (3 * r * r + h * h) / 12 + ms * (0.4f * r * r + h * h / 4 + 3 * h * r / 8);
      I = Vec3f(ix, ix, iz);
      break;
    }
    default: {
      const Vec3f e = s.halfExtents * 2.f;
      m = density * e.prod();
      I = Vec3f(e.y() * e.y() + e.z() * e.z(), e.x() * e.x() + e.z() * e.z(), e.x() * e.x() + e.y() * e.y()) * (m / 12.f);
    }
  }
  inverseMass = 1.f / m;
  inverseInertia = I.cwiseInverse();
}

GridBodyFrame gridBodyFrame(const MassProperties& mp) {
  Eigen::SelfAdjointEigenSolver<Mat3d> eig(mp.inertia);
  Mat3d axes = eig.eigenvectors();
  if (axes.determinant() < 0) axes.col(2) = -axes.col(2);
  GridBodyFrame f;
  f.bodyInGrid = RigidTransform{mp.centerOfMass, Quatf(axes.cast<float>()).normalized()};
  f.inverseMass = float(1.0 / mp.mass);
  // note: a floor on the eigenvalues keeps a degenerate (flat) grid's inverse inertia finite.
  f.inverseInertia = eig.eigenvalues().cast<float>().cwiseMax(1e-12f).cwiseInverse();
  return f;
}

}  // namespace bw
