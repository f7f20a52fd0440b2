#include "world/scene_budget.h"

#include <unistd.h>

namespace bw {

SceneTotals sceneTotals(const SceneDescription& scene) {
  SceneTotals t;
  for (const GridDescription& g : scene.grids) {
    t.bodies += 1;  // a tiled build is one grid too
    t.listedBricks += g.bricks.size();
  }
  for (const SpawnerDescription& s : scene.spawners) t.bodies += s.count;
  for (const TerrainDescription& tr : scene.terrains) {
    t.bodies += 1;
    if (!tr.generator.empty()) t.generatedVoxels += uint64_t(tr.size.x) * uint64_t(tr.size.y) * uint64_t(tr.size.z);
  }
  t.bytes = t.bodies * kBytesPerBody + t.listedBricks * kBytesPerListedBrick + t.generatedVoxels * kBytesPerGeneratedVoxel;
  return t;
}

uint64_t physicalMemoryBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? uint64_t(pages) * uint64_t(page) : 0;
}

uint64_t memoryBudgetBytes(const SceneSettings& settings) {
  if (settings.memoryBudgetMiB > 0) return uint64_t(settings.memoryBudgetMiB * 1048576.0);
  const uint64_t machine = physicalMemoryBytes();
  return machine ? machine / 2 : uint64_t(8) << 30;  // unknown machine: 8 GiB
}

}  // namespace bw
