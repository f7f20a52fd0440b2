// `brickworld inspect FILE`: load a content file and print what it became. A .brs save goes into
// a brick grid (counts per asset, per shape and per component, its lights, bounds, the OctoBVH's
// shape and memory, so the real builds can be compared with the seeded generators); a .vox model
// goes into a voxel terrain (models, voxel counts per palette index, water, bounds, chunk and
// broadphase counts).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "cli/command_registry.h"
#include "collision/bricks/brick_grid.h"
#include "collision/content/brs_reader.h"
#include "collision/core/errors.h"
#include "collision/content/vox_reader.h"
#include "collision/core/argument_checks.h"

namespace bw::cli {
namespace {

double msSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

int inspectBrs(const std::string& path, bool json) {
  const auto t0 = std::chrono::steady_clock::now();
  const BrsLoadResult save = loadBrs(path);
  const double loadMs = msSince(t0);

  const auto t1 = std::chrono::steady_clock::now();
  BrickGrid grid(BrickGrid::Config(uint32_t(save.bricks.size()) + 1024));
  for (const Brick& b : save.bricks) grid.placeBrick(b);
  const double placeMs = msSince(t1);

  const auto mem = grid.index().memoryStats();
  const auto shape = grid.index().shapeStats();
  const uint64_t elements = std::max<uint64_t>(mem.elements, 1);
  const uint64_t nodes = mem.nonEmptyNodes;
  const double forcedShare = shape.innerNodes ? double(shape.forcedNodes) / double(shape.innerNodes) : 0.0;
  const Aabb bounds = save.bounds;
  const bool hasBounds = !bounds.isEmpty();
  uint32_t pointLights = 0, spotLights = 0;
  for (const BuildLight& l : save.lights) (l.kind == BuildLightKind::Spot ? spotLights : pointLights) += 1;

  if (json) {
    nlohmann::json j;
    j["file"] = path;
    j["format"] = "brs";
    j["import_scale_m_per_unit"] = 0.04;
    j["version"] = save.version;
    j["game_version"] = save.gameVersion;
    j["map"] = save.mapName;
    j["author"] = save.author;
    j["total_bricks"] = save.totalBricks;
    j["indexed_bricks"] = save.bricks.size();
    j["collision_off"] = save.collisionOff;
    j["unknown_assets"] = save.unknownAssets;
    j["assets"] = save.assetCounts;
    j["shapes"] = save.shapeCounts;
    j["components"] = save.componentCounts;
    j["lights"] = {{"point", pointLights},
                   {"spot", spotLights},
                   {"total", save.lights.size()},
                   {"light_components_found", save.lightComponentsFound}};
    if (hasBounds) {
      j["bounds_min"] = {bounds.min.x(), bounds.min.y(), bounds.min.z()};
      j["bounds_max"] = {bounds.max.x(), bounds.max.y(), bounds.max.z()};
    }
    j["load_ms"] = loadMs;
    j["place_ms"] = placeMs;
    j["octobvh"] = {{"nodes", nodes},
                    {"allocated_nodes", mem.nodes},
                    {"leaves", shape.leaves},
                    {"inner_nodes", shape.innerNodes},
                    {"depth", shape.depth},
                    {"forced_nodes", shape.forcedNodes},
                    {"forced_share", forcedShare},
                    {"forced_elements", shape.forcedElements},
                    {"bytes_per_element", double(mem.totalBytes()) / double(elements)},
                    {"total_bytes", mem.totalBytes()}};
    std::cout << j.dump(2) << "\n";
    return 0;
  }

  std::printf("%s: Brickadia save, format version %d (game %d)\n", path.c_str(), save.version, save.gameVersion);
  std::printf("  scale       1 Brickadia unit = 0.04 m (a 1 x 1 brick is 0.4 m across; sizes below in metres)\n");
  std::printf("  map \"%s\", author \"%s\"\n", save.mapName.c_str(), save.author.c_str());
  std::printf("  bricks      %u in the file, %zu indexed, %u with collision off, %u of unknown assets\n",
              save.totalBricks, save.bricks.size(), save.collisionOff, save.unknownAssets);
  std::printf("  load        %.1f ms (read + parse + convert), placing into the grid %.1f ms\n", loadMs, placeMs);
  if (hasBounds)
    std::printf("  bounds      (%.2f, %.2f, %.2f) .. (%.2f, %.2f, %.2f), size %.2f x %.2f x %.2f\n", bounds.min.x(),
                bounds.min.y(), bounds.min.z(), bounds.max.x(), bounds.max.y(), bounds.max.z(), bounds.extent().x(),
                bounds.extent().y(), bounds.extent().z());
  std::printf("  per shape\n");
  for (const auto& [name, n] : save.shapeCounts) std::printf("    %-34s %8u\n", name.c_str(), n);
  std::printf("  lights      %zu (%u point, %u spot) of %u bricks with a light component\n", save.lights.size(),
              pointLights, spotLights, save.lightComponentsFound);
  std::printf("  per component\n");
  for (const auto& [name, n] : save.componentCounts) std::printf("    %-34s %8u\n", name.c_str(), n);
  std::printf("  per asset\n");
  std::vector<std::pair<std::string, uint32_t>> assets(save.assetCounts.begin(), save.assetCounts.end());
  std::stable_sort(assets.begin(), assets.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
  for (const auto& [name, n] : assets) std::printf("    %-34s %8u\n", name.c_str(), n);
  std::printf("  octobvh     %llu nodes (%llu leaves, %llu inner), depth %d, %.1f B/element\n",
              (unsigned long long)nodes, (unsigned long long)shape.leaves, (unsigned long long)shape.innerNodes,
              shape.depth, double(mem.totalBytes()) / double(elements));
  std::printf("              forced splits at %llu of %llu inner nodes (%.1f%%), %llu elements below their min level\n",
              (unsigned long long)shape.forcedNodes, (unsigned long long)shape.innerNodes, 100.0 * forcedShare,
              (unsigned long long)shape.forcedElements);
  return 0;
}

// The material map for a .vox file: --materials FILE, else --water FIRST LAST, else monu6's
// documented default for a file named monu6.vox, else no water.
struct VoxMapChoice {
  VoxMaterialMap map;
  std::string source;
};

VoxMapChoice chooseVoxMap(const std::string& path, const std::string& mapFile, const std::vector<int>& water) {
  if (!mapFile.empty()) return {loadVoxMaterialMap(mapFile), "mapping file " + mapFile};
  if (water.size() == 2) {
    if (water[0] < 1 || water[1] > 255 || water[1] < water[0])
      throw InvalidInput("brickworld inspect: --water " + std::to_string(water[0]) + " " + std::to_string(water[1]) +
                         " is not a palette range within [1, 255]");
    VoxMaterialMap m;
    m.waterFirst = water[0];
    m.waterLast = water[1];
    return {m, "--water"};
  }
  if (std::filesystem::path(path).filename() == "monu6.vox") return {VoxMaterialMap::monu6(), "monu6 default"};
  return {VoxMaterialMap{}, "none"};
}

int inspectVox(const std::string& path, bool json, const std::string& mapFile, const std::vector<int>& water,
               size_t topN) {
  const auto t0 = std::chrono::steady_clock::now();
  const VoxModelSet set = loadVox(path);
  const double loadMs = msSince(t0);
  const VoxMapChoice choice = chooseVoxMap(path, mapFile, water);

  const auto t1 = std::chrono::steady_clock::now();
  const VoxTerrain vt = buildVoxTerrain(set, choice.map);
  const double buildMs = msSince(t1);
  const Terrain& terrain = *vt.terrain;

  std::vector<std::pair<int, uint64_t>> perIndex;
  for (int i = 1; i < 256; ++i)
    if (set.paletteCounts[size_t(i)] != 0) perIndex.emplace_back(i, set.paletteCounts[size_t(i)]);
  std::stable_sort(perIndex.begin(), perIndex.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
  const size_t usedIndices = perIndex.size();
  if (perIndex.size() > topN) perIndex.resize(topN);
  uint64_t waterInFile = 0;
  for (int i = 1; i < 256; ++i)
    if (choice.map.isWater(uint8_t(i))) waterInFile += set.paletteCounts[size_t(i)];
  const bool hasWaterRange = choice.map.waterFirst <= choice.map.waterLast;
  const Int3& bmin = set.boundsMin;
  const Int3& bmax = set.boundsMax;
  const Int3& vmin = set.voxelBoundsMin;
  const Int3& vmax = set.voxelBoundsMax;
  const Int3& tsize = terrain.voxels().size();
  const Int3& grid = terrain.voxels().chunkGrid();

  if (json) {
    nlohmann::json j;
    j["file"] = path;
    j["format"] = "vox";
    j["version"] = set.version;
    j["default_palette"] = set.defaultPalette;
    j["scene_graph"] = set.hasSceneGraph;
    j["animation_frames"] = set.animationFrames;
    j["import_scale"] = "1 voxel = voxel_size world units (the scene's terrain voxel_size; 1 here)";
    nlohmann::json models = nlohmann::json::array();
    for (const VoxModel& m : set.models)
      models.push_back({{"size", {m.size.x, m.size.y, m.size.z}}, {"voxels", m.voxels.size()}});
    j["models"] = models;
    nlohmann::json instances = nlohmann::json::array();
    for (const VoxInstance& inst : set.instances)
      instances.push_back({{"model", inst.model},
                           {"translation", {inst.translation.x, inst.translation.y, inst.translation.z}},
                           {"offset", {inst.offset.x, inst.offset.y, inst.offset.z}},
                           {"rotation_ignored", inst.rotationIgnored}});
    j["instances"] = instances;
    j["file_voxels"] = set.fileVoxels;
    j["total_voxels"] = set.totalVoxels;
    j["transforms_applied"] = set.transformsApplied;
    j["ignored_rotations"] = set.ignoredRotations;
    j["skipped_chunks"] = set.skippedChunks;
    j["palette_indices_used"] = usedIndices;
    nlohmann::json top = nlohmann::json::array();
    for (const auto& [index, n] : perIndex) {
      const VoxRgba c = set.palette[size_t(index)];
      top.push_back({{"index", index}, {"voxels", n}, {"rgba", {c.r, c.g, c.b, c.a}}});
    }
    j["palette_counts_top"] = top;
    j["material_map"] = choice.source;
    if (hasWaterRange) j["water_range"] = {choice.map.waterFirst, choice.map.waterLast};
    j["water_voxels"] = waterInFile;
    if (bmin.x <= bmax.x) {
      j["bounds_min"] = {bmin.x, bmin.y, bmin.z};
      j["bounds_max"] = {bmax.x, bmax.y, bmax.z};
    }
    if (vmin.x <= vmax.x) {
      j["voxel_bounds_min"] = {vmin.x, vmin.y, vmin.z};
      j["voxel_bounds_max"] = {vmax.x, vmax.y, vmax.z};
    }
    j["load_ms"] = loadMs;
    j["build_ms"] = buildMs;
    j["terrain"] = {{"size", {tsize.x, tsize.y, tsize.z}},
                    {"chunk_grid", {grid.x, grid.y, grid.z}},
                    {"vox_to_terrain", {vt.voxToTerrain.x, vt.voxToTerrain.y, vt.voxToTerrain.z}},
                    {"solid_voxels", vt.solidVoxels},
                    {"water_voxels", vt.waterVoxels},
                    {"skipped_voxels", vt.skippedVoxels},
                    {"stored_chunks", terrain.voxels().storedChunkCount()},
                    {"voxel_bytes", terrain.voxels().residentBytes()},
                    {"broadphase_entries", terrain.broadphase().entryCount()},
                    {"broadphase_masked", terrain.broadphase().maskedCount()},
                    {"broadphase_bytes", terrain.broadphase().bytes()}};
    std::cout << j.dump(2) << "\n";
    return 0;
  }

  std::printf("%s: MagicaVoxel model, version %d, %s palette%s\n", path.c_str(), set.version,
              set.defaultPalette ? "default" : "own", set.hasSceneGraph ? ", scene graph" : "");
  std::printf("  models      %zu, instances %zu, transforms applied %u, rotations ignored %u, chunks skipped %u\n",
              set.models.size(), set.instances.size(), set.transformsApplied, set.ignoredRotations, set.skippedChunks);
  std::printf("  scale       1 voxel = 1 world unit here (a scene's terrain sets voxel_size)\n");
  if (set.animationFrames > 1)
    std::printf("  animation   %u frames: frame 0 placed, the others not (a terrain is one pose)\n", set.animationFrames);
  for (size_t i = 0; i < set.models.size() && i < 16; ++i)
    std::printf("    model %-4zu %d x %d x %d, %zu voxels\n", i, set.models[i].size.x, set.models[i].size.y,
                set.models[i].size.z, set.models[i].voxels.size());
  if (set.models.size() > 16) std::printf("    ... %zu more\n", set.models.size() - 16);
  std::printf("  voxels      %llu placed (%llu in the file), %zu palette indices used\n",
              (unsigned long long)set.totalVoxels, (unsigned long long)set.fileVoxels, usedIndices);
  std::printf("  load        %.1f ms (read + parse + place), building the terrain %.1f ms\n", loadMs, buildMs);
  if (bmin.x <= bmax.x)
    std::printf("  bounds      (%d, %d, %d) .. (%d, %d, %d), %d x %d x %d voxels (model boxes)\n", bmin.x, bmin.y, bmin.z,
                bmax.x, bmax.y, bmax.z, bmax.x - bmin.x + 1, bmax.y - bmin.y + 1, bmax.z - bmin.z + 1);
  if (vmin.x <= vmax.x)
    std::printf("              (%d, %d, %d) .. (%d, %d, %d), %d x %d x %d voxels (occupied)\n", vmin.x, vmin.y, vmin.z,
                vmax.x, vmax.y, vmax.z, vmax.x - vmin.x + 1, vmax.y - vmin.y + 1, vmax.z - vmin.z + 1);
  if (hasWaterRange)
    std::printf("  water       palette %d..%d (%s): %llu voxels\n", choice.map.waterFirst, choice.map.waterLast,
                choice.source.c_str(), (unsigned long long)waterInFile);
  else
    std::printf("  water       %llu voxels (material map: %s; give --water FIRST LAST)\n",
                (unsigned long long)waterInFile, choice.source.c_str());
  std::printf("  per palette index (top %zu)\n", perIndex.size());
  for (const auto& [index, n] : perIndex) {
    const VoxRgba c = set.palette[size_t(index)];
    std::printf("    %3d  rgba(%3d, %3d, %3d, %3d) %s %10llu\n", index, c.r, c.g, c.b, c.a,
                choice.map.isWater(uint8_t(index)) ? "water" : "     ", (unsigned long long)n);
  }
  std::printf("  terrain     %d x %d x %d voxels (%d x %d x %d chunks), %u chunks stored, %.1f KiB of voxels\n", tsize.x,
              tsize.y, tsize.z, grid.x, grid.y, grid.z, terrain.voxels().storedChunkCount(),
              double(terrain.voxels().residentBytes()) / 1024.0);
  std::printf("              %llu solid, %llu water, %llu skipped voxels written\n", (unsigned long long)vt.solidVoxels,
              (unsigned long long)vt.waterVoxels, (unsigned long long)vt.skippedVoxels);
  std::printf("  broadphase  %zu chunk entries, %zu with masks, %.1f KiB\n", terrain.broadphase().entryCount(),
              terrain.broadphase().maskedCount(), double(terrain.broadphase().bytes()) / 1024.0);
  return 0;
}

CommandRegistration reg{"inspect",
                        "Load a content file (.brs into a brick grid, .vox into a voxel terrain) and print counts, "
                        "bounds and index shape",
                        [](CLI::App& cmd) {
  auto file = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  auto materials = std::make_shared<std::string>();
  auto water = std::make_shared<std::vector<int>>();
  auto top = std::make_shared<size_t>(16);
  cmd.add_option("file", *file, "a Brickadia save (.brs) or a MagicaVoxel model (.vox)")->required();
  cmd.add_flag("--json", *json, "print one JSON object");
  cmd.add_option("--water", *water, ".vox: palette indices FIRST LAST that are water")->expected(2);
  cmd.add_option("--materials", *materials, ".vox: a JSON palette -> material mapping file (see vox_reader.h)");
  cmd.add_option("--top", *top, ".vox: palette indices listed, most used first")->capture_default_str();
  return [=] {
    const std::string ext = lowerExtension(*file);
    if (ext == ".vox") return inspectVox(*file, *json, *materials, *water, *top);
    if (ext == ".brs") return inspectBrs(*file, *json);
    throw InvalidInput(*file + ": expected a Brickadia save (.brs) or a MagicaVoxel model (.vox), got a '" + ext +
                       "' file (a scene runs with `brickworld run`)");
  };
}};

}  // namespace
}  // namespace bw::cli
