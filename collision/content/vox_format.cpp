#include "collision/content/vox_format.h"

#include <algorithm>
#include <charconv>
#include <utility>

#include "collision/content/byte_reader.h"
#include "collision/core/argument_checks.h"

namespace bw::vox {
namespace {

constexpr int kChunkHeaderBytes = 12;

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

std::string chunkName(const uint8_t* id) {
  std::string s;
  for (int i = 0; i < 4; ++i) s += (id[i] >= 32 && id[i] < 127) ? char(id[i]) : '?';
  return s;
}

}  // namespace

void SceneWalker::walk(std::vector<VoxInstance>& out, uint32_t& transformsApplied, uint32_t& ignoredRotations) {
  if (!nodes_.count(0)) failFile(file_, "scene graph", "has no root node 0");
  visit(0, Int3{}, false, 0, out, transformsApplied);
  ignoredRotations = uint32_t(rotatedNodes_.size());
}

void SceneWalker::visit(int32_t id, Int3 t, bool rotated, int depth, std::vector<VoxInstance>& out, uint32_t& transforms) {
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

std::map<int32_t, SceneNode> readVoxChunks(const uint8_t* data, size_t size, const std::string& file, VoxModelSet& set) {
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
        node.frames = std::max(frames, 1u);
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
        node.frames = count;
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
  return nodes;
}

}  // namespace bw::vox
