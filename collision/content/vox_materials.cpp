#include "collision/content/vox_reader.h"

#include <algorithm>
#include <charconv>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "collision/content/byte_reader.h"
#include "collision/core/argument_checks.h"

// The .vox reader's colours and materials: MagicaVoxel's default palette and the palette index ->
// terrain material rules (VoxMaterialMap, the water range, the JSON mapping file). Declared in
// vox_reader.h; kept apart from the chunk format (vox_format.cpp) and the terrain build
// (vox_reader.cpp).

namespace bw {
namespace {

std::array<VoxRgba, 256> makeDefaultPalette() {
  std::array<VoxRgba, 256> p{};
  static constexpr uint8_t kCube[6] = {0xff, 0xcc, 0x99, 0x66, 0x33, 0x00};
  static constexpr uint8_t kRamp[10] = {0xee, 0xdd, 0xbb, 0xaa, 0x88, 0x77, 0x55, 0x44, 0x22, 0x11};
  int i = 1;
  for (int r = 0; r < 6; ++r)
    for (int g = 0; g < 6; ++g)
      for (int b = 0; b < 6; ++b)
        if (r != 5 || g != 5 || b != 5) p[size_t(i++)] = VoxRgba{kCube[r], kCube[g], kCube[b], 0xff};
  for (int channel = 0; channel < 4; ++channel)
    for (uint8_t v : kRamp) {
      VoxRgba c{0, 0, 0, 0xff};
      if (channel == 0 || channel == 3) c.r = v;
      if (channel == 1 || channel == 3) c.g = v;
      if (channel == 2 || channel == 3) c.b = v;
      p[size_t(i++)] = c;
    }
  return p;
}

}  // namespace

const std::array<VoxRgba, 256>& voxDefaultPalette() {
  static const std::array<VoxRgba, 256> palette = makeDefaultPalette();
  return palette;
}

// ---- materials ----

VoxMaterialMap VoxMaterialMap::monu6() {
  VoxMaterialMap m;
  m.waterFirst = 29;
  m.waterLast = 31;
  return m;
}

uint8_t VoxMaterialMap::materialFor(uint8_t paletteIndex) const {
  const int16_t o = overrides[paletteIndex];
  if (o >= 0) return uint8_t(o);
  if (paletteIndex == 0) return kMaterialAir;
  if (paletteIndex >= waterFirst && paletteIndex <= waterLast) return kMaterialWater;
  if (solids == Solids::Single) return solidMaterial;
  return uint8_t(std::min(int(paletteIndex) + 1, 255));
}

VoxMaterialMap parseVoxMaterialMap(const std::string& text, const std::string& file) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    failFile(file, "mapping", std::string("not valid JSON: ") + e.what());
  }
  if (!j.is_object()) failFile(file, "mapping", "must be a JSON object");
  auto paletteIndex = [&](const nlohmann::json& v, const std::string& what) {
    if (!v.is_number_integer() || v.get<int64_t>() < 1 || v.get<int64_t>() > 255)
      failFile(file, what, "palette index " + v.dump() + " is not an integer in [1, 255]");
    return int(v.get<int64_t>());
  };
  auto material = [&](const nlohmann::json& v, const std::string& what, int lo) {
    if (!v.is_number_integer() || v.get<int64_t>() < lo || v.get<int64_t>() > 255)
      failFile(file, what, "material " + v.dump() + " is not an integer in [" + std::to_string(lo) + ", 255]");
    return int(v.get<int64_t>());
  };
  VoxMaterialMap m;
  for (const auto& [key, value] : j.items()) {
    if (key == "water") {
      if (!value.is_array() || value.size() != 2) failFile(file, "water", "must be [first, last]");
      m.waterFirst = paletteIndex(value[0], "water");
      m.waterLast = paletteIndex(value[1], "water");
      if (m.waterLast < m.waterFirst) failFile(file, "water", "range " + value.dump() + " is inverted");
    } else if (key == "solids") {
      if (value == "per_index") m.solids = VoxMaterialMap::Solids::PerPaletteIndex;
      else if (value == "single") m.solids = VoxMaterialMap::Solids::Single;
      else failFile(file, "solids", value.dump() + " is neither \"per_index\" nor \"single\"");
    } else if (key == "solid_material") {
      m.solidMaterial = uint8_t(material(value, "solid_material", kMaterialFirstSolid));
    } else if (key == "materials") {
      if (!value.is_object()) failFile(file, "materials", "must be an object {\"paletteIndex\": material}");
      for (const auto& [indexText, mat] : value.items()) {
        int index = 0;
        const auto [next, ec] = std::from_chars(indexText.data(), indexText.data() + indexText.size(), index);
        if (ec != std::errc() || next != indexText.data() + indexText.size() || index < 1 || index > 255)
          failFile(file, "materials", "key \"" + indexText + "\" is not a palette index in [1, 255]");
        m.overrides[size_t(index)] = int16_t(material(mat, "materials[\"" + indexText + "\"]", 0));
      }
    } else {
      failFile(file, "mapping", "unknown key \"" + key + "\" (expected water, solids, solid_material, materials)");
    }
  }
  return m;
}

VoxMaterialMap loadVoxMaterialMap(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) failFile(path, "file", "cannot be opened");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return parseVoxMaterialMap(text, path);
}

}  // namespace bw
