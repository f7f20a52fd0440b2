#include "collision/content/vox_reader.h"

#include <algorithm>
#include <charconv>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <utility>

#include "collision/content/byte_reader.h"
#include "collision/core/argument_checks.h"

namespace bw {
namespace {

constexpr int kChunkHeaderBytes = 12;
// A .vox file holds at most a few hundred models of 256^3 voxels; anything above 2 GiB is not one.
constexpr std::streamoff kMaxFileBytes = std::streamoff(1) << 31;

std::string int3Text(const Int3& v) {
  // note: appended piece by piece; "(" + std::to_string(...) trips GCC 12's false -Wrestrict.
  std::string s = "(";
  s += std::to_string(v.x);
  s += ", ";
  s += std::to_string(v.y);
  s += ", ";
  s += std::to_string(v.z);
  s += ")";
  return s;
}

// Bytes of one chunk's content, with the .vox string and DICT encodings.
class ChunkReader : public ByteReader {
 public:
  ChunkReader(const uint8_t* data, size_t size, const std::string& file, std::string where)
      : ByteReader(data, size, file, std::move(where), "the chunk") {}
  std::string string(const char* what) {
    const uint32_t n = count(what, 1);
    const uint8_t* p = take(n, what);
    return std::string(reinterpret_cast<const char*>(p), n);
  }
  std::map<std::string, std::string> dict(const char* what) {
    const uint32_t n = count(what, 8);
    std::map<std::string, std::string> out;
    for (uint32_t i = 0; i < n; ++i) {
      std::string key = string("DICT key");
      out[std::move(key)] = string("DICT value");
    }
    return out;
  }
};

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

enum class NodeKind : uint8_t { Transform, Group, Shape };

struct SceneNode {
  NodeKind kind = NodeKind::Transform;
  std::vector<int32_t> children;  // nTRN: one child; nGRP: any; nSHP: none
  Int3 translation;               // nTRN frame 0
  bool rotated = false;           // nTRN frame 0 has a non-identity _r
  int32_t model = -1;             // nSHP: first model
};

const char* kindName(NodeKind k) {
  switch (k) {
    case NodeKind::Transform: return "nTRN";
    case NodeKind::Group: return "nGRP";
    case NodeKind::Shape: return "nSHP";
  }
  return "?";
}

// "_t": three integers separated by spaces.
Int3 parseTranslation(const std::string& text, ByteReader& r) {
  int32_t v[3] = {0, 0, 0};
  const char* p = text.data();
  const char* end = p + text.size();
  for (int axis = 0; axis < 3; ++axis) {
    while (p < end && *p == ' ') ++p;
    const auto [next, ec] = std::from_chars(p, end, v[axis]);
    if (ec != std::errc() || next == p) r.failHere("_t \"" + text + "\" is not three integers");
    p = next;
  }
  while (p < end && *p == ' ') ++p;
  if (p != end) r.failHere("_t \"" + text + "\" is not three integers");
  for (int32_t c : v)
    if (c < -kVoxMaxTranslation || c > kVoxMaxTranslation)
      r.failHere("_t \"" + text + "\" is beyond +-" + std::to_string(kVoxMaxTranslation));
  return Int3{v[0], v[1], v[2]};
}

// "_r": a rotation byte. Bits 0-1: column of row 0's non-zero entry; bits 2-3: row 1's; bits 4-6:
// signs of rows 0..2 (set = -1). Row 2 takes the remaining column. Identity is 0b0000100 = 4.
bool parseRotationIsIdentity(const std::string& text, ByteReader& r) {
  int value = 0;
  const auto [next, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || next != text.data() + text.size() || value < 0 || value > 127)
    r.failHere("_r \"" + text + "\" is not a rotation byte (0..127)");
  const int row0 = value & 3, row1 = (value >> 2) & 3;
  if (row0 == 3 || row1 == 3 || row0 == row1) r.failHere("_r " + text + " is not a rotation (rows share a column)");
  return value == 4;
}

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

// Walks the scene graph from node 0, appending one instance per root -> nSHP path.
class SceneWalker {
 public:
  SceneWalker(const std::map<int32_t, SceneNode>& nodes, const std::vector<VoxModel>& models,
              const std::string& file)
      : nodes_(nodes), models_(models), file_(file) {}

  void walk(std::vector<VoxInstance>& out, uint32_t& transformsApplied, uint32_t& ignoredRotations) {
    if (!nodes_.count(0)) failFile(file_, "scene graph", "has no root node 0");
    visit(0, Int3{}, false, 0, out, transformsApplied);
    ignoredRotations = uint32_t(rotatedNodes_.size());
  }

 private:
  void visit(int32_t id, Int3 t, bool rotated, int depth, std::vector<VoxInstance>& out, uint32_t& transforms) {
    const auto it = nodes_.find(id);
    if (it == nodes_.end())
      failFile(file_, "scene graph", "node " + std::to_string(id) + " is referenced but missing");
    if (depth >= kVoxMaxSceneDepth)
      failFile(file_, "scene graph", "path to node " + std::to_string(id) + " is deeper than " +
                                     std::to_string(kVoxMaxSceneDepth) + " nodes");
    if (std::find(path_.begin(), path_.end(), id) != path_.end())
      failFile(file_, "scene graph", "cycle through node " + std::to_string(id));
    const SceneNode& n = it->second;
    if (n.kind == NodeKind::Transform) {
      ++transforms;
      t = {t.x + n.translation.x, t.y + n.translation.y, t.z + n.translation.z};
      for (int32_t c : {t.x, t.y, t.z})
        if (c < -kVoxMaxTranslation || c > kVoxMaxTranslation)
          failFile(file_, "scene graph", "translation " + int3Text(t) + " at node " + std::to_string(id) +
                                         " is beyond +-" + std::to_string(kVoxMaxTranslation));
      if (n.rotated) {
        rotated = true;
        rotatedNodes_.insert(id);
      }
    }
    if (n.kind == NodeKind::Shape) {
      if (n.model < 0 || size_t(n.model) >= models_.size())
        failFile(file_, "scene graph", "nSHP node " + std::to_string(id) + " names model " + std::to_string(n.model) +
                                       " of " + std::to_string(models_.size()));
      if (out.size() >= kVoxMaxInstances)
        failFile(file_, "scene graph", "expands to more than " + std::to_string(kVoxMaxInstances) + " instances");
      const Int3& s = models_[size_t(n.model)].size;
      VoxInstance inst;
      inst.model = uint32_t(n.model);
      inst.translation = t;
      inst.offset = {t.x - s.x / 2, t.y - s.y / 2, t.z - s.z / 2};
      inst.rotationIgnored = rotated;
      out.push_back(inst);
      return;
    }
    path_.push_back(id);
    for (int32_t c : n.children) visit(c, t, rotated, depth + 1, out, transforms);
    path_.pop_back();
  }

  const std::map<int32_t, SceneNode>& nodes_;
  const std::vector<VoxModel>& models_;
  const std::string& file_;
  std::vector<int32_t> path_;
  std::set<int32_t> rotatedNodes_;
};

std::string chunkName(const uint8_t* id) {
  std::string s;
  for (int i = 0; i < 4; ++i) s += (id[i] >= 32 && id[i] < 127) ? char(id[i]) : '?';
  return s;
}

}  // namespace

uint64_t VoxModelSet::countInRange(int first, int last) const {
  uint64_t n = 0;
  for (int i = std::max(first, 0); i <= std::min(last, 255); ++i) n += paletteCounts[size_t(i)];
  return n;
}

const std::array<VoxRgba, 256>& voxDefaultPalette() {
  static const std::array<VoxRgba, 256> palette = makeDefaultPalette();
  return palette;
}

VoxModelSet parseVox(const uint8_t* data, size_t size, const std::string& file) {
  if (data == nullptr && size != 0) failFile(file, "file", "no data");
  ChunkReader header(data, size, file, "header");
  const uint8_t* magic = header.take(4, "magic \"VOX \"");
  if (magic[0] != 'V' || magic[1] != 'O' || magic[2] != 'X' || magic[3] != ' ')
    header.failHere("not a MagicaVoxel file (magic is \"" + chunkName(magic) + "\", expected \"VOX \")");
  const int32_t version = header.i32("version");
  if (version != 150 && version != 200)
    header.failHere("unsupported version " + std::to_string(version) + " (150 and 200 are supported)");

  // MAIN chunk header.
  const size_t mainAt = 8;
  ChunkReader mainHeader(data + mainAt, size - mainAt, file, "MAIN chunk");
  const uint8_t* mainId = mainHeader.take(4, "chunk id");
  if (chunkName(mainId) != "MAIN")
    mainHeader.failHere("first chunk is \"" + chunkName(mainId) + "\", expected \"MAIN\"");
  const int32_t mainContent = mainHeader.i32("content size");
  const int32_t mainChildren = mainHeader.i32("children size");
  if (mainContent < 0 || mainChildren < 0)
    mainHeader.failHere("negative sizes (content " + std::to_string(mainContent) + ", children " +
                        std::to_string(mainChildren) + ")");
  mainHeader.take(size_t(mainContent), "content");
  const uint8_t* children = mainHeader.take(size_t(mainChildren), "children");

  VoxModelSet set;
  set.version = version;
  set.palette = voxDefaultPalette();
  int32_t packModels = -1;
  bool pendingSize = false;
  Int3 pendingSizeValue;
  std::map<int32_t, SceneNode> nodes;

  size_t pos = 0;
  uint32_t chunkIndex = 0;
  while (pos < size_t(mainChildren)) {
    const std::string where = "chunk " + std::to_string(chunkIndex);
    ChunkReader head(children + pos, size_t(mainChildren) - pos, file, where);
    const uint8_t* idBytes = head.take(4, "chunk id");
    const std::string id = chunkName(idBytes);
    const std::string chunkWhere = id + " chunk " + std::to_string(chunkIndex);
    ChunkReader hdr(children + pos + 4, size_t(mainChildren) - pos - 4, file, chunkWhere);
    const int32_t n = hdr.i32("content size");
    const int32_t m = hdr.i32("children size");
    if (n < 0 || m < 0)
      hdr.failHere("negative sizes (content " + std::to_string(n) + ", children " + std::to_string(m) + ")");
    if (uint64_t(n) + uint64_t(m) > hdr.remaining())
      hdr.failHere("content " + std::to_string(n) + " + children " + std::to_string(m) + " bytes exceed MAIN (" +
                   std::to_string(hdr.remaining()) + " bytes left)");
    ChunkReader r(children + pos + kChunkHeaderBytes, size_t(n), file, chunkWhere);
    pos += kChunkHeaderBytes + size_t(n) + size_t(m);
    ++chunkIndex;

    if (pendingSize && id != "XYZI") r.failHere("a SIZE chunk is not followed by its XYZI chunk");
    if (id == "PACK") {
      if (packModels >= 0) r.failHere("second PACK chunk");
      packModels = r.i32("numModels");
      if (packModels < 1) r.failHere("numModels " + std::to_string(packModels) + " is not positive");
    } else if (id == "SIZE") {
      Int3 s;
      s.x = r.i32("size x");
      s.y = r.i32("size y");
      s.z = r.i32("size z");
      for (int32_t c : {s.x, s.y, s.z})
        if (c < 1 || c > kVoxMaxModelSize)
          r.failHere("model " + std::to_string(set.models.size()) + " size " + int3Text(s) + " is outside [1, " +
                     std::to_string(kVoxMaxModelSize) + "] per axis");
      pendingSize = true;
      pendingSizeValue = s;
    } else if (id == "XYZI") {
      if (!pendingSize) r.failHere("XYZI chunk without a SIZE chunk before it");
      pendingSize = false;
      const uint32_t count = r.count("numVoxels", 4);
      const uint8_t* p = r.take(size_t(count) * 4, "voxels");
      VoxModel model;
      model.size = pendingSizeValue;
      model.voxels.resize(count);
      for (uint32_t i = 0; i < count; ++i) {
        const VoxVoxel v{p[4 * i], p[4 * i + 1], p[4 * i + 2], p[4 * i + 3]};
        if (v.x >= model.size.x || v.y >= model.size.y || v.z >= model.size.z)
          r.failHere("model " + std::to_string(set.models.size()) + " voxel " + std::to_string(i) + " at " +
                     int3Text({v.x, v.y, v.z}) + " is outside SIZE " + int3Text(model.size));
        if (v.colorIndex == 0)
          r.failHere("model " + std::to_string(set.models.size()) + " voxel " + std::to_string(i) +
                     " has colour index 0 (empty)");
        model.voxels[i] = v;
      }
      set.fileVoxels += count;
      set.models.push_back(std::move(model));
    } else if (id == "RGBA") {
      if (!set.defaultPalette) r.failHere("second RGBA chunk");
      const uint8_t* p = r.take(256 * 4, "palette");
      set.palette[0] = VoxRgba{};
      for (int i = 0; i < 255; ++i)
        set.palette[size_t(i + 1)] = VoxRgba{p[4 * i], p[4 * i + 1], p[4 * i + 2], p[4 * i + 3]};
      set.defaultPalette = false;
    } else if (id == "nTRN" || id == "nGRP" || id == "nSHP") {
      SceneNode node;
      const int32_t nodeId = r.i32("node id");
      if (nodeId < 0) r.failHere("node id " + std::to_string(nodeId) + " is negative");
      r.dict("node attributes");
      if (id == "nTRN") {
        node.kind = NodeKind::Transform;
        node.children.push_back(r.i32("child node id"));
        r.i32("reserved id");
        r.i32("layer id");
        const uint32_t frames = r.count("numFrames", 4);
        for (uint32_t f = 0; f < frames; ++f) {
          const std::map<std::string, std::string> attrs = r.dict("frame attributes");
          if (f != 0) continue;
          if (const auto t = attrs.find("_t"); t != attrs.end()) node.translation = parseTranslation(t->second, r);
          if (const auto rot = attrs.find("_r"); rot != attrs.end()) node.rotated = !parseRotationIsIdentity(rot->second, r);
        }
      } else if (id == "nGRP") {
        node.kind = NodeKind::Group;
        const uint32_t count = r.count("numChildren", 4);
        node.children.reserve(count);
        for (uint32_t i = 0; i < count; ++i) node.children.push_back(r.i32("child node id"));
      } else {
        node.kind = NodeKind::Shape;
        const uint32_t count = r.count("numModels", 8);
        if (count == 0) r.failHere("shape node " + std::to_string(nodeId) + " has no model");
        for (uint32_t i = 0; i < count; ++i) {
          const int32_t model = r.i32("model id");
          r.dict("model attributes");
          if (i == 0) node.model = model;
        }
      }
      if (!nodes.emplace(nodeId, std::move(node)).second)
        r.failHere("node id " + std::to_string(nodeId) + " is used by an earlier " +
                   kindName(nodes.at(nodeId).kind) + " chunk");
    } else {
      ++set.skippedChunks;
    }
  }
  if (pendingSize) failFile(file, "MAIN chunk", "the last SIZE chunk has no XYZI chunk");
  if (packModels >= 0 && size_t(packModels) != set.models.size())
    failFile(file, "PACK chunk",
         "numModels " + std::to_string(packModels) + " but the file has " + std::to_string(set.models.size()) +
             " SIZE/XYZI pairs");

  // Placement.
  set.hasSceneGraph = !nodes.empty();
  if (set.hasSceneGraph) {
    SceneWalker(nodes, set.models, file).walk(set.instances, set.transformsApplied, set.ignoredRotations);
  } else {
    for (size_t i = 0; i < set.models.size(); ++i) set.instances.push_back(VoxInstance{uint32_t(i), {}, {}, false});
  }

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
