// Fuzz target: the .vox reader (parseVox) and the terrain built from what it reads. Any byte
// string either loads or throws InvalidInput; what loads is consistent (voxels inside their
// models, palette counts summing to the placed total, bounds holding every placed voxel) and a
// small load builds a terrain whose written voxels add up to the placed ones.
#include <algorithm>

#include "collision/content/vox_reader.h"
#include "collision/core/errors.h"
#include "fuzz/fuzz_support.h"

namespace {

constexpr int64_t kTerrainVoxelsChecked = int64_t(1) << 18;  // bounds volume up to which a terrain is built

int32_t axis(const bw::Int3& v, int a) { return a == 0 ? v.x : a == 1 ? v.y : v.z; }

void checkLoaded(const bw::VoxModelSet& set) {
  uint64_t fileVoxels = 0;
  for (const bw::VoxModel& m : set.models) {
    for (int a = 0; a < 3; ++a)
      FUZZ_CHECK(axis(m.size, a) >= 1 && axis(m.size, a) <= bw::kVoxMaxModelSize, "model size %d on axis %d", axis(m.size, a), a);
    for (const bw::VoxVoxel& v : m.voxels)
      FUZZ_CHECK(v.x < m.size.x && v.y < m.size.y && v.z < m.size.z && v.colorIndex != 0,
                 "voxel (%d %d %d) index %d outside a %d x %d x %d model", v.x, v.y, v.z, v.colorIndex, m.size.x, m.size.y, m.size.z);
    fileVoxels += m.voxels.size();
  }
  FUZZ_CHECK(fileVoxels == set.fileVoxels, "fileVoxels %llu, models hold %llu", (unsigned long long)set.fileVoxels,
             (unsigned long long)fileVoxels);
  uint64_t placed = 0, counted = 0;
  for (const bw::VoxInstance& inst : set.instances) {
    FUZZ_CHECK(inst.model < set.models.size(), "instance of model %u of %zu", inst.model, set.models.size());
    const bw::VoxModel& m = set.models[inst.model];
    placed += m.voxels.size();
    for (int a = 0; a < 3; ++a)
      FUZZ_CHECK(axis(inst.offset, a) >= axis(set.boundsMin, a) && axis(inst.offset, a) + axis(m.size, a) - 1 <= axis(set.boundsMax, a),
                 "instance box outside the bounds on axis %d", a);
  }
  for (uint64_t c : set.paletteCounts) counted += c;
  FUZZ_CHECK(placed == set.totalVoxels && counted == placed, "placed %llu, totalVoxels %llu, palette counts %llu",
             (unsigned long long)placed, (unsigned long long)set.totalVoxels, (unsigned long long)counted);
  if (set.empty()) return;
  int64_t volume = 1;
  for (int a = 0; a < 3; ++a) volume *= int64_t(axis(set.voxelBoundsMax, a)) - axis(set.voxelBoundsMin, a) + 1;
  if (volume > kTerrainVoxelsChecked) return;
  const bw::VoxTerrain t = bw::buildVoxTerrain(set);
  FUZZ_CHECK(t.solidVoxels + t.waterVoxels + t.skippedVoxels == set.totalVoxels,
             "terrain wrote %llu + %llu water + %llu skipped of %llu placed", (unsigned long long)t.solidVoxels,
             (unsigned long long)t.waterVoxels, (unsigned long long)t.skippedVoxels, (unsigned long long)set.totalVoxels);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  bw::VoxModelSet set;
  try {
    set = bw::parseVox(data, size, "fuzz.vox");
  } catch (const bw::InvalidInput&) {
    return 0;  // refused with a message: the documented outcome for a bad file
  }
  checkLoaded(set);
  return 0;
}
