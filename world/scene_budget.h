#pragma once
/// What a scene declares in all and the memory it will need, estimated from the description
/// alone, before anything is built: a scene of 1000 spawners of 10^6 bodies each passed every
/// per-field check and grew without bound towards the out-of-memory killer. validateScene()
/// refuses a scene over scene_limits::kMaxTotalBodies bodies or over its memory budget with one
/// message naming the totals and the limit.
///
/// The estimate counts what the description states: bodies (grids, their tiles, spawned
/// primitives and grid copies, terrains), bricks listed in the scene, voxels of generated
/// terrains. Bricks of generators and .brs saves and voxels of .vox models are known only
/// once read, so they are not in it (their readers bound them: brick pools, the .vox limits).
#include <cstdint>
#include <string>

#include "world/scene_description.h"

namespace bw {

struct SceneTotals {
  uint64_t bodies = 0;
  uint64_t listedBricks = 0;     ///< bricks given in the scene's grids
  uint64_t generatedVoxels = 0;  ///< voxels of generated terrains
  uint64_t bytes = 0;            ///< the memory estimate (the per-item costs below)
};

/// Measured: 1M spheres peak at 509 MiB resident (`brickworld run` of a 1M-sphere scene, session
/// 9): ~530 B a body with its broadphase, pair and containment state; a brick ~60 B in its grid
/// (pool and OctoBVH, profiles/RESULTS.md); a voxel 2 B plus its masks.
constexpr uint64_t kBytesPerBody = 600, kBytesPerListedBrick = 64, kBytesPerGeneratedVoxel = 3;

SceneTotals sceneTotals(const SceneDescription& scene);
/// The budget in bytes: settings.memory_budget_mib, or half this machine's physical memory.
uint64_t memoryBudgetBytes(const SceneSettings& settings);
/// This machine's physical memory in bytes (sysconf), 0 when unknown.
uint64_t physicalMemoryBytes();

}  // namespace bw
