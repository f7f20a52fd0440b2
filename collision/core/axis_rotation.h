#pragma once
/// The 24 axis-aligned rotations a brick can have, as exact signed permutations.
///
/// Index = direction * 4 + spin. `direction` (0..5 = +X, -X, +Y, -Y, +Z, -Z) is where the
/// brick's local +Z (its "up") points; `spin` (0..3) turns the brick by spin * 90 degrees about
/// that direction, counter-clockwise looking down the axis. Index 16 (+Z, spin 0) is identity.
/// Applying a rotation permutes and negates components, so it is exact in float.
#include <array>
#include <cstdint>

#include "collision/core/math_types.h"

namespace bw {

class AxisRotation {
 public:
  static constexpr int kCount = 24;
  enum Direction : uint8_t { PosX = 0, NegX, PosY, NegY, PosZ, NegZ };

  constexpr AxisRotation() : index_(identityIndex()) {}
  /// Throws InvalidInput for index >= 24.
  static AxisRotation fromIndex(int index);
  /// Throws InvalidInput for direction >= 6 or spin >= 4.
  static AxisRotation fromDirectionSpin(int direction, int spin);
  static constexpr AxisRotation identity() { return AxisRotation(); }

  constexpr uint8_t index() const { return index_; }
  constexpr int direction() const { return index_ / 4; }
  constexpr int spin() const { return index_ % 4; }

  /// Output component i = sign(i) * input component sourceAxis(i).
  int sourceAxis(int i) const { return table().axis[index_][i]; }
  int sign(int i) const { return table().sign[index_][i]; }

  Vec3f apply(const Vec3f& v) const {
    const auto& t = table();
    return {t.sign[index_][0] * v[t.axis[index_][0]], t.sign[index_][1] * v[t.axis[index_][1]],
            t.sign[index_][2] * v[t.axis[index_][2]]};
  }
  /// Rotated half extents of a box: a permutation, no signs.
  Vec3f applyToExtent(const Vec3f& e) const {
    const auto& t = table();
    return {e[t.axis[index_][0]], e[t.axis[index_][1]], e[t.axis[index_][2]]};
  }
  AxisRotation inverse() const { return AxisRotation(table().inverse[index_]); }
  /// (*this) * o: apply o first, then this.
  AxisRotation operator*(const AxisRotation& o) const { return AxisRotation(table().compose[index_][o.index_]); }
  bool operator==(const AxisRotation&) const = default;

  Mat3f matrix() const;
  Quatf quaternion() const;

  struct Tables {
    int8_t axis[kCount][3];
    int8_t sign[kCount][3];
    uint8_t inverse[kCount];
    uint8_t compose[kCount][kCount];
  };
  static const Tables& table();

 private:
  explicit constexpr AxisRotation(uint8_t i) : index_(i) {}
  static constexpr uint8_t identityIndex() { return PosZ * 4; }
  uint8_t index_;
};

}  // namespace bw
