#include "recording/recording_reader.h"

#include <cmath>
#include <zlib.h>

#include "collision/core/errors.h"

namespace bw {
namespace {

// Reads a block's payload field by field; every read is bounds-checked and a failure names
// the block.
class BlockReader {
 public:
  BlockReader(std::span<const uint8_t> payload, std::string where) : p_(payload), where_(std::move(where)) {}
  template <class T>
  T get(const char* what) {
    need(sizeof(T), what);
    T v;
    std::memcpy(&v, p_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return v;
  }
  float finite(const char* what) {
    const float v = get<float>(what);
    if (!std::isfinite(v)) fail(std::string(what) + " is not finite");
    return v;
  }
  Vec3f vec(const char* what) {
    const float x = finite(what), y = finite(what), z = finite(what);
    return {x, y, z};
  }
  Quatf quat(const char* what) {
    const float x = finite(what), y = finite(what), z = finite(what), w = finite(what);
    const Quatf q(w, x, y, z);
    if (std::abs(q.squaredNorm() - 1.f) > 1e-3f) fail(std::string(what) + " is not a unit quaternion");
    return q;
  }
  std::span<const uint8_t> bytes(size_t n, const char* what) {
    need(n, what);
    const auto s = p_.subspan(at_, n);
    at_ += n;
    return s;
  }
  /// Checks that `count` records of `each` bytes fit in what is left.
  void fits(uint64_t count, uint64_t each, const char* what) {
    if (count * each > p_.size() - at_)
      fail(std::string(what) + ": " + std::to_string(count) + " records of " + std::to_string(each) + " bytes do not fit the " +
           std::to_string(p_.size() - at_) + " bytes left");
  }
  void end() {
    if (at_ != p_.size()) fail(std::to_string(p_.size() - at_) + " bytes left over after the block's content");
  }
  [[noreturn]] void fail(const std::string& what) const { throw InvalidInput(where_ + ": " + what); }

 private:
  void need(size_t n, const char* what) {
    if (p_.size() - at_ < n) fail(std::string("ends before ") + what);
  }
  std::span<const uint8_t> p_;
  size_t at_ = 0;
  std::string where_;
};

std::string tagName(uint32_t tag) {
  std::string s(4, '?');
  for (int k = 0; k < 4; ++k) {
    const char c = char((tag >> (8 * k)) & 0xFF);
    s[k] = c >= 32 && c < 127 ? c : '?';
  }
  return s;
}

Brick readBrick(BlockReader& r) {
  Brick b;
  b.position = r.vec("brick position");
  b.halfSize = r.vec("brick half size");
  b.filter = r.get<uint32_t>("brick filter");
  b.material = r.get<uint8_t>("brick material");
  const uint8_t rotation = r.get<uint8_t>("brick rotation");
  const uint8_t shape = r.get<uint8_t>("brick shape");
  b.sides = r.get<uint8_t>("brick sides");
  if (rotation >= 24) r.fail("brick rotation " + std::to_string(rotation) + " (must be 0..23)");
  if (shape > 3) r.fail("brick shape " + std::to_string(shape) + " (must be 0..3)");
  b.rotation = AxisRotation::fromIndex(rotation);
  b.shape = BrickShape(shape);
  try {
    validateBrick(b, "brick");
  } catch (const InvalidInput& e) {
    r.fail(e.what());
  }
  return b;
}

}  // namespace

std::vector<uint8_t> readRecordingBytes(const std::string& path) {
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) throw InvalidInput("recording " + path + ": cannot open it");
  std::vector<uint8_t> out;
  uint8_t buffer[1 << 16];
  int n;
  while ((n = gzread(f, buffer, sizeof buffer)) > 0) out.insert(out.end(), buffer, buffer + n);
  int err = Z_OK;
  const char* message = gzerror(f, &err);
  const std::string why = n < 0 || (err != Z_OK && err != Z_BUF_ERROR) ? message : "";
  gzclose(f);
  // A stream cut short (Z_BUF_ERROR at its end) keeps what was read: a run that died mid-way.
  if (!why.empty()) throw InvalidInput("recording " + path + ": cannot be read (" + why + ")");
  return out;
}

Recording readRecording(const std::string& path) { return parseRecording(readRecordingBytes(path), path); }

Recording parseRecording(std::span<const uint8_t> bytes, const std::string& name) {
  const std::string file = "recording " + name;
  if (bytes.size() < 12 || std::memcmp(bytes.data(), kRecordingMagic, 8) != 0)
    throw InvalidInput(file + ": not a brickworld recording (it does not start with BWRECORD)");
  uint32_t version;
  std::memcpy(&version, bytes.data() + 8, 4);
  if (version != kRecordingVersion)
    throw InvalidInput(file + ": version " + std::to_string(version) + ", this brickworld reads version " + std::to_string(kRecordingVersion));
  Recording rec;
  size_t at = 12;
  uint32_t blockNumber = 0;
  // Blocks before the first EDIT, SPLT or FRAM describe the scene's start; later ones belong to
  // the frame whose FRAM follows them (its counts gathered in `pending`).
  bool started = false;
  RecordedFrame pending;
  while (at < bytes.size()) {
    ++blockNumber;
    if (bytes.size() - at < 8) break;  // a cut-off block header: a run that died mid-way
    uint32_t tag, length;
    std::memcpy(&tag, bytes.data() + at, 4);
    std::memcpy(&length, bytes.data() + at + 4, 4);
    const std::string where = file + ": block " + std::to_string(blockNumber) + " (" + tagName(tag) + " at byte " + std::to_string(at) + ")";
    if (bytes.size() - at - 8 < length) {
      if (rec.complete) throw InvalidInput(where + ": runs past the end of the file");
      break;  // cut off: keep the complete frames
    }
    BlockReader r(bytes.subspan(at + 8, length), where);
    at += 8 + size_t(length);
    if (blockNumber == 1 && tag != kTagHead) r.fail("the first block must be HEAD");
    if (rec.complete) r.fail("blocks after END_");
    const int32_t appears = started ? int32_t(rec.frames.size()) : -1;
    if (tag == kTagHead) {
      if (blockNumber != 1) r.fail("a second HEAD");
      const auto text = r.bytes(length, "the header");
      try {
        rec.head = nlohmann::json::parse(text.begin(), text.end());
        const auto& o = rec.head.at("origin");
        rec.origin = Vec3d(o.at(0).get<double>(), o.at(1).get<double>(), o.at(2).get<double>());
        rec.stages = rec.head.at("stages").get<std::vector<std::string>>();
        rec.contacts = rec.head.at("contacts").get<bool>();
        if (rec.head.at("rotations").size() != 24) r.fail("rotations must list 24 matrices");
      } catch (const nlohmann::json::exception& e) {
        r.fail(std::string("the header is not the JSON FORMAT.md describes: ") + e.what());
      }
    } else if (tag == kTagGrid) {
      RecordedGrid g;
      g.index = r.get<uint32_t>("grid index");
      if (g.index != rec.grids.size()) r.fail("grid " + std::to_string(g.index) + " where grid " + std::to_string(rec.grids.size()) + " comes next");
      const uint32_t nameLength = r.get<uint32_t>("name length");
      const auto nameBytes = r.bytes(nameLength, "the grid's name");
      g.name.assign(nameBytes.begin(), nameBytes.end());
      g.brickCount = r.get<uint32_t>("brick count");
      const uint32_t n = r.get<uint32_t>("recorded brick count");
      if (n != 0 && n != g.brickCount) r.fail("records " + std::to_string(n) + " of " + std::to_string(g.brickCount) + " bricks (all or none)");
      r.fits(n, kRecordedBrickBytes, "bricks");
      g.frame = appears;
      g.brickIds.reserve(n);
      g.bricks.reserve(n);
      for (uint32_t k = 0; k < n; ++k) {
        g.brickIds.push_back(r.get<uint32_t>("brick id"));
        g.bricks.push_back(readBrick(r));
      }
      r.end();
      rec.grids.push_back(std::move(g));
    } else if (tag == kTagNodes) {
      const uint32_t g = r.get<uint32_t>("grid index");
      if (g >= rec.grids.size()) r.fail("boxes of grid " + std::to_string(g) + ", which the recording has not described");
      const uint32_t levels = r.get<uint32_t>("level count");
      if (levels > 16) r.fail(std::to_string(levels) + " levels (at most 16)");
      auto& out = rec.grids[g].nodeLevels;
      out.assign(levels, {});
      for (auto& level : out) {
        const uint32_t n = r.get<uint32_t>("box count");
        r.fits(n, 24, "boxes");
        level.resize(n);
        for (Aabb& b : level) {
          b.min = r.vec("box min");
          b.max = r.vec("box max");
          if (!(b.min.array() <= b.max.array()).all()) r.fail("a box whose min exceeds its max");
        }
      }
      r.end();
    } else if (tag == kTagTerrain) {
      const uint32_t t = r.get<uint32_t>("terrain index");
      if (t > rec.terrainChunks.size()) r.fail("terrain " + std::to_string(t) + " before terrain " + std::to_string(rec.terrainChunks.size()));
      r.finite("voxel size");
      const uint32_t chunks = r.get<uint32_t>("chunk count");
      if (t == rec.terrainTriangles.size()) rec.terrainTriangles.emplace_back();
      for (uint32_t c = 0; c < chunks; ++c) {
        Int3 coord;
        coord.x = r.get<int32_t>("chunk coordinates");
        coord.y = r.get<int32_t>("chunk coordinates");
        coord.z = r.get<int32_t>("chunk coordinates");
        if (coord.x < 0 || coord.y < 0 || coord.z < 0) r.fail("negative chunk coordinates");
        const uint32_t vertices = r.get<uint32_t>("vertex count"), triangles = r.get<uint32_t>("triangle count");
        r.fits(vertices, 12, "vertices");
        for (uint32_t v = 0; v < vertices; ++v) r.vec("vertex");
        r.fits(triangles, 13, "triangles");
        for (uint32_t i = 0; i < 3 * triangles; ++i)
          if (r.get<uint32_t>("vertex index") >= vertices) r.fail("a triangle's vertex index is out of its chunk's range");
        r.bytes(triangles, "materials");
        rec.terrainTriangles[t][chunkKey(coord)] = triangles;
      }
      r.end();
      if (t == rec.terrainChunks.size()) rec.terrainChunks.push_back(chunks);
      if (started) pending.terrainChunks += chunks;  // chunks this frame changed
    } else if (tag == kTagBody) {
      const uint32_t first = r.get<uint32_t>("first body id"), count = r.get<uint32_t>("body count");
      if (first != rec.bodies.size()) r.fail("bodies from " + std::to_string(first) + " where body " + std::to_string(rec.bodies.size()) + " comes next");
      r.fits(count, kRecordedBodyBytes, "bodies");
      for (uint32_t k = 0; k < count; ++k) {
        RecordedBody b;
        const uint8_t motion = r.get<uint8_t>("motion"), kind = r.get<uint8_t>("kind");
        r.get<uint16_t>("padding");
        if (motion > 2) r.fail("body " + std::to_string(first + k) + ": motion " + std::to_string(motion));
        if (kind > 5) r.fail("body " + std::to_string(first + k) + ": kind " + std::to_string(kind));
        b.motion = MotionType(motion);
        b.kind = RecordedKind(kind);
        b.ref = r.get<uint32_t>("grid or terrain index");
        if (b.kind == RecordedKind::Grid && b.ref >= rec.grids.size())
          r.fail("body " + std::to_string(first + k) + " uses grid " + std::to_string(b.ref) + ", which the recording has not described");
        if (b.kind == RecordedKind::Terrain && b.ref >= rec.terrainChunks.size())
          r.fail("body " + std::to_string(first + k) + " uses terrain " + std::to_string(b.ref) + ", which the recording has not described");
        b.size = r.vec("size");
        b.shapePosition = r.vec("shape position");
        b.shapeRotation = r.quat("shape rotation");
        b.position = r.vec("position");
        b.rotation = r.quat("rotation");
        b.frame = appears;
        rec.bodies.push_back(b);
      }
      r.end();
    } else if (tag == kTagEdit || tag == kTagSplit) {
      started = true;
      const uint32_t n = r.get<uint32_t>("count");
      if (tag == kTagEdit) {
        r.fits(n, kRecordedEditBytes, "brick edits");
        for (uint32_t k = 0; k < n; ++k) {
          RecordedEdit e;
          e.grid = r.get<uint32_t>("grid");
          if (e.grid >= rec.grids.size()) r.fail("an edit of a grid the recording has not described");
          e.brick = r.get<uint32_t>("brick id");
          const uint8_t placed = r.get<uint8_t>("placed");
          if (placed > 1) r.fail("placed must be 0 or 1");
          e.placed = placed == 1;
          e.value = readBrick(r);
          pending.edits.push_back(e);
        }
        pending.bricksEdited += n;
      } else {
        r.fits(n, 12, "splits");
        for (uint32_t k = 0; k < n; ++k) {
          if (r.get<uint32_t>("grid the part left") >= rec.grids.size()) r.fail("a split from a grid the recording has not described");
          r.get<uint32_t>("the part's grid");
          r.get<uint32_t>("the part's body");
        }
        pending.splits += n;
      }
      r.end();
    } else if (tag == kTagFrame) {
      started = true;
      RecordedFrame f = std::move(pending);
      pending = RecordedFrame{};
      f.index = r.get<uint32_t>("frame index");
      if (f.index != rec.frames.size()) r.fail("frame " + std::to_string(f.index) + " where frame " + std::to_string(rec.frames.size()) + " comes next");
      f.stageMs.resize(rec.stages.size());
      for (float& ms : f.stageMs) ms = r.finite("a stage time");
      f.bodyCount = r.get<uint32_t>("body count");
      if (f.bodyCount != rec.bodies.size())
        r.fail(std::to_string(f.bodyCount) + " bodies, but BODY blocks described " + std::to_string(rec.bodies.size()));
      const uint32_t m = r.get<uint32_t>("moving body count");
      r.fits(m, kRecordedPoseBytes, "poses");
      uint32_t last = 0;
      for (uint32_t k = 0; k < m; ++k) {
        const uint32_t id = r.get<uint32_t>("body id");
        if (id >= f.bodyCount || (k && id <= last)) r.fail("body id " + std::to_string(id) + " out of order or range");
        last = id;
        f.ids.push_back(id);
        f.positions.push_back(r.vec("position"));
        f.rotations.push_back(r.quat("rotation"));
        const uint8_t state = r.get<uint8_t>("state");
        if (state > 3) r.fail("body " + std::to_string(id) + ": state " + std::to_string(state));
        f.states.push_back(RecordedState(state));
      }
      r.end();
      rec.frames.push_back(std::move(f));
    } else if (tag == kTagContacts) {
      if (rec.frames.empty()) r.fail("contacts before the first frame");
      const uint32_t n = r.get<uint32_t>("contact count");
      r.fits(n, kRecordedContactBytes, "contacts");
      for (uint32_t k = 0; k < n; ++k) {
        r.vec("contact point");
        r.vec("contact normal");
        r.finite("contact depth");
      }
      r.end();
      rec.frames.back().contacts = n;
    } else if (tag == kTagMode) {
      RecordedSubmissionMode m;
      const uint32_t nameLength = r.get<uint32_t>("name length");
      const auto nameBytes = r.bytes(nameLength, "the mode's name");
      m.name.assign(nameBytes.begin(), nameBytes.end());
      const uint32_t n = r.get<uint32_t>("frame count");
      if (n != rec.frames.size()) r.fail("times for " + std::to_string(n) + " frames, the recording holds " + std::to_string(rec.frames.size()));
      r.fits(n, 16, "frame times");
      for (uint32_t f = 0; f < n; ++f) {
        m.updateMs.push_back(r.finite("a transform update time"));
        m.submissionMs.push_back(r.finite("a submission time"));
        m.commitMs.push_back(r.finite("a commit time"));
        m.waitMs.push_back(r.finite("a render wait time"));
      }
      r.end();
      rec.modes.push_back(std::move(m));
    } else if (tag == kTagEnd) {
      const uint32_t frames = r.get<uint32_t>("frame count");
      if (frames != rec.frames.size()) r.fail("says " + std::to_string(frames) + " frames, the file holds " + std::to_string(rec.frames.size()));
      r.end();
      rec.complete = true;
    }
    // Unknown tags: skipped (FORMAT.md).
  }
  if (rec.head.is_null()) throw InvalidInput(file + ": no HEAD block");
  return rec;
}

}  // namespace bw
