// The seeded ring station: a hub, spokes and a habitat ring with floors.
#include <algorithm>
#include <array>
#include <cmath>

#include "collision/content/build_writer.h"
#include "collision/core/argument_checks.h"
#include "collision/core/seeded_random.h"

namespace bw {

using namespace buildgen;

namespace {

// ---------------------------------------------------------------------------------- ring station

// Which way is "up" (toward the axis) for a cell of the pixelated ring at (x, y).
AxisRotation towardAxis(float x, float y, int spin) {
  const int direction = std::abs(x) >= std::abs(y) ? (x > 0.f ? kNegX : kPosX) : (y > 0.f ? kNegY : kPosY);
  return rotation(direction, spin);
}

void ringBody(BuildWriter& w, uint64_t seed, float scale) {
  const float s = std::sqrt(scale);
  const float c = kStud;  // lattice cell in the XY plane
  // note: shells 1.5 cells thick keep the digital circle closed: a 1-cell ring leaves
  // diagonal-only contacts a small body could slip through.
  const float band = 1.5f * c;
  const float floorR = snap(80.f * s, c, 8.f);
  const float innerR = floorR - snap(8.f * s, c, 2.4f) - band;
  const float width = snap(16.f * s, 1.6f, 3.2f);
  const float seg = 0.8f;  // length along Z of floor and ceiling bricks
  const int zSegs = std::max(1, int(std::lround(width / seg)));
  const float zStep = width / float(zSegs), z0 = -width * 0.5f;
  const int hubCells = std::max(2, int(std::lround(4.f * s / c)));
  const float hubR = float(hubCells) * c;
  const int spokeHalf = 2;  // spokes are 2 * spokeHalf cells wide and tall
  w.ring({innerR, floorR, width});

  const float outerR = floorR + band;
  const int n = int(std::ceil(outerR / c)) + 1;
  // Squared radii: classification uses exact float products only, so it is the same everywhere.
  const float floor2 = floorR * floorR, outer2 = outerR * outerR, inner2 = innerR * innerR,
              ceilOut = innerR + band, ceilOut2 = ceilOut * ceilOut;
  const float maxModule = floorR - ceilOut - 2.f * c;
  auto cellCenter = [&](int i, int j) { return Vec3f((float(i) + 0.5f) * c, (float(j) + 0.5f) * c, 0.f); };

  w.part("floor");
  for (int j = -n; j < n; ++j)
    for (int i = -n; i < n; ++i) {
      const Vec3f p = cellCenter(i, j);
      const float d2 = p.x() * p.x() + p.y() * p.y();
      if (d2 < floor2 || d2 >= outer2) continue;
      const AxisRotation up = towardAxis(p.x(), p.y(), (i + j) & 3);
      for (int k = 0; k < zSegs; ++k)
        w.add(Vec3f(p.x(), p.y(), z0 + (float(k) + 0.5f) * zStep), Vec3f(c * 0.5f, c * 0.5f, zStep * 0.5f),
              BuildMaterial::Concrete, BrickShape::Box, up);
    }
  w.part("ceiling");
  for (int j = -n; j < n; ++j)
    for (int i = -n; i < n; ++i) {
      const Vec3f p = cellCenter(i, j);
      const float d2 = p.x() * p.x() + p.y() * p.y();
      if (d2 < inner2 || d2 >= ceilOut2) continue;
      const AxisRotation down = towardAxis(-p.x(), -p.y(), (i - j) & 3);
      // Skylight strips of glass in the middle of the band, every 16 cells around the ring.
      const bool skylightColumn = (std::abs(i) % 16) < 2 || (std::abs(j) % 16) < 2;
      for (int k = 0; k < zSegs; ++k) {
        const bool glass = skylightColumn && k > 1 && k + 2 < zSegs;
        w.add(Vec3f(p.x(), p.y(), z0 + (float(k) + 0.5f) * zStep), Vec3f(c * 0.5f, c * 0.5f, zStep * 0.5f),
              glass ? BuildMaterial::Glass : BuildMaterial::Metal, BrickShape::Box, down);
      }
    }
  w.part("walls");
  // Side walls close the band at both ends of Z, on a coarser 0.8 lattice (they are plain plates).
  const float wc = 2.f * c;
  const int wn = n / 2 + 1;
  for (float side : {-1.f, 1.f})
    for (int j = -wn; j < wn; ++j)
      for (int i = -wn; i < wn; ++i) {
        const float x = (float(i) + 0.5f) * wc, y = (float(j) + 0.5f) * wc;
        const float d2 = x * x + y * y;
        if (d2 < inner2 || d2 >= outer2) continue;
        w.add(Vec3f(x, y, side * (width * 0.5f + c * 0.5f)), Vec3f(wc * 0.5f, wc * 0.5f, c * 0.5f), BuildMaterial::Metal);
      }
  w.part("modules", kBuildFilterDetail);
  // Modules (rooms, tanks, crates) standing on the floor: solid blocks of cells in the band just
  // inside the floor. The XY plane is cut into 16-cell blocks; a hash of (seed, block) decides
  // whether a block has a module, how tall it is and which Z range it covers.
  if (maxModule >= c) {
    for (int j = -n; j < n; ++j)
      for (int i = -n; i < n; ++i) {
        const Vec3f p = cellCenter(i, j);
        const float d2 = p.x() * p.x() + p.y() * p.y();
        if (d2 >= floor2) continue;
        const int bx = i >> 4, by = j >> 4;  // arithmetic shift: floor division for negatives too
        SeededRandom blockRng(seed ^ (uint64_t(uint32_t(bx)) * 0x9E3779B1ull) ^ (uint64_t(uint32_t(by)) << 32));
        if (blockRng.below(3) == 0) continue;
        const float height = std::min(maxModule, c * float(3 + blockRng.below(6)));
        const float inner = floorR - height;
        if (d2 < inner * inner) continue;
        const int kz0 = int(blockRng.below(uint32_t(zSegs))), kz1 = std::min(zSegs, kz0 + 1 + int(blockRng.below(3)));
        const AxisRotation up = towardAxis(p.x(), p.y(), 0);
        for (int k = kz0; k < kz1; ++k)
          w.add(Vec3f(p.x(), p.y(), z0 + (float(k) + 0.5f) * zStep), Vec3f(c * 0.5f, c * 0.5f, zStep * 0.5f),
                BuildMaterial::Plastic, BrickShape::Box, up);
      }
  }
  // Lights around the ring at z = 0, one per ~10 units, at radius ceilOut + c: ceiling cells
  // (centres inside ceilOut) reach at most c / sqrt(2) = 0.28 past it and modules stop at least
  // 2c - 0.28 short of it, so every light has 0.1 of open space on each side.
  const float lightR = ceilOut + c;
  const int lights = 4 * std::max(2, int(std::lround(lightR * 6.2831853f / 40.f)));
  const float lightRadius = std::clamp(lightR * 6.2831853f / float(lights), 4.f, 15.f);
  for (int k = 0; k < lights; ++k) w.light(circlePoint(k, lights) * lightR, lightRadius);
  w.part("hub");
  for (int k = 0; k < zSegs; ++k)
    w.add(Vec3f(0, 0, z0 + (float(k) + 0.5f) * zStep), Vec3f(hubR, hubR, zStep * 0.5f), BuildMaterial::Metal,
          BrickShape::Cylinder, AxisRotation::identity(), 32);
  w.part("spokes");
  // Four spokes along +-X and +-Y from the hub to the ceiling, square tubes of cells.
  for (int axis = 0; axis < 2; ++axis)
    for (int u = -n; u < n; ++u) {
      if (u >= -hubCells && u < hubCells) continue;
      for (int v = -spokeHalf; v < spokeHalf; ++v) {
        const Vec3f p = axis == 0 ? cellCenter(u, v) : cellCenter(v, u);
        const float d2 = p.x() * p.x() + p.y() * p.y();
        if (d2 >= inner2) continue;
        for (int k = -spokeHalf; k < spokeHalf; ++k) {
          const bool shell = v == -spokeHalf || v == spokeHalf - 1 || k == -spokeHalf || k == spokeHalf - 1;
          if (!shell) continue;  // hollow: a corridor runs inside
          w.add(Vec3f(p.x(), p.y(), (float(k) + 0.5f) * c), Vec3f::Constant(c * 0.5f), BuildMaterial::Metal, BrickShape::Box,
                rotation(axis == 0 ? kPosX : kPosY, (u & 1) * 2));
        }
      }
    }
}

}  // namespace

GeneratedBuild generateRingStation(uint64_t seed, float scale) {
  requireScale(scale, 0.01, 64.0, "generateRingStation");
  return runBuild("ring_station", [&](BuildWriter& w) { ringBody(w, seed, scale); });
}

}  // namespace bw
