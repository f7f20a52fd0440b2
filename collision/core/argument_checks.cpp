#include "collision/core/argument_checks.h"

#include <cmath>
#include <sstream>

namespace bw {
namespace {

[[noreturn]] void fail(const char* context, const std::string& what, const std::string& problem) {
  throw InvalidInput(std::string(context) + ": " + what + " " + problem);
}

std::string describe(double v) {
  if (std::isnan(v)) return "is NaN";
  std::ostringstream s;
  s << "is " << v;
  return s.str();
}

template <class V>
void requireFiniteVec(const V& v, const char* context, const char* what) {
  static const char* axis[3] = {".x", ".y", ".z"};
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(double(v[i]))) fail(context, std::string(what) + axis[i], describe(double(v[i])));
  }
}

}  // namespace

void requireFinite(double v, const char* context, const char* what) {
  if (!std::isfinite(v)) fail(context, what, describe(v));
}

void requireFinite(const Vec3f& v, const char* context, const char* what) { requireFiniteVec(v, context, what); }
void requireFinite(const Vec3d& v, const char* context, const char* what) { requireFiniteVec(v, context, what); }

void requireUnitQuaternion(const Quatf& q, const char* context, const char* what) {
  const float c[4] = {q.w(), q.x(), q.y(), q.z()};
  for (float f : c) {
    if (!std::isfinite(f)) fail(context, what, "has a non-finite component (" + describe(f) + ")");
  }
  const double n = std::sqrt(double(q.squaredNorm()));
  if (std::abs(n - 1.0) > 1e-3) {
    std::ostringstream s;
    s << "is not a unit quaternion (norm " << n << ")";
    fail(context, what, s.str());
  }
}

void requireInRange(double v, double lo, double hi, const char* context, const char* what) {
  if (!std::isfinite(v)) fail(context, what, describe(v));
  if (v < lo || v > hi) {
    std::ostringstream s;
    s << "is " << v << ", outside [" << lo << ", " << hi << "]";
    fail(context, what, s.str());
  }
}

}  // namespace bw
