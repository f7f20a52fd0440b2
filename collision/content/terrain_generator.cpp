#include "collision/content/terrain_generator.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "collision/core/errors.h"
#include "collision/core/seeded_random.h"

namespace bw {

void generateRandomTerrain(VoxelTerrain& t, uint32_t seed, float blobDensity) {
  std::mt19937 rng(seed);
  // note: std::mt19937 is fully specified, std::uniform_real_distribution is not (libstdc++
  // and libc++ differ); the unit draw is written out so the terrain is the same everywhere.
  auto u = [](std::mt19937& g) { return float(g() >> 8) * 0x1.0p-24f; };
  const Int3 s = t.size();
  const float fx = 0.05f + 0.2f * u(rng), fz = 0.05f + 0.2f * u(rng), ph = 6.f * u(rng);
  const int base = std::max(1, s.y / 3);
  const int waterLevel = std::min(s.y - 1, base + 2);
  for (int z = 0; z < s.z; ++z) {
    for (int x = 0; x < s.x; ++x) {
      const int h = std::clamp(base + int(std::lround(3.f * std::sin(fx * float(x) + ph) * std::cos(fz * float(z)))), 0, s.y - 1);
      const uint8_t mat = uint8_t(kMaterialFirstSolid + ((x / 5 + z / 7) % 3));
      t.fillBox({x, 0, z}, {x, h, z}, Voxel::make(mat, 255));
      if (h < waterLevel) t.fillBox({x, h + 1, z}, {x, waterLevel, z}, Voxel::make(kMaterialWater, 200));
    }
  }
  const int blobs = int(blobDensity * float(s.x) * float(s.y) * float(s.z) / 8.f);
  for (int i = 0; i < blobs; ++i) {
    const Int3 lo{int(rng() % uint32_t(s.x)), int(rng() % uint32_t(s.y)), int(rng() % uint32_t(s.z))};
    const Int3 hi{std::min(s.x - 1, lo.x + int(rng() % 3)), std::min(s.y - 1, lo.y + int(rng() % 3)),
                  std::min(s.z - 1, lo.z + int(rng() % 3))};
    const uint32_t kind = rng() % 4;
    const Voxel v = kind == 0 ? Voxel{}
                              : (kind == 1 ? Voxel::make(kMaterialWater, 255) : Voxel::make(uint8_t(2 + rng() % 5), 255));
    t.fillBox(lo, hi, v);
  }
}

namespace {

struct Waves {
  float f[4], p[4], a[4];
  explicit Waves(uint32_t seed) {
    std::mt19937 rng(seed);
    auto u = [](std::mt19937& g) { return float(g() >> 8) * 0x1.0p-24f; };  // as above
    for (int i = 0; i < 4; ++i) {
      f[i] = (0.004f + 0.03f * u(rng)) * float(1 << i);
      p[i] = 6.2831853f * u(rng);
      a[i] = 1.f / float(1 << i);
    }
  }
  /// In [0, 1].
  float at(float x, float z) const {
    float h = 0.f, norm = 0.f;
    for (int i = 0; i < 4; ++i) {
      h += a[i] * std::sin(f[i] * x + p[i]) * std::cos(f[i] * 0.7f * z + 1.3f * p[i]);
      norm += a[i];
    }
    return 0.5f + 0.5f * h / norm;
  }
};

}  // namespace

void generateRollingHills(VoxelTerrain& t, uint32_t seed, int base, int amplitude, int waterLevel) {
  const Waves w(seed);
  const Int3 s = t.size();
  for (int z = 0; z < s.z; ++z) {
    for (int x = 0; x < s.x; ++x) {
      const int h = std::clamp(base + int(float(amplitude) * w.at(float(x), float(z))), 0, s.y - 1);
      t.fillBox({x, 0, z}, {x, h, z}, Voxel::make(uint8_t(kMaterialFirstSolid + (h % 4)), 255));
      if (h < waterLevel) t.fillBox({x, h + 1, z}, {x, std::min(waterLevel, s.y - 1), z}, Voxel::make(kMaterialWater, 255));
    }
  }
}

void generateQuarry(VoxelTerrain& t, uint32_t seed) {
  const Int3 s = t.size();
  if (s.x < 32 || s.y < 32 || s.z < 16)
    throw InvalidInput("generateQuarry: the terrain is " + std::to_string(s.x) + " x " + std::to_string(s.y) + " x " + std::to_string(s.z) +
                       " voxels, at least 32 x 32 x 16 needed");
  SeededRandom r(seed);
  const int ground = 4, top = s.z * 3 / 4, edge = s.x / 8;
  t.fillBox({0, 0, 0}, {s.x - 1, s.y - 1, ground - 1}, Voxel::make(kMaterialFirstSolid));
  const int cliffFront = s.y - s.y / 5;
  t.fillBox({edge, cliffFront, ground}, {s.x - 1 - edge, s.y - 1, top - 1}, Voxel::make(kMaterialFirstSolid + 1));
  const int finY = cliffFront - 6;
  t.fillBox({edge + 2, finY, ground}, {s.x - 3 - edge, finY + 1, top * 4 / 5 - 1}, Voxel::make(kMaterialFirstSolid + 2));
  const int pillarY = finY - 10;
  for (int x = edge + 2; x + 4 <= s.x - edge; x += 10) {
    const int h = ground + int(float(top - ground) * float(r.uniform(0.6, 1.0)));
    t.fillBox({x, pillarY, ground}, {x + 3, pillarY + 3, h - 1}, Voxel::make(kMaterialFirstSolid + 3));
  }
}

float heightfieldHeight(float x, float z, float amplitude, uint32_t seed) {
  return amplitude * Waves(seed).at(x, z);
}

HeightfieldMesh makeHeightfieldMesh(uint32_t n, float spacing, float amplitude, uint32_t seed) {
  const Waves w(seed);
  HeightfieldMesh m;
  m.vertices.reserve(size_t(n + 1) * (n + 1));
  for (uint32_t z = 0; z <= n; ++z) {
    for (uint32_t x = 0; x <= n; ++x) {
      const float px = float(x) * spacing, pz = float(z) * spacing;
      m.vertices.emplace_back(px, amplitude * w.at(px, pz), pz);
    }
  }
  m.indices.reserve(size_t(n) * n * 6);
  for (uint32_t z = 0; z < n; ++z) {
    for (uint32_t x = 0; x < n; ++x) {
      const uint32_t a = z * (n + 1) + x, b = a + 1, c = a + (n + 1), d = c + 1;
      // Counter-clockwise seen from above (+Y).
      m.indices.insert(m.indices.end(), {a, c, d, a, d, b});
    }
  }
  return m;
}

}  // namespace bw
