#include "collision/content/vox_reader.h"

#include <algorithm>
#include <fstream>
#include <limits>
#include <map>
#include <utility>

#include "collision/content/byte_reader.h"
#include "collision/content/vox_format.h"
#include "collision/core/argument_checks.h"

// The build step of the .vox reader: chunks and the scene graph are read by vox_format.h and the
// palette and material rules live in vox_materials.cpp; here the placed model set gets its
// bounds and counts, and the terrain is built from it.

namespace bw {
namespace {

using vox::SceneNode;
using vox::SceneWalker;

// A .vox file holds at most a few hundred models of 256^3 voxels; anything above 2 GiB is not one.
constexpr std::streamoff kMaxFileBytes = std::streamoff(1) << 31;

struct Bounds {
  Int3 lo{std::numeric_limits<int32_t>::max(), std::numeric_limits<int32_t>::max(),
          std::numeric_limits<int32_t>::max()};
  Int3 hi{std::numeric_limits<int32_t>::min(), std::numeric_limits<int32_t>::min(),
          std::numeric_limits<int32_t>::min()};
  void add(const Int3& v) {
    lo = {std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z)};
    hi = {std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z)};
  }
  bool empty() const { return lo.x > hi.x; }
};

}  // namespace

uint64_t VoxModelSet::countInRange(int first, int last) const {
  uint64_t n = 0;
  for (int i = std::max(first, 0); i <= std::min(last, 255); ++i) n += paletteCounts[size_t(i)];
  return n;
}

VoxModelSet parseVox(const uint8_t* data, size_t size, const std::string& file) {
  VoxModelSet set;
  const std::map<int32_t, SceneNode> nodes = vox::readVoxChunks(data, size, file, set);

  // Placement.
  set.hasSceneGraph = !nodes.empty();
  if (set.hasSceneGraph) {
    SceneWalker(nodes, set.models, file).walk(set.instances, set.transformsApplied, set.ignoredRotations);
  } else {
    // Several models without a scene graph: an animation's frames (MagicaVoxel 0.98 and earlier).
    if (!set.models.empty()) set.instances.push_back(VoxInstance{0, {}, {}, false});
    set.animationFrames = std::max<uint32_t>(1, uint32_t(set.models.size()));
  }
  for (const auto& [id, node] : nodes) set.animationFrames = std::max(set.animationFrames, node.frames);

  // Per-model tight bounds and palette counts once; instances only add them up (a shared model
  // may be placed thousands of times).
  std::vector<Bounds> modelBounds(set.models.size());
  std::vector<std::array<uint32_t, 256>> modelCounts(set.models.size());
  for (size_t i = 0; i < set.models.size(); ++i) {
    modelCounts[i].fill(0);
    for (const VoxVoxel& v : set.models[i].voxels) {
      modelBounds[i].add({v.x, v.y, v.z});
      ++modelCounts[i][v.colorIndex];
    }
  }
  Bounds boxes, tight;
  for (const VoxInstance& inst : set.instances) {
    const VoxModel& model = set.models[inst.model];
    boxes.add(inst.offset);
    boxes.add({inst.offset.x + model.size.x - 1, inst.offset.y + model.size.y - 1, inst.offset.z + model.size.z - 1});
    const Bounds& local = modelBounds[inst.model];
    for (size_t c = 0; c < 256; ++c) set.paletteCounts[c] += modelCounts[inst.model][c];
    set.totalVoxels += model.voxels.size();
    if (set.totalVoxels > kVoxMaxPlacedVoxels)
      failFile(file, "scene graph", "places more than " + std::to_string(kVoxMaxPlacedVoxels) + " voxels");
    if (!local.empty()) {
      tight.add({inst.offset.x + local.lo.x, inst.offset.y + local.lo.y, inst.offset.z + local.lo.z});
      tight.add({inst.offset.x + local.hi.x, inst.offset.y + local.hi.y, inst.offset.z + local.hi.z});
    }
  }
  if (boxes.empty()) {
    set.boundsMin = {0, 0, 0};
    set.boundsMax = {-1, -1, -1};
  } else {
    set.boundsMin = boxes.lo;
    set.boundsMax = boxes.hi;
  }
  if (tight.empty()) {
    set.voxelBoundsMin = {0, 0, 0};
    set.voxelBoundsMax = {-1, -1, -1};
  } else {
    set.voxelBoundsMin = tight.lo;
    set.voxelBoundsMax = tight.hi;
  }
  return set;
}

VoxModelSet loadVox(const std::string& path) {
  requireRegularFile(path, "a MagicaVoxel .vox model");
  std::ifstream in(path, std::ios::binary);
  if (!in) failFile(path, "file", "cannot be opened");
  in.seekg(0, std::ios::end);
  const std::streamoff end = in.tellg();
  if (end < 0) failFile(path, "file", "cannot be read");
  if (end > kMaxFileBytes) failFile(path, "file", "is larger than 2 GiB");
  std::vector<uint8_t> bytes(static_cast<size_t>(end));
  in.seekg(0, std::ios::beg);
  if (!bytes.empty() && !in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(bytes.size())))
    failFile(path, "file", "cannot be read");
  return parseVox(bytes.data(), bytes.size(), path);
}

// ---- terrain ----

VoxTerrain buildVoxTerrain(const VoxModelSet& set, const VoxMaterialMap& materials, const VoxTerrainOptions& options) {
  const char* context = "buildVoxTerrain";
  if (options.margin < 0 || options.margin > (1 << 20))
    throw InvalidInput(std::string(context) + ": margin " + std::to_string(options.margin) + " is outside [0, 2^20]");
  if (materials.solids == VoxMaterialMap::Solids::Single && materials.solidMaterial < kMaterialFirstSolid)
    throw InvalidInput(std::string(context) + ": solidMaterial " + std::to_string(materials.solidMaterial) +
                       " is not a solid material (>= 2)");
  const bool none = set.boundsMin.x > set.boundsMax.x;
  const Int3 lo = none ? Int3{} : set.boundsMin;
  const Int3 hi = none ? Int3{-1, -1, -1} : set.boundsMax;
  const int64_t margin = options.margin;
  auto extent = [&](int32_t a, int32_t b) { return std::max<int64_t>(int64_t(b) - int64_t(a) + 1 + 2 * margin, 1); };
  const int64_t sx = extent(lo.x, hi.x), sy = extent(lo.y, hi.y), sz = extent(lo.z, hi.z);
  for (int64_t s : {sx, sy, sz})
    if (s > VoxelTerrain::kMaxSize)
      throw InvalidInput(std::string(context) + ": model bounds plus margin span " + std::to_string(s) +
                         " voxels, more than a terrain holds (" + std::to_string(VoxelTerrain::kMaxSize) + ")");

  VoxTerrain out;
  out.voxToTerrain = {int32_t(margin - lo.x), int32_t(margin - lo.y), int32_t(margin - lo.z)};
  out.terrain = std::make_unique<Terrain>(Int3{int32_t(sx), int32_t(sy), int32_t(sz)}, options.voxelSize,
                                          options.placement, options.cacheBudgetBytes);

  std::array<uint8_t, 256> materialOf{};
  for (int i = 0; i < 256; ++i) materialOf[size_t(i)] = materials.materialFor(uint8_t(i));
  if (set.totalVoxels == 0) return out;

  const Int3 editLo{int32_t(margin), int32_t(margin), int32_t(margin)};
  const Int3 editHi{int32_t(sx - margin - 1), int32_t(sy - margin - 1), int32_t(sz - margin - 1)};
  out.terrain->edit(editLo, editHi, [&](VoxelTerrain& voxels) {
    for (const VoxInstance& inst : set.instances) {
      const Int3 base{inst.offset.x + out.voxToTerrain.x, inst.offset.y + out.voxToTerrain.y,
                      inst.offset.z + out.voxToTerrain.z};
      for (const VoxVoxel& v : set.models[inst.model].voxels) {
        const uint8_t mat = materialOf[v.colorIndex];
        if (mat == kMaterialAir) {
          ++out.skippedVoxels;
          continue;
        }
        if (mat == kMaterialWater) ++out.waterVoxels;
        else ++out.solidVoxels;
        voxels.set({base.x + v.x, base.y + v.y, base.z + v.z}, Voxel::make(mat));
      }
    }
  });
  return out;
}

}  // namespace bw
