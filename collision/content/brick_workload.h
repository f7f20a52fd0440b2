#pragma once
/// The seeded brick-build workload shared by tests, benchmarks and scenes: box elements with
/// the size mix and clustering of real brick builds (article 000's load workload).
///
/// Mix: ~90% small bricks (0.2..2 per side, microbricks down to 0.04 when enabled), ~9% medium
/// (2..20), ~1% huge thin plates, walls and ramps (one side 50..500, another 2..50, thickness
/// 0.04..2).
/// Placement: `clusters` centres with very uneven brick counts; each cluster's radius is the one
/// at which its bricks fill 10..60% of its volume times `density` (real bricks tile space rather
/// than pile up), positions snapped to a 0.2 lattice so many bricks touch exactly, as in a real
/// build. `density` 1 is the sparse build; kDenseBuild packs the same bricks 200x tighter, so a
/// 2 m box around a brick meets ~75 elements, a third of them huge (the dense build of issue 20).
#include <cstdint>
#include <vector>

#include "collision/core/aabb.h"

namespace bw {

struct BrickWorkloadParams {
  uint32_t count = 100'000;
  uint64_t seed = 1;
  uint32_t clusters = 30;
  float extent = 2000.f;       ///< side of the region cluster centres fall in
  Vec3f offset = Vec3f::Zero(); ///< added to every element (far-from-origin workloads)
  float smallShare = 0.90f;
  float mediumShare = 0.09f;   ///< the rest are huge plates/ramps
  bool microbricks = true;     ///< some small bricks are 0.04-unit microbricks
  float snap = 0.2f;           ///< lattice positions snap to (0: no snapping)
  float density = 1.f;         ///< multiplies every cluster's fill (> 0): its radius scales by density^-1/3
};

/// `density` of the dense build (sparse: 1).
constexpr float kDenseBuild = 200.f;

/// Deterministic for a given params value, on every platform.
std::vector<Aabb> generateBrickWorkload(const BrickWorkloadParams& p);

/// Workload for stacks of large flat plates (the article's worst case for loose octrees):
/// `plates` plates of size x size, thickness 0.2..0.4, stacked with small jitter.
std::vector<Aabb> generatePlateStack(uint32_t plates, float size, uint64_t seed);

}  // namespace bw
