#include "recording/recording_writer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <zlib.h>

#include "collision/core/errors.h"
#include "collision/core/hash.h"
#include "collision/terrain/chunk_mesher.h"

namespace bw {
namespace {

// Stage times of a frame, in the order of stageNames(); "other" is what the named stages
// leave of the frame (waits, bookkeeping inside step()).
constexpr int kStages = 10;
void stageTimes(const StepStats& s, float out[kStages]) {
  const double render = s.render.updateMs + s.render.submissionMs + s.render.commitMs + s.render.waitMs;
  const double named[kStages - 1] = {s.editMs + s.editLoadMs, s.splitMs, s.terrainEditMs, s.broadphaseMs, s.contactsMs,
                                     s.solverMs, s.integrateMs, s.raysMs, render};
  double sum = 0;
  for (int k = 0; k < kStages - 1; ++k) {
    out[k] = float(named[k]);
    sum += named[k];
  }
  out[kStages - 1] = float(std::max(0.0, s.totalMs - sum));
}

RecordedKind kindOf(const BodyShape& s) {
  if (s.isGrid()) return RecordedKind::Grid;
  if (s.isTerrain()) return RecordedKind::Terrain;
  switch (s.primitive.kind) {
    case QueryShape::Kind::Sphere: return RecordedKind::Sphere;
    case QueryShape::Kind::Box: return RecordedKind::Box;
    case QueryShape::Kind::Capsule: return RecordedKind::Capsule;
    case QueryShape::Kind::Hull: return RecordedKind::Hull;
  }
  return RecordedKind::Hull;
}

void putBrick(ByteSink& s, const Brick& b) {
  static_assert(sizeof(Brick) == 32);
  s.put(b.position);
  s.put(b.halfSize);
  s.put(b.filter);
  s.put(b.material);
  s.put(b.rotation.index());
  s.put(uint8_t(b.shape));
  s.put(b.sides);
}

void putQuat(ByteSink& s, const Quatf& q) {
  s.put(q.x());
  s.put(q.y());
  s.put(q.z());
  s.put(q.w());
}

uint64_t chunkVoxelHash(const VoxelChunk& c) { return hashBytes(0x5EED, c.voxels, sizeof c.voxels); }

}  // namespace

const std::vector<std::string>& RecordingWriter::stageNames() {
  static const std::vector<std::string> names{"edits", "splits", "terrain_edits", "broadphase", "contacts",
                                              "solver", "integrate", "rays", "render", "other"};
  return names;
}

RecordingWriter::RecordingWriter(World& world, const std::string& path, RecordingOptions options, int threads)
    : path_(path), options_(options) {
  // Uncompressed by default: compressing ~66 KB of poses a frame (city_rain) cost more than a
  // frame's simulation (measured, level 1 and 6), and poses barely compress (20.2 -> 17.9 MB).
  file_ = gzopen(path.c_str(), options.gzip ? "wb6" : "wbT");
  if (!file_) throw InvalidInput("--record: cannot write " + path);
  world.recordEdits(true);

  // The origin: the bodies' mean position at the start on a 1024 m lattice (FORMAT.md).
  const BodyStore& bodies = world.bodies();
  Vec3d mean = Vec3d::Zero();
  for (uint32_t i = 0; i < bodies.size(); ++i) mean += bodies.position[i] / double(std::max<uint32_t>(bodies.size(), 1));
  for (int k = 0; k < 3; ++k) origin_[k] = std::round(mean[k] / 1024.0) * 1024.0;

  nlohmann::json rotations = nlohmann::json::array();
  for (int r = 0; r < 24; ++r) {
    const AxisRotation rot = AxisRotation::fromIndex(r);
    nlohmann::json m = nlohmann::json::array();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) m.push_back(rot.sourceAxis(i) == j ? rot.sign(i) : 0);
    rotations.push_back(m);
  }
  const SceneDescription& scene = world.scene();
  const nlohmann::json head{{"format", "brickworld recording"},
                            {"version", kRecordingVersion},
                            {"scene", scene.name},
                            {"timestep", scene.settings.timestep},
                            {"substeps", scene.settings.substeps},
                            {"threads", threads},
                            {"origin", {origin_.x(), origin_.y(), origin_.z()}},
                            {"stages", stageNames()},
                            {"contacts", options.contacts},
                            {"rotations", rotations},
                            {"brick_shapes", {"box", "wedge", "corner_wedge", "cylinder"}}};
  const std::string text = head.dump();
  gzwrite(static_cast<gzFile>(file_), kRecordingMagic, sizeof kRecordingMagic);
  gzwrite(static_cast<gzFile>(file_), &kRecordingVersion, sizeof kRecordingVersion);
  bytes_ += sizeof kRecordingMagic + sizeof kRecordingVersion;
  ByteSink s;
  s.put(text.data(), text.size());
  block(kTagHead, s);
  for (uint32_t g = 0; g < world.gridCount(); ++g) writeGrid(world, g);
  chunkHashes_.resize(world.terrainCount());
  for (uint32_t t = 0; t < world.terrainCount(); ++t) {
    writeTerrainChunks(world, t, nullptr);
    world.terrain(t).voxels().forEachChunk([&](const Int3& c, const VoxelChunk& chunk) { chunkHashes_[t][chunkKey(c)] = chunkVoxelHash(chunk); });
  }
  writeBodies(world, 0);
}

RecordingWriter::~RecordingWriter() {
  if (file_) gzclose(static_cast<gzFile>(file_));
}

void RecordingWriter::block(uint32_t tag, const ByteSink& payload) {
  if (payload.bytes.size() > UINT32_MAX)
    throw InvalidInput("--record: a block of " + std::to_string(payload.bytes.size()) +
                       " bytes does not fit the format's 32-bit length (a grid recorded brick by brick above ~119M bricks: lower "
                       "--record-bricks)");
  const uint32_t header[2] = {tag, uint32_t(payload.bytes.size())};
  gzFile f = static_cast<gzFile>(file_);
  if (gzwrite(f, header, sizeof header) != int(sizeof header)) failed_ = true;
  if (!payload.bytes.empty() && gzwrite(f, payload.bytes.data(), unsigned(payload.bytes.size())) != int(payload.bytes.size())) failed_ = true;
  bytes_ += sizeof header + payload.bytes.size();
}

void RecordingWriter::putPose(ByteSink& s, const Vec3d& position, const Quatf& rotation) const {
  const Vec3f p = (position - origin_).cast<float>();
  s.put(p);
  putQuat(s, rotation);
}

void RecordingWriter::writeGrid(const World& world, uint32_t g) {
  const BrickGrid& grid = world.grid(g);
  const std::string& name = world.gridName(g);
  const bool bricks = grid.brickCount() <= options_.maxGridBricks;
  ByteSink& s = scratch_;
  s.bytes.clear();
  s.bytes.reserve(20 + name.size() + (bricks ? size_t(grid.brickCount()) * kRecordedBrickBytes : 0));
  s.put(g);
  s.put(uint32_t(name.size()));
  s.put(name.data(), name.size());
  s.put(grid.brickCount());
  s.put(uint32_t(bricks ? grid.brickCount() : 0));
  if (mirrors_.size() <= g) mirrors_.resize(g + 1);
  mirrors_[g] = Mirror{.kept = bricks, .bricks = {}, .live = {}};
  if (bricks)
    grid.forEachBrick([&](uint32_t id) {
      s.put(id);
      putBrick(s, grid.brick(id));
      mirrorEdit({g, id, true, grid.brick(id)});
    });
  block(kTagGrid, s);
  writeNodeBoxes(world, g);
  gridsWritten_ = g + 1;
}

void RecordingWriter::mirrorEdit(const BrickEdit& e) {
  if (e.grid >= mirrors_.size() || !mirrors_[e.grid].kept) return;
  Mirror& m = mirrors_[e.grid];
  if (e.brick >= m.live.size()) {
    if (!e.placed) return;
    const size_t size = std::max<size_t>(e.brick + 1, m.live.size() * 3 / 2);
    m.live.resize(size, 0);
    m.bricks.resize(size);
  }
  m.live[e.brick] = e.placed;
  if (e.placed) m.bricks[e.brick] = e.value;
}

void RecordingWriter::diffWithMirror(const World& world, uint32_t g, std::vector<BrickEdit>& out) {
  if (g >= gridsWritten_ || !mirrors_[g].kept) return;  // a grid made this frame is written as the frame leaves it
  const BrickGrid& grid = world.grid(g);
  Mirror& m = mirrors_[g];
  const size_t first = out.size();
  const auto same = [](const Brick& a, const Brick& b) { return std::memcmp(&a, &b, sizeof(Brick)) == 0; };
  for (uint32_t id = 0; id < m.live.size(); ++id)
    if (m.live[id] && (!grid.hasBrick(id) || !same(grid.brick(id), m.bricks[id]))) out.push_back({g, id, false, m.bricks[id]});
  grid.forEachBrick([&](uint32_t id) {
    if (id >= m.live.size() || !m.live[id] || !same(grid.brick(id), m.bricks[id])) out.push_back({g, id, true, grid.brick(id)});
  });
  for (size_t k = first; k < out.size(); ++k) mirrorEdit(out[k]);
}

void RecordingWriter::writeNodeBoxes(const World& world, uint32_t g) {
  ByteSink& s = scratch_;
  s.bytes.clear();
  s.put(g);
  s.put(uint32_t(options_.nodeLevels));
  std::vector<Aabb> boxes;
  uint32_t most = 1;
  for (int level = 1; level <= options_.nodeLevels; ++level) {
    most *= 8;
    boxes.clear();
    world.grid(g).coverBoxes(most, boxes);
    // An empty grid's cover is one inverted box: nothing to draw.
    std::erase_if(boxes, [](const Aabb& b) { return !(b.min.allFinite() && b.max.allFinite() && (b.min.array() <= b.max.array()).all()); });
    s.put(uint32_t(boxes.size()));
    for (const Aabb& b : boxes) {
      s.put(b.min);
      s.put(b.max);
    }
  }
  block(kTagNodes, s);
}

void RecordingWriter::writeTerrainChunks(const World& world, uint32_t t, const std::vector<uint64_t>* chunks) {
  const Terrain& terrain = world.terrain(t);
  const VoxelTerrain& voxels = terrain.voxels();
  const float chunkEdge = terrain.voxelSize() * float(kChunkSize);
  std::vector<Int3> coords;
  if (chunks) {
    for (uint64_t k : *chunks) coords.push_back(chunkCoordFromKey(k));
  } else {
    voxels.forEachChunk([&](const Int3& c, const VoxelChunk&) { coords.push_back(c); });
    std::sort(coords.begin(), coords.end(), [](const Int3& a, const Int3& b) { return chunkKey(a) < chunkKey(b); });
  }
  ByteSink& s = scratch_;
  s.bytes.clear();
  s.put(t);
  s.put(terrain.voxelSize());
  s.put(uint32_t(coords.size()));
  ChunkNeighbourhood n;
  ChunkMesh mesh;
  for (const Int3& c : coords) {
    voxels.gatherNeighbourhood(c, n);
    meshChunk(n, terrain.voxelSize(), mesh);
    s.put(c.x);
    s.put(c.y);
    s.put(c.z);
    s.put(uint32_t(mesh.vertices.size()));
    s.put(mesh.triangleCount());
    const Vec3f offset(float(c.x) * chunkEdge, float(c.y) * chunkEdge, float(c.z) * chunkEdge);
    for (uint32_t v = 0; v < mesh.vertices.size(); ++v) s.put(Vec3f(mesh.vertex(v) + offset));
    for (uint16_t i : mesh.indices) s.put(uint32_t(i));
    s.put(mesh.materials.data(), mesh.materials.size());
  }
  block(kTagTerrain, s);
  terrainsWritten_ = std::max(terrainsWritten_, t + 1);
}

std::vector<uint64_t> RecordingWriter::changedChunks(const World& world, uint32_t t) {
  std::unordered_map<uint64_t, uint64_t>& kept = chunkHashes_[t];
  std::unordered_map<uint64_t, uint64_t> now;
  now.reserve(kept.size());
  std::vector<Int3> changed;
  world.terrain(t).voxels().forEachChunk([&](const Int3& c, const VoxelChunk& chunk) {
    const uint64_t key = chunkKey(c), h = chunkVoxelHash(chunk);
    now[key] = h;
    const auto it = kept.find(key);
    if (it == kept.end() || it->second != h) changed.push_back(c);
  });
  for (const auto& [key, h] : kept)
    if (!now.count(key)) changed.push_back(chunkCoordFromKey(key));
  kept.swap(now);
  // A chunk's mesh reads one voxel into each neighbour: remesh the neighbours too.
  std::vector<uint64_t> out;
  const Int3 size = world.terrain(t).voxels().size();
  const Int3 chunks{(size.x + kChunkSize - 1) / kChunkSize, (size.y + kChunkSize - 1) / kChunkSize, (size.z + kChunkSize - 1) / kChunkSize};
  for (const Int3& c : changed)
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const Int3 n{c.x + dx, c.y + dy, c.z + dz};
          if (n.x < 0 || n.y < 0 || n.z < 0 || n.x >= chunks.x || n.y >= chunks.y || n.z >= chunks.z) continue;
          out.push_back(chunkKey(n));
        }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

void RecordingWriter::writeBodies(const World& world, uint32_t first) {
  const BodyStore& b = world.bodies();
  ByteSink& s = scratch_;
  s.bytes.clear();
  s.put(first);
  s.put(b.size() - first);
  for (uint32_t i = first; i < b.size(); ++i) {
    const BodyShape& shape = b.shape[i];
    const RecordedKind kind = kindOf(shape);
    s.put(uint8_t(b.motion[i]));
    s.put(uint8_t(kind));
    s.put(uint16_t(0));
    s.put(shape.isGrid() ? shape.grid : shape.isTerrain() ? shape.terrain : kInvalidIndex);
    Vec3f size = Vec3f::Zero();
    if (kind == RecordedKind::Sphere) size.x() = shape.primitive.radius;
    if (kind == RecordedKind::Capsule) size = Vec3f(shape.primitive.radius, shape.primitive.halfHeight, 0.f);
    if (kind == RecordedKind::Box || kind == RecordedKind::Hull) size = shape.primitive.localHalfExtents();
    s.put(size);
    s.put(Vec3f(b.shapeFromBody[i].translation.cast<float>()));
    putQuat(s, b.shapeFromBody[i].rotation);
    putPose(s, b.position[i], b.rotation[i]);
  }
  block(kTagBody, s);
  bodiesWritten_ = b.size();
}

void RecordingWriter::frame(const World& world, const ContainmentReport& inside) {
  const StepStats& stats = world.lastStats();
  const EditLog& log = world.lastEdits();
  ByteSink& s = scratch_;
  // The logged edits, then what edits through World::editGrid() changed (found by comparing
  // those grids with their mirrors once the logged edits are in).
  edits_.assign(log.bricks.begin(), log.bricks.end());
  for (const BrickEdit& e : edits_) mirrorEdit(e);
  for (uint32_t g : log.wholeGrids) diffWithMirror(world, g, edits_);
  if (!edits_.empty()) {
    s.bytes.clear();
    s.put(uint32_t(edits_.size()));
    for (const BrickEdit& e : edits_) {
      s.put(e.grid);
      s.put(e.brick);
      s.put(uint8_t(e.placed));
      putBrick(s, e.value);
    }
    block(kTagEdit, s);
  }
  if (!log.splits.empty()) {
    s.bytes.clear();
    s.put(uint32_t(log.splits.size()));
    for (const SplitEdit& e : log.splits) {
      s.put(e.fromGrid);
      s.put(e.grid);
      s.put(e.body);
    }
    block(kTagSplit, s);
  }
  // Grids made this frame (split parts, terrain slabs), as the frame leaves them.
  for (uint32_t g = gridsWritten_; g < world.gridCount(); ++g) writeGrid(world, g);
  if (stats.voxelsCarved || stats.terrainParts || stats.debrisVoxels)
    for (uint32_t t = 0; t < world.terrainCount(); ++t) {
      const std::vector<uint64_t> changed = changedChunks(world, t);
      if (!changed.empty()) writeTerrainChunks(world, t, &changed);
    }
  if (world.bodies().size() > bodiesWritten_) writeBodies(world, bodiesWritten_);

  const BodyStore& b = world.bodies();
  states_.assign(b.size(), uint8_t(RecordedState::Awake));
  for (uint32_t i = 0; i < b.size(); ++i)
    if (world.asleep(i)) states_[i] = uint8_t(RecordedState::Asleep);
  for (const Depenetration& d : world.depenetrating())
    if (d.body < b.size()) states_[d.body] = uint8_t(RecordedState::PushedOut);
  for (uint32_t body : inside.bodies)
    if (body < b.size()) states_[body] = uint8_t(RecordedState::InsideSolid);
  float stages[kStages];
  stageTimes(stats, stages);
  uint32_t moving = 0;
  for (uint32_t i = 0; i < b.size(); ++i) moving += b.motion[i] != MotionType::Static;
  s.bytes.clear();
  s.bytes.reserve(16 + sizeof stages + size_t(moving) * kRecordedPoseBytes);
  s.put(frames_);
  s.put(stages, sizeof stages);
  s.put(b.size());
  s.put(moving);
  for (uint32_t i = 0; i < b.size(); ++i) {
    if (b.motion[i] == MotionType::Static) continue;
    s.put(i);
    putPose(s, b.position[i], b.rotation[i]);
    s.put(states_[i]);
  }
  block(kTagFrame, s);

  if (options_.contacts) {
    s.bytes.clear();
    uint32_t n = 0;
    for (uint32_t k = 0; k < world.pairs().size(); ++k) n += uint32_t(world.pairContacts(k).size());
    s.put(n);
    for (uint32_t k = 0; k < world.pairs().size(); ++k)
      for (const Contact& c : world.pairContacts(k)) {
        s.put(Vec3f((c.position - origin_).cast<float>()));
        s.put(c.normal);
        s.put(c.depth);
      }
    block(kTagContacts, s);
  }
  ++frames_;
}

void RecordingWriter::submissionMode(const std::string& name, std::span<const double> update, std::span<const double> submission,
                                     std::span<const double> commit, std::span<const double> wait) {
  for (const auto& series : {update, submission, commit, wait})
    if (series.size() != frames_)
      throw InvalidInput("recording: submission mode " + name + " has " + std::to_string(series.size()) + " frames, the recording " +
                         std::to_string(frames_));
  ByteSink& s = scratch_;
  s.bytes.clear();
  s.put(uint32_t(name.size()));
  s.put(name.data(), name.size());
  s.put(frames_);
  for (uint32_t f = 0; f < frames_; ++f)
    for (const auto& series : {update, submission, commit, wait}) s.put(float(series[f]));
  block(kTagMode, s);
}

void RecordingWriter::finish() {
  if (!file_) return;
  ByteSink s;
  s.put(frames_);
  block(kTagEnd, s);
  const int closed = gzclose(static_cast<gzFile>(file_));
  file_ = nullptr;
  if (failed_ || closed != Z_OK) throw InvalidInput("--record: writing " + path_ + " failed (disk full?)");
}

}  // namespace bw
