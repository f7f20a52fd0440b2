#pragma once
/// Validation of values at public API boundaries.
///
/// Contract: every public entry point that stores or acts on caller-supplied geometry
/// (positions, sizes, directions, rotations, transforms) rejects NaN and infinity by
/// throwing bw::InvalidInput before anything is modified. The message names the
/// argument ("what") and the offending value, e.g.
///   "OctoBVH::insert: bounds.min.y is NaN".
/// Nothing is stored when the check fails, so a failed call leaves the structure as it was.
#include <stdexcept>
#include <string>

#include "collision/math_types.h"

namespace bw {

/// Thrown when a caller passes an invalid value (NaN, infinity, out of range, inverted bounds).
class InvalidInput : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Thrown when a fixed-capacity resource (pool reservation, batch array) is full.
class CapacityExceeded : public std::length_error {
 public:
  using std::length_error::length_error;
};

/// Throws InvalidInput("<context>: <what> is NaN/inf (value)") if v is not finite.
void requireFinite(double v, const char* context, const char* what);
void requireFinite(const Vec3f& v, const char* context, const char* what);
void requireFinite(const Vec3d& v, const char* context, const char* what);
/// A rotation must be finite and unit length within 1e-3 (it is renormalised by callers).
void requireUnitQuaternion(const Quatf& q, const char* context, const char* what);
/// Throws InvalidInput unless lo <= v <= hi (and v is finite).
void requireInRange(double v, double lo, double hi, const char* context, const char* what);

}  // namespace bw
