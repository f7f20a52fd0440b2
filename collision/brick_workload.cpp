#include "collision/brick_workload.h"

#include <algorithm>
#include <cmath>

#include "collision/seeded_random.h"

namespace bw {

namespace {

float snapTo(double v, float step) { return step > 0 ? float(std::round(v / step) * step) : float(v); }

Vec3f smallSize(SeededRandom& r, bool micro) {
  if (micro && r.unit() < 0.1) {
    const float m = 0.04f * float(1 + r.below(3));
    return {m, m * float(1 + r.below(2)), m};
  }
  static const float kStuds[] = {0.2f, 0.4f, 0.8f, 1.2f, 1.6f, 2.0f};
  return {kStuds[r.below(6)], kStuds[r.below(3)], kStuds[r.below(6)]};
}

}  // namespace

std::vector<Aabb> generateBrickWorkload(const BrickWorkloadParams& p) {
  SeededRandom r(p.seed);
  struct Cluster {
    Vec3d centre;
    double radius;
    double weight;
  };
  std::vector<Cluster> clusters(std::max<uint32_t>(p.clusters, 1));
  double totalWeight = 0;
  for (auto& c : clusters) {
    c.centre = {r.uniform(0, p.extent), r.uniform(0, p.extent * 0.25), r.uniform(0, p.extent)};
    c.radius = r.logUniform(5.0, p.extent * 0.1);
    c.weight = std::pow(r.unit() + 0.02, 3.0);  // a few dominant clusters, many sparse ones
    totalWeight += c.weight;
  }
  std::vector<Aabb> out;
  out.reserve(p.count);
  for (uint32_t i = 0; i < p.count; ++i) {
    double pick = r.unit() * totalWeight;
    size_t ci = 0;
    while (ci + 1 < clusters.size() && pick >= clusters[ci].weight) pick -= clusters[ci++].weight;
    const Cluster& c = clusters[ci];
    const double kind = r.unit();
    Vec3f size;
    if (kind < p.smallShare) {
      size = smallSize(r, p.microbricks);
    } else if (kind < p.smallShare + p.mediumShare) {
      size = {float(r.logUniform(2, 20)), float(r.logUniform(0.4, 10)), float(r.logUniform(2, 20))};
    } else {
      // Huge thin plates (floors, walls) and long ramps.
      const float thick = float(r.logUniform(0.04, 2.0));
      const float a = float(r.logUniform(50, 500)), b = float(r.logUniform(2, 500));
      switch (r.below(3)) {
        case 0: size = {a, thick, b}; break;       // floor plate
        case 1: size = {a, b * 0.2f, thick}; break; // wall
        default: size = {thick * 4, a * 0.3f, b};   // ramp-like slab
      }
    }
    Vec3f centre;
    for (int k = 0; k < 3; ++k) centre[k] = snapTo(c.centre[k] + r.normal() * c.radius, p.snap);
    Aabb b{centre - size * 0.5f + p.offset, centre + size * 0.5f + p.offset};
    out.push_back(b);
  }
  return out;
}

std::vector<Aabb> generatePlateStack(uint32_t plates, float size, uint64_t seed) {
  SeededRandom r(seed);
  std::vector<Aabb> out;
  float y = 0;
  for (uint32_t i = 0; i < plates; ++i) {
    const float thick = float(r.uniform(0.2, 0.4));
    const Vec3f jitter(float(r.uniform(-2, 2)), 0.f, float(r.uniform(-2, 2)));
    out.push_back({Vec3f(-size * 0.5f, y, -size * 0.5f) + jitter, Vec3f(size * 0.5f, y + thick, size * 0.5f) + jitter});
    y += thick;
  }
  return out;
}

}  // namespace bw
