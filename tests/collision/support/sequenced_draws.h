#pragma once
// Random vectors drawn in one fixed order on every compiler. C++ leaves the order in which a
// call's arguments are evaluated unspecified: `Vec3f(float(r.uniform(0, 1)), ...)` draws z
// first under GCC and x first under clang, so a test written that way checks other cases when
// built with the other compiler (the clang-built ASan run met cases GCC's order never draws,
// and tolerances measured on GCC's cases failed on them: see profiles/RESULTS.md, session 28).
// These draw z, then y, then x (w last for a quaternion): GCC's order, so the cases and the
// figures the tests print stay the ones their tolerances were measured on.
#include "collision/core/math_types.h"

namespace bw::test {

/// (x, y, z) from draw(0), draw(1), draw(2), called in the order z, y, x.
template <class Draw>
Vec3f drawVec3(Draw&& draw) {
  const float z = float(draw(2));
  const float y = float(draw(1));
  const float x = float(draw(0));
  return Vec3f(x, y, z);
}

/// A quaternion (w, x, y, z) from draw(), called in the order z, y, x, w.
template <class Draw>
Quatf drawQuat(Draw&& draw) {
  const float z = float(draw());
  const float y = float(draw());
  const float x = float(draw());
  const float w = float(draw());
  return Quatf(w, x, y, z);
}

}  // namespace bw::test
