#include "collision/content/brs_reader.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>
#include <limits>
#include <string_view>
#include <utility>
#include <zlib.h>

#include "collision/bricks/brick_geometry.h"
#include "collision/content/byte_reader.h"
#include "collision/core/argument_checks.h"

namespace bw {
namespace {

constexpr int kMinVersion = 8;
constexpr int kMaxVersion = 10;
// Sections are small in practice (Lighthouse_Island's largest is 2 MB); a larger claim is a
// corrupt header, and refusing it keeps a bad file from allocating gigabytes.
constexpr int64_t kMaxSectionBytes = int64_t(1) << 30;
// Half sizes beyond this (100,000 studs) are corrupt records, not builds.
constexpr uint64_t kMaxBrsHalfSize = 1'000'000;
// Positions beyond this are corrupt too; it also keeps position * scale well inside float range.
constexpr int64_t kMaxBrsPosition = int64_t(1) << 30;
constexpr size_t kMinRecordBytes = 5;
// Reservations are capped so that a corrupt count cannot allocate ahead of the data that backs it.
constexpr uint32_t kMaxReserve = 1u << 20;

// A section's reader with the .brs string encoding.
class BrsReader : public ByteReader {
 public:
  using ByteReader::ByteReader;
  // Latin-1 (positive length, NUL-terminated) or UTF-16 (negative length, low bytes kept).
  std::string string(const char* what) {
    const int32_t n = i32(what);
    std::string s;
    if (n >= 0) {
      const uint8_t* p = take(size_t(n), what);
      s.assign(reinterpret_cast<const char*>(p), size_t(n));
    } else {
      if (n == std::numeric_limits<int32_t>::min()) failHere(std::string(what) + " has an invalid length");
      const size_t units = size_t(-int64_t(n));
      if (units > remaining() / 2) failHere(std::string("truncated: ") + what + " needs " + std::to_string(units * 2) + " bytes");
      const uint8_t* p = take(units * 2, what);
      s.resize(units);
      for (size_t i = 0; i < units; ++i) s[i] = char(p[2 * i]);
    }
    while (!s.empty() && s.back() == '\0') s.pop_back();
    return s;
  }
};

// Reads one section header and returns its uncompressed bytes.
std::vector<uint8_t> readSection(ByteReader& file, const char* name, const std::string& fileName) {
  const std::string where = std::string(name) + " section";
  const int32_t uncompressed = file.i32(where.c_str());
  const int32_t compressed = file.i32(where.c_str());
  if (uncompressed < 0 || compressed < 0 || uncompressed > kMaxSectionBytes)
    failFile(fileName, where,
         "sizes out of range (uncompressed " + std::to_string(uncompressed) + ", compressed " +
             std::to_string(compressed) + ")");
  if (compressed > 0 && compressed >= uncompressed)
    failFile(fileName, where,
         "compressed size " + std::to_string(compressed) + " is not below the uncompressed size " +
             std::to_string(uncompressed));
  const size_t stored = compressed > 0 ? size_t(compressed) : size_t(uncompressed);
  if (stored > file.remaining())
    failFile(fileName, where,
         "truncated: needs " + std::to_string(stored) + " bytes at offset " + std::to_string(file.position()) +
             ", only " + std::to_string(file.remaining()) + " left");
  const uint8_t* p = file.take(stored, where.c_str());
  std::vector<uint8_t> out(static_cast<size_t>(uncompressed), uint8_t(0));
  if (compressed == 0) {
    if (!out.empty()) std::memcpy(out.data(), p, out.size());
    return out;
  }
  uLongf produced = uLongf(out.size());
  const int rc = uncompress(out.data(), &produced, p, uLong(compressed));
  if (rc != Z_OK || produced != out.size())
    failFile(fileName, where,
         std::string("zlib data is corrupt (") + (rc == Z_OK ? "size mismatch" : zError(rc)) + ", expected " +
             std::to_string(uncompressed) + " bytes)");
  return out;
}

// The brick bit stream: least significant bit of each byte first, every read bounds-checked.
class BitReader {
 public:
  BitReader(const std::vector<uint8_t>& bytes, const std::string& file) : bytes_(bytes), file_(file) {
    bitCount_ = uint64_t(bytes.size()) * 8;
  }
  void setBrick(uint32_t i) { brick_ = i; }
  bool bit() {
    if (pos_ >= bitCount_) truncated();
    const bool b = (bytes_[size_t(pos_ >> 3)] >> (pos_ & 7)) & 1;
    ++pos_;
    return b;
  }
  uint64_t bits(int n) {
    if (pos_ + uint64_t(n) > bitCount_) truncated();
    uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= uint64_t(bit()) << i;
    return v;
  }
  void align() { pos_ = (pos_ + 7) & ~uint64_t(7); }
  // Unreal's SerializeInt: only as many bits as values below max need.
  uint32_t uintBelow(uint64_t max) {
    uint64_t value = 0;
    for (uint64_t mask = 1; value + mask < max; mask <<= 1)
      if (bit()) value |= mask;
    return uint32_t(value);
  }
  // Unreal's SerializeIntPacked: 7 bits per group, the group's first bit says "more follows".
  uint64_t packed() {
    uint64_t value = 0;
    for (int group = 0; group < 5; ++group) {
      const bool more = bit();
      value |= bits(7) << (7 * group);
      if (!more) break;
    }
    return value;
  }
  int64_t signedPacked() {
    const uint64_t v = packed();
    const int64_t magnitude = int64_t(v >> 1);
    return (v & 1) ? magnitude : -magnitude;
  }
  [[noreturn]] void failHere(const std::string& problem) const {
    failFile(file_, "bricks section", "brick " + std::to_string(brick_) + ": " + problem);
  }

 private:
  [[noreturn]] void truncated() const {
    failHere("truncated record (bit " + std::to_string(pos_) + " of " + std::to_string(bitCount_) + ")");
  }
  const std::vector<uint8_t>& bytes_;
  const std::string& file_;
  uint64_t pos_ = 0, bitCount_ = 0;
  uint32_t brick_ = 0;
};

// ---- orientation ----

using IMat = std::array<std::array<int, 3>, 3>;

IMat mul(const IMat& a, const IMat& b) {
  IMat r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) r[i][j] += a[i][k] * b[k][j];
  return r;
}

// D(d): takes local +Z to direction d (rows are output components); see the header.
IMat brsDirectionMatrix(int d) {
  switch (d) {
    case 0: return IMat{{{0, 0, 1}, {0, -1, 0}, {1, 0, 0}}};
    case 1: return IMat{{{0, 0, -1}, {0, 1, 0}, {1, 0, 0}}};
    case 2: return IMat{{{0, 1, 0}, {0, 0, 1}, {1, 0, 0}}};
    case 3: return IMat{{{0, -1, 0}, {0, 0, -1}, {1, 0, 0}}};
    case 4: return IMat{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
    default: return IMat{{{-1, 0, 0}, {0, 1, 0}, {0, 0, -1}}};
  }
}

AxisRotation rotationWithMatrix(const IMat& m) {
  for (int i = 0; i < AxisRotation::kCount; ++i) {
    const AxisRotation r = AxisRotation::fromIndex(i);
    bool same = true;
    for (int row = 0; row < 3 && same; ++row)
      for (int col = 0; col < 3 && same; ++col)
        same = (r.sourceAxis(row) == col ? r.sign(row) : 0) == m[row][col];
    if (same) return r;
  }
  throw InvalidInput("brsOrientation: matrix is not one of the 24 axis rotations");
}

const std::array<AxisRotation, 24>& orientationTable() {
  static const std::array<AxisRotation, 24> table = [] {
    const IMat rz{{{0, -1, 0}, {1, 0, 0}, {0, 0, 1}}};
    std::array<AxisRotation, 24> t{};
    for (int d = 0; d < 6; ++d) {
      IMat m = brsDirectionMatrix(d);
      for (int r = 0; r < 4; ++r) {
        t[size_t(d * 4 + r)] = rotationWithMatrix(m);
        m = mul(m, rz);
      }
    }
    return t;
  }();
  return table;
}

// Folds from our canonical shapes to Brickadia's (see the header's shape table).
AxisRotation foldMinus90AboutX() { return rotationWithMatrix(IMat{{{1, 0, 0}, {0, 0, 1}, {0, -1, 0}}}); }
AxisRotation fold180AboutX() { return rotationWithMatrix(IMat{{{1, 0, 0}, {0, -1, 0}, {0, 0, -1}}}); }

// ---- shapes ----

enum class Fold : uint8_t { None, SideWedge, Inverted };

struct ProceduralAsset {
  std::string_view name;
  BrickShape shape;
  Fold fold;
};

constexpr ProceduralAsset kProcedural[] = {
    {"PB_DefaultBrick", BrickShape::Box, Fold::None},
    {"PB_DefaultTile", BrickShape::Box, Fold::None},
    {"PB_DefaultMicroBrick", BrickShape::Box, Fold::None},
    {"PB_DefaultStudded", BrickShape::Box, Fold::None},
    {"PB_DefaultRampInnerCorner", BrickShape::Box, Fold::None},
    {"PB_DefaultWedge", BrickShape::Wedge, Fold::None},
    {"PB_DefaultRamp", BrickShape::Wedge, Fold::None},
    {"PB_DefaultRampInverted", BrickShape::Wedge, Fold::Inverted},
    {"PB_DefaultSideWedge", BrickShape::Wedge, Fold::SideWedge},
    {"PB_DefaultSideWedgeTile", BrickShape::Wedge, Fold::SideWedge},
    {"PB_DefaultMicroWedge", BrickShape::Wedge, Fold::SideWedge},
    {"PB_DefaultRampCorner", BrickShape::CornerWedge, Fold::None},
    {"PB_DefaultMicroWedgeCorner", BrickShape::CornerWedge, Fold::None},
};

// Half sizes in Brickadia units (10 per stud, 4 per plate) of the fixed-shape assets.
constexpr BrsFixedAsset kFixed[] = {
    // Round and octagonal parts: prisms along local z.
    {"B_1x1_Round", {5, 5, 6}, BrickShape::Cylinder, 16},
    {"B_1x1F_Round", {5, 5, 2}, BrickShape::Cylinder, 16},
    {"B_2x2_Round", {10, 10, 6}, BrickShape::Cylinder, 16},
    {"B_2x2F_Round", {10, 10, 2}, BrickShape::Cylinder, 16},
    {"B_4x4_Round", {20, 20, 6}, BrickShape::Cylinder, 16},
    {"B_1x1_Cone", {5, 5, 6}, BrickShape::Cylinder, 16},
    {"B_2x2_Cone", {10, 10, 12}, BrickShape::Cylinder, 16},
    {"B_Chalice", {5, 5, 10}, BrickShape::Cylinder, 16},
    {"B_1x1F_Octo", {5, 5, 2}, BrickShape::Cylinder, 8},
    {"B_2x2F_Octo", {10, 10, 2}, BrickShape::Cylinder, 8},
    {"B_1x_Octo", {5, 5, 5}, BrickShape::Cylinder, 8},
    {"B_2x_Octo", {10, 10, 10}, BrickShape::Cylinder, 8},
    // Everything else collides as its bounding box.
    {"B_2x2F_Octo_Converter", {10, 10, 2}, BrickShape::Box, 0},
    {"B_2x2F_Octo_Converter_Inv", {10, 10, 2}, BrickShape::Box, 0},
    {"B_1x2f_Plate_Center", {10, 5, 2}, BrickShape::Box, 0},
    {"B_1x2f_Plate_Center_Inv", {10, 5, 2}, BrickShape::Box, 0},
    {"B_2x2f_Plate_Center", {10, 10, 2}, BrickShape::Box, 0},
    {"B_2x2f_Plate_Center_Inv", {10, 10, 2}, BrickShape::Box, 0},
    {"B_1x1_Brick_Side", {5, 5, 6}, BrickShape::Box, 0},
    {"B_1x1_Brick_Side_Lip", {5, 5, 6}, BrickShape::Box, 0},
    {"B_1x4_Brick_Side", {20, 5, 6}, BrickShape::Box, 0},
    {"B_Swirl_Plate", {5, 5, 4}, BrickShape::Box, 0},
    {"B_Handle", {5, 10, 6}, BrickShape::Box, 0},
    {"B_Fern", {10, 10, 2}, BrickShape::Box, 0},
    {"B_Flower", {10, 10, 2}, BrickShape::Box, 0},
    {"B_Small_Flower", {5, 5, 2}, BrickShape::Box, 0},
    {"B_Flame", {5, 5, 10}, BrickShape::Box, 0},
    {"B_Bone", {10, 10, 2}, BrickShape::Box, 0},
    {"B_BoneStraight", {10, 5, 2}, BrickShape::Box, 0},
    {"B_Sausage", {10, 5, 2}, BrickShape::Box, 0},
    {"B_Branch", {20, 11, 2}, BrickShape::Box, 0},
    {"B_Turkey_Body", {15, 10, 7}, BrickShape::Box, 0},
    {"B_Turkey_Leg", {10, 5, 3}, BrickShape::Box, 0},
    {"B_Bush", {15, 15, 16}, BrickShape::Box, 0},
    {"B_Leaf_Bush", {26, 26, 20}, BrickShape::Box, 0},
    {"B_Pine_Tree", {20, 20, 38}, BrickShape::Box, 0},
    {"B_Picket_Fence", {20, 5, 12}, BrickShape::Box, 0},
    {"B_Ladder", {12, 15, 12}, BrickShape::Box, 0},
    {"B_8x8_Lattice_Plate", {40, 40, 2}, BrickShape::Box, 0},
    {"B_SpawnPoint", {20, 20, 2}, BrickShape::Box, 0},
    {"B_CheckPoint", {20, 20, 2}, BrickShape::Box, 0},
    {"B_GoalPoint", {20, 20, 2}, BrickShape::Box, 0},
};

// A 1x1 brick: the stand-in for fixed-shape assets we have no entry for.
constexpr uint32_t kUnknownHalfSize[3] = {5, 5, 6};

// How one asset of the file's table turns into our bricks (resolved once per asset, not per brick).
struct AssetMapping {
  BrickShape shape = BrickShape::Box;
  Fold fold = Fold::None;
  uint8_t sides = 12;
  bool procedural = false;  // a known PB_ asset
  bool fixed = false;       // a known B_ asset
  uint32_t fixedHalf[3] = {0, 0, 0};
};

AssetMapping mapAsset(const std::string& name) {
  AssetMapping m;
  for (const auto& p : kProcedural)
    if (p.name == name) {
      m.shape = p.shape;
      m.fold = p.fold;
      m.procedural = true;
      return m;
    }
  for (const auto& f : kFixed)
    if (name == f.name) {
      m.shape = f.shape;
      m.sides = f.shape == BrickShape::Cylinder ? f.sides : 12;
      m.fixed = true;
      for (int i = 0; i < 3; ++i) m.fixedHalf[i] = f.halfSize[i];
      return m;
    }
  return m;
}

struct Header1 {
  std::string map, author, description;
  uint32_t brickCount = 0;
};

Header1 readHeader1(const std::vector<uint8_t>& bytes, const std::string& file) {
  BrsReader r(bytes.data(), bytes.size(), file, "header1");
  Header1 h;
  h.map = r.string("map name");
  h.author = r.string("author name");
  h.description = r.string("description");
  r.take(16, "author id");
  r.string("host name");
  r.take(16, "host id");
  r.take(8, "save time");
  const int32_t n = r.i32("brick count");
  if (n < 0) r.failHere("brick count is negative (" + std::to_string(n) + ")");
  h.brickCount = uint32_t(n);
  return h;
}

struct Header2 {
  std::vector<std::string> assets;
  uint32_t colors = 0, materials = 0, owners = 0, physicalMaterials = 0;
};

Header2 readHeader2(const std::vector<uint8_t>& bytes, int version, const std::string& file) {
  BrsReader r(bytes.data(), bytes.size(), file, "header2");
  Header2 h;
  const uint32_t mods = r.count("mods count", 4);
  for (uint32_t i = 0; i < mods; ++i) r.string("mod name");
  const uint32_t assets = r.count("brick assets count", 4);
  h.assets.reserve(assets);
  for (uint32_t i = 0; i < assets; ++i) h.assets.push_back(r.string("brick asset name"));
  h.colors = r.count("colors count", 4);
  r.take(size_t(h.colors) * 4, "colors");
  h.materials = r.count("materials count", 4);
  for (uint32_t i = 0; i < h.materials; ++i) r.string("material name");
  h.owners = r.count("brick owners count", 24);
  for (uint32_t i = 0; i < h.owners; ++i) {
    r.take(16, "owner id");
    r.string("owner name");
    r.i32("owner brick count");
  }
  if (version >= 9) {
    h.physicalMaterials = r.count("physical materials count", 4);
    for (uint32_t i = 0; i < h.physicalMaterials; ++i) r.string("physical material name");
  }
  return h;
}

// Checks the components section's framing (count, names, lengths) without interpreting it.
void checkComponents(const std::vector<uint8_t>& bytes, const std::string& file) {
  BrsReader r(bytes.data(), bytes.size(), file, "components");
  const uint32_t n = r.count("components count", 8);
  for (uint32_t i = 0; i < n; ++i) {
    r.string("component name");
    const int32_t len = r.i32("component length");
    if (len < 0) r.failHere("component length is negative (" + std::to_string(len) + ")");
    r.take(size_t(len), "component data");
  }
}

}  // namespace

std::span<const BrsFixedAsset> brsFixedAssets() { return kFixed; }

AxisRotation brsOrientation(int direction, int rotation) {
  if (direction < 0 || direction >= 6 || rotation < 0 || rotation >= 4)
    throw InvalidInput("brsOrientation: direction " + std::to_string(direction) + ", rotation " +
                       std::to_string(rotation) + " (expected 0..5, 0..3)");
  return orientationTable()[size_t(direction * 4 + rotation)];
}

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
  checkComponents(readSection(file, "components", name), name);

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
  BitReader bits(brickBytes, name);
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
  return out;
}

BrsLoadResult loadBrs(const std::string& path, float unitsPerBrsUnit) {
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
