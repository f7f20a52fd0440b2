#include "collision/content/brs_reader.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <utility>

#include "collision/bricks/brick_geometry.h"
#include "collision/content/brs_asset_mapping.h"
#include "collision/content/byte_reader.h"
#include "collision/content/brs_components.h"
#include "collision/content/brs_format.h"
#include "collision/core/argument_checks.h"

// The build step of the .brs reader: header and section reading come from brs_format.h, asset
// and orientation mapping from brs_asset_mapping.h, the components from brs_components.h; here
// the brick records are decoded and turned into Bricks, and light components into BuildLights.

namespace bw {
namespace {

using brs::AssetMapping;
using brs::BitReader;
using brs::BrsReader;
using brs::Component;
using brs::Fold;
using brs::fold180AboutX;
using brs::foldMinus90AboutX;
using brs::Header1;
using brs::Header2;
using brs::kMaxSectionBytes;
using brs::kMaxVersion;
using brs::kMinVersion;
using brs::kUnknownHalfSize;
using brs::mapAsset;
using brs::orientationTable;
using brs::readHeader1;
using brs::readComponents;
using brs::readHeader2;
using brs::readSection;

// Half sizes beyond this (100,000 studs) are corrupt records, not builds.
constexpr uint64_t kMaxBrsHalfSize = 1'000'000;
// Positions beyond this are corrupt too; it also keeps position * scale well inside float range.
constexpr int64_t kMaxBrsPosition = int64_t(1) << 30;
constexpr size_t kMinRecordBytes = 5;
// Reservations are capped so that a corrupt count cannot allocate ahead of the data that backs it.
constexpr uint32_t kMaxReserve = 1u << 20;

// One BuildLight per brick carrying a point or spot light component (see brs_reader.h).
void addLights(const Component& c, float unitsPerBrsUnit, const std::string& file, BrsLoadResult& out) {
  const bool light = c.name.size() >= 5 && c.name.compare(c.name.size() - 5, 5, "Light") == 0;
  if (light) out.lightComponentsFound += uint32_t(c.bricks.size());
  BuildLightKind kind;
  if (c.name == "BCD_PointLight") kind = BuildLightKind::Point;
  else if (c.name == "BCD_SpotLight") kind = BuildLightKind::Spot;
  else return;
  for (size_t k = 0; k < c.bricks.size(); ++k) {
    const uint32_t record = c.bricks[k];
    const BrsBrickRecord& rec = out.records[record];
    const float stored = c.radius.empty() ? 0.f : c.radius[k];
    const float radius = (stored > 0.f ? stored : kBrsDefaultLightRadius) * unitsPerBrsUnit;
    if (!std::isfinite(stored) || !std::isfinite(radius))
      failFile(file, "components",
               c.name + ": brick " + std::to_string(record) + ": Radius " + std::to_string(stored) + " is not finite");
    BuildLight l;
    l.position = Vec3f(float(rec.position[0]), float(rec.position[1]), float(rec.position[2])) * unitsPerBrsUnit;
    l.radius = radius;
    l.kind = kind;
    out.lights.push_back(l);
    out.lightRecords.push_back(record);
  }
}

}  // namespace

const char* brickShapeName(BrickShape shape) {
  switch (shape) {
    case BrickShape::Box: return "box";
    case BrickShape::Wedge: return "wedge";
    case BrickShape::CornerWedge: return "corner_wedge";
    case BrickShape::Cylinder: return "cylinder";
  }
  return "unknown";
}

BrsLoadResult parseBrs(const uint8_t* data, size_t size, const std::string& name, float unitsPerBrsUnit) {
  if (!(unitsPerBrsUnit > 0.f) || !(unitsPerBrsUnit < 1e6f))
    failFile(name, "arguments", "unitsPerBrsUnit is " + std::to_string(unitsPerBrsUnit) + ", expected > 0");
  if (data == nullptr && size != 0) failFile(name, "arguments", "data is null");
  if (size == 0) failFile(name, "file", "is empty");
  BrsReader file(data, size, name, "file");
  const uint8_t* magic = file.take(3, "magic");
  if (std::memcmp(magic, "BRS", 3) != 0) failFile(name, "file", "wrong magic (not a Brickadia save: expected \"BRS\")");
  BrsLoadResult out;
  out.version = file.u16("version");
  if (out.version < kMinVersion || out.version > kMaxVersion)
    failFile(name, "file",
         "unsupported version " + std::to_string(out.version) + " (supported: " + std::to_string(kMinVersion) + " to " +
             std::to_string(kMaxVersion) + ")");
  out.gameVersion = file.i32("game version");

  const Header1 h1 = readHeader1(readSection(file, "header1", name), name);
  Header2 h2 = readHeader2(readSection(file, "header2", name), out.version, name);
  out.mapName = h1.map;
  out.author = h1.author;
  out.description = h1.description;

  if (file.u8("preview format") != 0) {
    const int32_t len = file.i32("preview length");
    if (len < 0) file.failHere("preview length is negative (" + std::to_string(len) + ")");
    file.take(size_t(len), "preview image");
  }

  const std::vector<uint8_t> brickBytes = readSection(file, "bricks", name);
  // A record holds at least 42 bits (asset, size flag, three 8-bit packed positions, orientation,
  // flags, material, color flag, 8-bit owner) and starts on a byte boundary: at least 5 bytes.
  if (h1.brickCount > brickBytes.size() / kMinRecordBytes)
    failFile(name, "bricks section",
         "brick count " + std::to_string(h1.brickCount) + " exceeds the data (" + std::to_string(brickBytes.size()) +
             " bytes hold at most " + std::to_string(brickBytes.size() / kMinRecordBytes) + " records)");
  if (h1.brickCount > 0 && h2.assets.empty()) failFile(name, "header2", "no brick assets for " + std::to_string(h1.brickCount) + " bricks");
  const std::vector<Component> components = readComponents(readSection(file, "components", name), h1.brickCount, name);

  std::vector<AssetMapping> mappings;
  mappings.reserve(h2.assets.size());
  for (const std::string& a : h2.assets) mappings.push_back(mapAsset(a));
  std::vector<uint32_t> assetHistogram(h2.assets.size(), 0);
  std::array<uint32_t, 4> shapeHistogram{};

  const AxisRotation sideWedgeFold = foldMinus90AboutX();
  const AxisRotation invertedFold = fold180AboutX();
  const auto& orientations = orientationTable();
  const uint64_t assetMax = std::max<uint64_t>(h2.assets.size(), 2);
  const uint64_t materialMax = std::max<uint64_t>(h2.materials, 2);
  const uint64_t physicalMax = std::max<uint64_t>(h2.physicalMaterials, 2);

  out.totalBricks = h1.brickCount;
  out.records.reserve(std::min(h1.brickCount, kMaxReserve));
  out.bricks.reserve(std::min(h1.brickCount, kMaxReserve));
  out.assetNames = std::move(h2.assets);
  BitReader bits(brickBytes.data(), brickBytes.size(), name, "bricks section");
  for (uint32_t i = 0; i < h1.brickCount; ++i) {
    bits.setBrick(i);
    bits.align();
    BrsBrickRecord rec;
    rec.asset = bits.uintBelow(assetMax);
    if (rec.asset >= out.assetNames.size())
      bits.failHere("asset index " + std::to_string(rec.asset) + " is out of range (" +
                    std::to_string(out.assetNames.size()) + " assets)");
    rec.hasSize = bits.bit();
    if (rec.hasSize)
      for (auto& s : rec.size) {
        const uint64_t v = bits.packed();
        if (v == 0 || v > kMaxBrsHalfSize)
          bits.failHere("size " + std::to_string(v) + " is out of range (1.." + std::to_string(kMaxBrsHalfSize) + ")");
        s = uint32_t(v);
      }
    for (auto& p : rec.position) {
      const int64_t v = bits.signedPacked();
      if (v < -kMaxBrsPosition || v > kMaxBrsPosition)
        bits.failHere("position " + std::to_string(v) + " is out of range");
      p = int32_t(v);
    }
    const uint32_t orientation = bits.uintBelow(24);
    rec.direction = uint8_t((orientation >> 2) % 6);
    rec.rotation = uint8_t(orientation & 3);
    if (out.version >= 10) {
      rec.collision = bits.bit();  // player; weapon, interaction and tool do not stop bodies
      bits.bits(3);
    } else {
      rec.collision = bits.bit();
    }
    bits.bit();  // visibility
    const uint32_t material = bits.uintBelow(materialMax);
    if (out.version >= 9) {
      bits.uintBelow(physicalMax);
      bits.uintBelow(11);  // material intensity
    }
    if (bits.bit())
      bits.bits(out.version >= 9 ? 24 : 32);
    else
      bits.uintBelow(h2.colors);
    const uint64_t owner = bits.packed();
    if (owner > h2.owners)
      bits.failHere("owner " + std::to_string(owner) + " is out of range (" + std::to_string(h2.owners) + " owners)");

    const AssetMapping& m = mappings[rec.asset];
    bool unknown = false;
    if (rec.hasSize) {
      for (int k = 0; k < 3; ++k) rec.halfSizeUsed[k] = rec.size[k];
      unknown = !m.procedural && !m.fixed;
    } else if (m.fixed) {
      for (int k = 0; k < 3; ++k) rec.halfSizeUsed[k] = m.fixedHalf[k];
    } else {
      for (int k = 0; k < 3; ++k) rec.halfSizeUsed[k] = kUnknownHalfSize[k];
      unknown = true;
    }
    const BrickShape shape = unknown ? BrickShape::Box : m.shape;

    ++assetHistogram[rec.asset];
    ++shapeHistogram[size_t(shape)];
    out.unknownAssets += unknown;
    if (!rec.collision) {
      ++out.collisionOff;
      out.records.push_back(rec);
      continue;
    }

    Brick b;
    b.shape = shape;
    b.sides = m.sides;
    b.material = uint8_t(material);
    b.position = Vec3f(float(rec.position[0]), float(rec.position[1]), float(rec.position[2])) * unitsPerBrsUnit;
    Vec3f half(float(rec.halfSizeUsed[0]), float(rec.halfSizeUsed[1]), float(rec.halfSizeUsed[2]));
    AxisRotation rotation = orientations[size_t(rec.direction * 4 + rec.rotation)];
    if (!unknown && m.fold == Fold::SideWedge) {
      half = Vec3f(half.x(), half.z(), half.y());
      rotation = rotation * sideWedgeFold;
    } else if (!unknown && m.fold == Fold::Inverted) {
      rotation = rotation * invertedFold;
    }
    b.halfSize = half * unitsPerBrsUnit;
    b.rotation = rotation;
    try {
      validateBrick(b, "brick");
    } catch (const InvalidInput& e) {
      bits.failHere(std::string("converted brick is not valid (") + e.what() + ")");
    }
    rec.brick = int32_t(out.bricks.size());
    out.bricks.push_back(b);
    out.bounds.merge(brickBounds(b));
    out.records.push_back(rec);
  }

  for (size_t a = 0; a < assetHistogram.size(); ++a)
    if (assetHistogram[a] > 0) out.assetCounts[out.assetNames[a]] += assetHistogram[a];
  for (size_t s = 0; s < shapeHistogram.size(); ++s)
    if (shapeHistogram[s] > 0) out.shapeCounts[brickShapeName(BrickShape(s))] = shapeHistogram[s];
  for (const Component& c : components) {
    out.componentCounts[c.name] += uint32_t(c.bricks.size());
    addLights(c, unitsPerBrsUnit, name, out);
  }
  return out;
}

BrsLoadResult loadBrs(const std::string& path, float unitsPerBrsUnit) {
  requireRegularFile(path, "a Brickadia .brs save");
  std::ifstream in(path, std::ios::binary);
  if (!in) failFile(path, "file", "cannot be opened");
  in.seekg(0, std::ios::end);
  const std::streamoff end = in.tellg();
  if (end < 0) failFile(path, "file", "cannot be read");
  if (end > std::streamoff(4) * kMaxSectionBytes) failFile(path, "file", "is larger than 4 GiB");
  std::vector<uint8_t> bytes(static_cast<size_t>(end));
  in.seekg(0, std::ios::beg);
  if (!bytes.empty() && !in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(bytes.size())))
    failFile(path, "file", "cannot be read");
  return parseBrs(bytes.data(), bytes.size(), path, unitsPerBrsUnit);
}

}  // namespace bw
