#include "collision/content/build_writer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "collision/core/argument_checks.h"
#include "collision/core/assert.h"

namespace bw::buildgen {

// Tiles the box [lo, hi] with boxes close to `cell` (stretched so that a whole number fits
// exactly), leaving out cells whose centre is strictly inside one of `holes`. With
// bondAxis >= 0 every other layer along Z is shifted by half a cell along that axis (running
// bond), so its first and last bricks are half bricks. Neighbours share their boundary values
// exactly, so the tiles touch without overlapping.
void tile(BuildWriter& w, const Vec3f& lo, const Vec3f& hi, const Vec3f& cell, BuildMaterial material,
          std::span<const Aabb> holes, int bondAxis) {
  int n[3];
  float step[3];
  for (int a = 0; a < 3; ++a) {
    n[a] = std::max(1, int(std::lround((hi[a] - lo[a]) / cell[a])));
    step[a] = (hi[a] - lo[a]) / float(n[a]);
  }
  auto boundary = [&](int a, int t, int segments, bool shifted) {
    if (t == 0) return lo[a];
    if (t == segments) return hi[a];
    return lo[a] + (shifted ? float(t) - 0.5f : float(t)) * step[a];
  };
  for (int k = 0; k < n[2]; ++k) {
    const bool shifted = bondAxis >= 0 && (k & 1) != 0;
    const int segY = n[1] + (shifted && bondAxis == 1 ? 1 : 0);
    const int segX = n[0] + (shifted && bondAxis == 0 ? 1 : 0);
    const float z0 = boundary(2, k, n[2], false), z1 = boundary(2, k + 1, n[2], false);
    for (int j = 0; j < segY; ++j) {
      const bool sy = shifted && bondAxis == 1;
      const float y0 = boundary(1, j, segY, sy), y1 = boundary(1, j + 1, segY, sy);
      for (int i = 0; i < segX; ++i) {
        const bool sx = shifted && bondAxis == 0;
        const Vec3f blo(boundary(0, i, segX, sx), y0, z0), bhi(boundary(0, i + 1, segX, sx), y1, z1);
        const Vec3f c = (blo + bhi) * 0.5f;
        bool open = false;
        for (const Aabb& h : holes) open = open || strictlyInside(h, c);
        if (!open) w.addBox(blo, bhi, material);
      }
    }
  }
}

// A wall one brick thick between lo and hi, bricks laid along its longer horizontal axis.
void wall(BuildWriter& w, const Vec3f& lo, const Vec3f& hi, float brickLength, float brickHeight,
          BuildMaterial material, std::span<const Aabb> holes) {
  const int along = (hi.x() - lo.x() >= hi.y() - lo.y()) ? 0 : 1;
  Vec3f cell;
  cell[along] = brickLength;
  cell[1 - along] = hi[1 - along] - lo[1 - along];
  cell[2] = brickHeight;
  tile(w, lo, hi, cell, material, holes, along);
}

// A hip roof over [x0, x1] x [y0, y1] starting at z0: level k is a ring of wedges (corner
// wedges at its four corners) inset by k slots, resting on a ring of boxes one slot further
// in, so the roof is a stepped shell one brick thick. Narrow tops are closed with boxes.
void hipRoof(BuildWriter& w, float x0, float x1, float y0, float y1, float z0, float slot, float rise,
             BuildMaterial material) {
  const int nx = std::max(1, int(std::lround((x1 - x0) / slot)));
  const int ny = std::max(1, int(std::lround((y1 - y0) / slot)));
  const float sx = (x1 - x0) / float(nx), sy = (y1 - y0) / float(ny);
  auto cellLo = [&](int i, int j, int k) { return Vec3f(x0 + float(i) * sx, y0 + float(j) * sy, z0 + float(k) * rise); };
  const Vec3f half(sx * 0.5f, sy * 0.5f, rise * 0.5f);
  for (int k = 0;; ++k) {
    const int i0 = k, i1 = nx - 1 - k, j0 = k, j1 = ny - 1 - k;
    if (i1 - i0 < 2 || j1 - j0 < 2) {
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) {
          const Vec3f lo = cellLo(i, j, k);
          w.addBox(lo, lo + half * 2.f, material);
        }
      return;
    }
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const bool edgeX = i == i0 || i == i1, edgeY = j == j0 || j == j1;
        const bool innerRing = !edgeX && !edgeY && (i == i0 + 1 || i == i1 - 1 || j == j0 + 1 || j == j1 - 1);
        const Vec3f c = cellLo(i, j, k) + half;
        if (edgeX && edgeY) {
          // Canonical corner wedge slopes face +X and +Y; spin it to face out of this corner.
          const int spin = (i == i1) ? (j == j1 ? 0 : 3) : (j == j1 ? 1 : 2);
          w.add(c, half, material, BrickShape::CornerWedge, rotation(kPosZ, spin));
        } else if (edgeX || edgeY) {
          // Canonical wedge slope faces +X; spins 1, 2, 3 face +Y, -X, -Y.
          const int spin = edgeX ? (i == i1 ? 0 : 2) : (j == j1 ? 1 : 3);
          w.add(c, half, material, BrickShape::Wedge, rotation(kPosZ, spin));
        } else if (innerRing) {
          w.addBox(c - half, c + half, material);
        }
      }
  }
}

// Windows along a wall [lo, hi] every `pitch`, each `width` wide, spanning [z0, z1].
void addWindows(std::vector<Aabb>& holes, const Vec3f& lo, const Vec3f& hi, float pitch, float width, float z0,
                float z1) {
  const int along = (hi.x() - lo.x() >= hi.y() - lo.y()) ? 0 : 1;
  const float length = hi[along] - lo[along];
  const int count = int(length / pitch);
  const float margin = (length - float(count) * pitch) * 0.5f;
  for (int k = 0; k < count; ++k) {
    const float c = lo[along] + margin + (float(k) + 0.5f) * pitch;
    Aabb h{lo - Vec3f::Constant(0.01f), hi + Vec3f::Constant(0.01f)};
    h.min[along] = c - width * 0.5f;
    h.max[along] = c + width * 0.5f;
    h.min.z() = z0;
    h.max.z() = z1;
    holes.push_back(h);
  }
}

// Four walls around [x0, x1] x [y0, y1] from z0 to z1, thickness one stud; the X-walls own the
// corners. Windows every `pitch` on every wall; `door` (if any) is also cut.
void perimeterWalls(BuildWriter& w, std::vector<Aabb>& holes, float x0, float x1, float y0, float y1, float z0, float z1,
                    float brickLength, float brickHeight, BuildMaterial material, float pitch, float winZ0, float winZ1,
                    const std::optional<Aabb>& door) {
  const std::array<std::array<Vec3f, 2>, 4> walls = {{
      {Vec3f(x0, y0, z0), Vec3f(x1, y0 + kStud, z1)},
      {Vec3f(x0, y1 - kStud, z0), Vec3f(x1, y1, z1)},
      {Vec3f(x0, y0 + kStud, z0), Vec3f(x0 + kStud, y1 - kStud, z1)},
      {Vec3f(x1 - kStud, y0 + kStud, z0), Vec3f(x1, y1 - kStud, z1)},
  }};
  for (const auto& wl : walls) {
    holes.clear();
    addWindows(holes, wl[0], wl[1], pitch, pitch * 0.5f, winZ0, winZ1);
    if (door) holes.push_back(*door);
    wall(w, wl[0], wl[1], brickLength, brickHeight, material, holes);
  }
}

Vec3f circlePoint(int k, int n) {
  BW_ASSERT(n > 0 && n % 4 == 0);
  const int quarter = n / 4;
  k = ((k % n) + n) % n;
  const int turns = k / quarter, j = k % quarter;
  // Past an eighth of a turn, use the complement: cos(a) = sin(pi/2 - a).
  const bool mirror = 2 * j > quarter;
  const double a = double(mirror ? quarter - j : j) * (1.5707963267948966 / double(quarter));
  // note: |a| <= pi/4, where the terms to a^17 / 17! leave an error below 1e-16.
  double c = 0.0, s = 0.0, term = 1.0;
  for (int i = 0; i < 18; ++i) {
    if (i % 2 == 0) c += (i % 4 == 0) ? term : -term;
    else s += (i % 4 == 1) ? term : -term;
    term *= a / double(i + 1);
  }
  if (mirror) std::swap(c, s);
  for (int t = 0; t < turns; ++t) {  // a quarter turn: (x, y) -> (-y, x), exact
    const double x = c;
    c = -s;
    s = x;
  }
  return Vec3f(float(c), float(s), 0.f);
}

void computeBounds(GeneratedBuild& b) {
  Aabb box = Aabb::empty();
  for (const Brick& brick : b.bricks) {
    const Vec3f h = brick.rotation.applyToExtent(brick.halfSize);
    box.merge(Aabb{brick.position - h, brick.position + h});
  }
  b.bounds = box;
}

void requireScale(float scale, double lo, double hi, const char* context) {
  // note: the float argument 0.04f is slightly below the double 0.04; the slack accepts it.
  requireInRange(double(scale), lo * (1.0 - 1e-6), hi, context, "scale");
}

}  // namespace bw::buildgen
