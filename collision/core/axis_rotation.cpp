#include "collision/core/axis_rotation.h"

#include <string>

#include "collision/core/argument_checks.h"

namespace bw {
namespace {

using IMat = std::array<std::array<int, 3>, 3>;

constexpr IMat mul(const IMat& a, const IMat& b) {
  IMat r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      int s = 0;
      for (int k = 0; k < 3; ++k) s += a[i][k] * b[k][j];
      r[i][j] = s;
    }
  return r;
}

constexpr IMat transpose(const IMat& a) {
  IMat r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r[i][j] = a[j][i];
  return r;
}

// Rotation by +90 degrees about a unit axis vector: v -> a (a.v) + a x v.
constexpr IMat quarterTurn(int ax, int ay, int az) {
  const int a[3] = {ax, ay, az};
  IMat r{};
  for (int j = 0; j < 3; ++j) {
    int e[3] = {0, 0, 0};
    e[j] = 1;
    const int dot = a[0] * e[0] + a[1] * e[1] + a[2] * e[2];
    const int cross[3] = {a[1] * e[2] - a[2] * e[1], a[2] * e[0] - a[0] * e[2], a[0] * e[1] - a[1] * e[0]};
    for (int i = 0; i < 3; ++i) r[i][j] = a[i] * dot + cross[i];
  }
  return r;
}

constexpr IMat kIdentity{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};

// Base rotations taking local +Z to each direction.
constexpr IMat baseFor(int direction) {
  switch (direction) {
    case 0: return IMat{{{0, 0, 1}, {0, 1, 0}, {-1, 0, 0}}};   // +X: 90 deg about Y
    case 1: return IMat{{{0, 0, -1}, {0, 1, 0}, {1, 0, 0}}};   // -X: -90 deg about Y
    case 2: return IMat{{{1, 0, 0}, {0, 0, 1}, {0, -1, 0}}};   // +Y: -90 deg about X
    case 3: return IMat{{{1, 0, 0}, {0, 0, -1}, {0, 1, 0}}};   // -Y: 90 deg about X
    case 4: return kIdentity;                                  // +Z
    default: return IMat{{{1, 0, 0}, {0, -1, 0}, {0, 0, -1}}}; // -Z: 180 deg about X
  }
}

constexpr std::array<int, 3> directionVector(int direction) {
  std::array<int, 3> v{0, 0, 0};
  v[direction / 2] = (direction % 2 == 0) ? 1 : -1;
  return v;
}

constexpr IMat matrixFor(int index) {
  const int direction = index / 4, spin = index % 4;
  const auto d = directionVector(direction);
  const IMat q = quarterTurn(d[0], d[1], d[2]);
  IMat r = baseFor(direction);
  for (int k = 0; k < spin; ++k) r = mul(q, r);
  return r;
}

constexpr bool equal(const IMat& a, const IMat& b) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (a[i][j] != b[i][j]) return false;
  return true;
}

constexpr AxisRotation::Tables buildTables() {
  AxisRotation::Tables t{};
  IMat m[AxisRotation::kCount]{};
  for (int r = 0; r < AxisRotation::kCount; ++r) {
    m[r] = matrixFor(r);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (m[r][i][j] != 0) {
          t.axis[r][i] = int8_t(j);
          t.sign[r][i] = int8_t(m[r][i][j]);
        }
  }
  for (int a = 0; a < AxisRotation::kCount; ++a) {
    for (int b = 0; b < AxisRotation::kCount; ++b) {
      const IMat ab = mul(m[a], m[b]);
      for (int c = 0; c < AxisRotation::kCount; ++c)
        if (equal(ab, m[c])) t.compose[a][b] = uint8_t(c);
    }
    const IMat inv = transpose(m[a]);
    for (int c = 0; c < AxisRotation::kCount; ++c)
      if (equal(inv, m[c])) t.inverse[a] = uint8_t(c);
  }
  return t;
}

constexpr AxisRotation::Tables kTables = buildTables();

// Compile-time proof that the 24 matrices are distinct proper rotations and index 16 is identity.
constexpr bool tablesAreValid() {
  for (int a = 0; a < AxisRotation::kCount; ++a) {
    const IMat ma = matrixFor(a);
    const int det = ma[0][0] * (ma[1][1] * ma[2][2] - ma[1][2] * ma[2][1]) -
                    ma[0][1] * (ma[1][0] * ma[2][2] - ma[1][2] * ma[2][0]) +
                    ma[0][2] * (ma[1][0] * ma[2][1] - ma[1][1] * ma[2][0]);
    if (det != 1) return false;
    for (int b = 0; b < a; ++b)
      if (equal(ma, matrixFor(b))) return false;
    const auto up = directionVector(a / 4);
    for (int i = 0; i < 3; ++i)
      if (ma[i][2] != up[i]) return false;  // local +Z lands on the direction
  }
  return equal(matrixFor(16), kIdentity);
}
static_assert(tablesAreValid(), "axis rotation tables must be 24 distinct proper rotations");

}  // namespace

const AxisRotation::Tables& AxisRotation::table() { return kTables; }

AxisRotation AxisRotation::fromIndex(int index) {
  if (index < 0 || index >= kCount)
    throw InvalidInput("AxisRotation::fromIndex: index is " + std::to_string(index) + ", expected 0..23");
  return AxisRotation(uint8_t(index));
}

AxisRotation AxisRotation::fromDirectionSpin(int direction, int spin) {
  if (direction < 0 || direction >= 6)
    throw InvalidInput("AxisRotation::fromDirectionSpin: direction is " + std::to_string(direction) + ", expected 0..5");
  if (spin < 0 || spin >= 4)
    throw InvalidInput("AxisRotation::fromDirectionSpin: spin is " + std::to_string(spin) + ", expected 0..3");
  return AxisRotation(uint8_t(direction * 4 + spin));
}

Mat3f AxisRotation::matrix() const {
  Mat3f m = Mat3f::Zero();
  for (int i = 0; i < 3; ++i) m(i, sourceAxis(i)) = float(sign(i));
  return m;
}

// note: the 24 are made once, each as it always was (matrix to quaternion, normalised: the same
// bits). Made on every call, the conversion's square roots and branches were 1.6% of
// demolition's instructions: a brick's pose is made for every brick a grid pair or a terrain
// pair meets.
Quatf AxisRotation::quaternion() const {
  static const std::array<Quatf, kCount> kQuaternions = [] {
    std::array<Quatf, kCount> q;
    for (int i = 0; i < kCount; ++i) q[size_t(i)] = Quatf(AxisRotation(uint8_t(i)).matrix()).normalized();
    return q;
  }();
  return kQuaternions[index_];
}

}  // namespace bw
