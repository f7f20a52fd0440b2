#pragma once
/// Argument checks at public API boundaries (the errors they throw: collision/core/errors.h).
///
/// Contract: every public entry point that stores or acts on caller-supplied geometry
/// (positions, sizes, directions, rotations, transforms) rejects NaN and infinity by
/// throwing bw::InvalidInput before anything is modified. The message names the
/// argument ("what") and the offending value, e.g.
///   "OctoBVH::insert: bounds.min.y is NaN".
/// Nothing is stored when the check fails, so a failed call leaves the structure as it was.
#include "collision/core/errors.h"
#include "collision/core/math_types.h"

namespace bw {

/// Throws InvalidInput("<context>: <what> is NaN/inf (value)") if v is not finite.
void requireFinite(double v, const char* context, const char* what);
void requireFinite(const Vec3f& v, const char* context, const char* what);
void requireFinite(const Vec3d& v, const char* context, const char* what);
/// A rotation must be finite and unit length within 1e-3 (it is renormalised by callers).
void requireUnitQuaternion(const Quatf& q, const char* context, const char* what);
/// Throws InvalidInput unless lo <= v <= hi (and v is finite).
void requireInRange(double v, double lo, double hi, const char* context, const char* what);

}  // namespace bw
