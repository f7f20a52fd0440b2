#include "collision/content/brick_workload.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "collision/core/errors.h"
#include "collision/core/seeded_random.h"

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
  if (!(p.density > 0.f) || !std::isfinite(p.density))
    throw InvalidInput("generateBrickWorkload: density is " + std::to_string(p.density) + ", expected a finite value > 0");
  SeededRandom r(p.seed);
  struct Cluster {
    Vec3d centre;
    double weight;
    double volume = 0;  // total volume of its bricks
    double radius = 2;
  };
  std::vector<Cluster> clusters(std::max<uint32_t>(p.clusters, 1));
  double totalWeight = 0;
  for (auto& c : clusters) {
    c.centre = {r.uniform(0, p.extent), r.uniform(0, p.extent * 0.25), r.uniform(0, p.extent)};
    c.weight = std::pow(r.unit() + 0.02, 3.0);  // a few dominant clusters, many sparse ones
    totalWeight += c.weight;
  }
  // Pass 1: sizes and cluster of every brick.
  std::vector<Vec3f> sizes(p.count);
  std::vector<uint32_t> owner(p.count);
  for (uint32_t i = 0; i < p.count; ++i) {
    double pick = r.unit() * totalWeight;
    uint32_t ci = 0;
    while (ci + 1 < clusters.size() && pick >= clusters[ci].weight) pick -= clusters[ci++].weight;
    owner[i] = ci;
    const double kind = r.unit();
    Vec3f size;
    if (kind < p.smallShare) {
      size = smallSize(r, p.microbricks);
    } else if (kind < p.smallShare + p.mediumShare) {
      size = {float(r.logUniform(2, 20)), float(r.logUniform(0.4, 10)), float(r.logUniform(2, 20))};
    } else {
      // Huge elements: long thin plates, walls and ramps up to 500 long. The second side stays
      // below 50 so they do not pile into stacks of 500x500 floors at every point (the plate
      // stack is its own workload, generatePlateStack).
      const float thick = float(r.logUniform(0.04, 2.0));
      const float a = float(r.logUniform(50, 500)), b = float(r.logUniform(2, 50));
      switch (r.below(3)) {
        case 0: size = {a, thick, b}; break;         // floor plate
        case 1: size = {b, a * 0.2f, thick}; break;  // wall
        default: size = {thick * 4, b, a};           // long ramp
      }
    }
    sizes[i] = size;
    clusters[ci].volume += double(size.prod());
  }
  // Real bricks tile space instead of piling up: each cluster gets the radius at which its bricks
  // fill 10..60% of its volume (hollow hulls next to solid detail), times the density.
  for (auto& c : clusters) {
    const double fill = r.logUniform(0.1, 0.6) * double(p.density);
    c.radius = std::max(2.0, std::cbrt(c.volume / fill * 3.0 / (4.0 * 3.14159265358979)));
  }
  // Pass 2: positions, normally spread around the cluster centre (sigma = radius / 2).
  std::vector<Aabb> out;
  out.reserve(p.count);
  for (uint32_t i = 0; i < p.count; ++i) {
    const Cluster& c = clusters[owner[i]];
    Vec3f centre;
    for (int k = 0; k < 3; ++k) centre[k] = snapTo(c.centre[k] + r.normal() * c.radius * 0.5, p.snap);
    out.push_back({centre - sizes[i] * 0.5f + p.offset, centre + sizes[i] * 0.5f + p.offset});
  }
  return out;
}

std::vector<Aabb> generatePlateStack(uint32_t plates, float size, uint64_t seed) {
  SeededRandom r(seed);
  std::vector<Aabb> out;
  float y = 0;
  for (uint32_t i = 0; i < plates; ++i) {
    const float thick = float(r.uniform(0.2, 0.4));
    const float jx = float(r.uniform(-2, 2));  // one draw per statement: argument order is unspecified
    const float jz = float(r.uniform(-2, 2));
    const Vec3f jitter(jx, 0.f, jz);
    out.push_back({Vec3f(-size * 0.5f, y, -size * 0.5f) + jitter, Vec3f(size * 0.5f, y + thick, size * 0.5f) + jitter});
    y += thick;
  }
  return out;
}

}  // namespace bw
