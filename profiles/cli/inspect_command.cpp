// `brickworld inspect FILE`: load a content file, put it into a brick grid and print what it
// became: counts per asset and per shape, bounds, and the OctoBVH's shape and memory, so the
// real builds can be compared with the seeded generators.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "cli/command_registry.h"
#include "collision/brick_grid.h"
#include "collision/brs_reader.h"

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

  if (json) {
    nlohmann::json j;
    j["file"] = path;
    j["format"] = "brs";
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

CommandRegistration reg{"inspect", "Load a content file (.brs) into a brick grid and print counts, bounds and index shape",
                        [](CLI::App& cmd) {
  auto file = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  cmd.add_option("file", *file, "a Brickadia save (.brs)")->required();
  cmd.add_flag("--json", *json, "print one JSON object");
  return [=] {
    const std::string ext = lowerExtension(*file);
    if (ext == ".vox") {
      std::cerr << "brickworld inspect: " << *file
                << ": .vox (MagicaVoxel terrain) inspection is not available yet; only .brs saves can be inspected\n";
      return 2;
    }
    return inspectBrs(*file, *json);
  };
}};

}  // namespace
}  // namespace bw::cli
