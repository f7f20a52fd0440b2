#include "world/scene_file.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "collision/content/build_generators.h"
#include "collision/content/byte_reader.h"
#include "collision/terrain/voxel_terrain.h"
#include "collision/core/argument_checks.h"

namespace bw {

namespace {

using nlohmann::json;

std::string describe(const json& v) {
  std::string s = v.dump();
  if (s.size() > 60) s = s.substr(0, 57) + "...";
  return s;
}

// A JSON value with its path in the file, for error messages.
class Field {
 public:
  Field(const json& v, std::string path, const std::string& file) : v_(v), path_(std::move(path)), file_(file) {}

  [[noreturn]] void fail(const std::string& expected) const {
    throw SceneError(file_ + ": " + path_ + ": expected " + expected + ", got " + describe(v_));
  }
  [[noreturn]] void failMessage(const std::string& message) const { throw SceneError(file_ + ": " + path_ + ": " + message); }

  bool has(const char* key) const { return v_.is_object() && v_.contains(key); }
  Field at(const char* key) const {
    if (!v_.is_object()) fail("an object");
    if (!v_.contains(key)) throw SceneError(file_ + ": " + path_ + ": missing required field '" + key + "'");
    return Field(v_.at(key), path_ + "." + key, file_);
  }
  Field index(size_t i) const { return Field(v_.at(i), path_ + "[" + std::to_string(i) + "]", file_); }
  size_t arraySize(size_t maxSize) const {
    if (!v_.is_array()) fail("an array");
    if (v_.size() > maxSize) failMessage("has " + std::to_string(v_.size()) + " entries, at most " + std::to_string(maxSize) + " allowed");
    return v_.size();
  }
  // Unknown keys are errors: a typo must not silently fall back to a default.
  void allowOnly(std::initializer_list<const char*> keys) const {
    if (!v_.is_object()) fail("an object");
    std::set<std::string> allowed(keys.begin(), keys.end());
    for (auto it = v_.begin(); it != v_.end(); ++it) {
      if (!allowed.count(it.key())) {
        std::string list;
        for (const char* k : keys) list += std::string(list.empty() ? "" : ", ") + k;
        throw SceneError(file_ + ": " + path_ + "." + it.key() + ": unknown field (expected one of: " + list + ")");
      }
    }
  }

  double number(double lo, double hi) const {
    if (!v_.is_number()) fail("a number in " + range(lo, hi));
    const double d = v_.get<double>();
    if (!std::isfinite(d) || d < lo || d > hi) fail("a number in " + range(lo, hi));
    return d;
  }
  int64_t integer(int64_t lo, int64_t hi) const {
    if (!v_.is_number_integer()) fail("an integer in " + std::to_string(lo) + ".." + std::to_string(hi));
    const int64_t i = v_.get<int64_t>();
    if (i < lo || i > hi) fail("an integer in " + std::to_string(lo) + ".." + std::to_string(hi));
    return i;
  }
  uint64_t seed() const {
    if (!v_.is_number_unsigned() && !(v_.is_number_integer() && v_.get<int64_t>() >= 0)) fail("a non-negative integer seed");
    return v_.get<uint64_t>();
  }
  bool boolean() const {
    if (!v_.is_boolean()) fail("true or false");
    return v_.get<bool>();
  }
  std::string string() const {
    if (!v_.is_string()) fail("a string");
    return v_.get<std::string>();
  }
  std::string oneOf(std::initializer_list<const char*> options) const {
    std::string list;
    for (const char* o : options) list += std::string(list.empty() ? "" : ", ") + "\"" + o + "\"";
    if (!v_.is_string()) fail("one of " + list);
    const std::string s = v_.get<std::string>();
    for (const char* o : options)
      if (s == o) return s;
    fail("one of " + list);
  }
  Vec3d vec3(double lo, double hi) const {
    if (!v_.is_array() || v_.size() != 3) fail("an array of 3 numbers in " + range(lo, hi));
    Vec3d out;
    for (int i = 0; i < 3; ++i) out[i] = index(size_t(i)).number(lo, hi);
    return out;
  }
  // A rotation: [w, x, y, z] unit quaternion (normalised if within 1e-3 of unit length).
  Quatf quaternion() const {
    if (!v_.is_array() || v_.size() != 4) fail("a unit quaternion [w, x, y, z]");
    double q[4];
    for (int i = 0; i < 4; ++i) q[i] = index(size_t(i)).number(-1.001, 1.001);
    const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (std::abs(n - 1.0) > 1e-3) fail("a unit quaternion [w, x, y, z] (norm " + std::to_string(n) + ")");
    return Quatf(float(q[0] / n), float(q[1] / n), float(q[2] / n), float(q[3] / n));
  }

 private:
  static std::string range(double lo, double hi) {
    std::ostringstream s;
    s << "[" << lo << ", " << hi << "]";
    return s.str();
  }
  const json& v_;
  std::string path_;
  const std::string& file_;
};

constexpr double kMaxCoord = scene_limits::kMaxCoordinate;
constexpr double kMaxSpeed = scene_limits::kMaxSpeed;

Brick parseBrick(const Field& f) {
  f.allowOnly({"position", "half_size", "shape", "rotation", "material", "filter", "sides"});
  Brick b;
  b.position = f.at("position").vec3(-1e8, 1e8).cast<float>();
  // note: the bound as written (0.002), not the float kMinBrickHalfSize (0.0020000000949...):
  // against the float, "0.002" was refused with "expected [0.002, ...], got 0.002". It rounds
  // to kMinBrickHalfSize itself, which grids accept.
  b.halfSize = f.at("half_size").vec3(0.002, 1e6).cast<float>();
  if (f.has("shape")) {
    const std::string s = f.at("shape").oneOf({"box", "wedge", "corner_wedge", "cylinder"});
    b.shape = s == "box" ? BrickShape::Box : s == "wedge" ? BrickShape::Wedge : s == "corner_wedge" ? BrickShape::CornerWedge : BrickShape::Cylinder;
  }
  if (f.has("rotation")) b.rotation = AxisRotation::fromIndex(int(f.at("rotation").integer(0, 23)));
  if (f.has("material")) b.material = uint8_t(f.at("material").integer(0, 255));
  if (f.has("filter")) b.filter = uint32_t(f.at("filter").integer(0, 0xFFFFFFFFll));
  if (f.has("sides")) b.sides = uint8_t(f.at("sides").integer(3, 64));
  return b;
}

MotionType parseMotion(const Field& f) {
  const std::string m = f.oneOf({"static", "kinematic", "dynamic"});
  return m == "static" ? MotionType::Static : m == "kinematic" ? MotionType::Kinematic : MotionType::Dynamic;
}

// A content file named in a scene: relative paths are relative to the scene file's folder. The
// file must exist now, so a typo fails before anything is built.
std::string contentPath(const Field& f, const std::string& sceneSource, const char* extension) {
  const std::string name = f.string();
  std::filesystem::path p(name);
  if (p.extension() != extension) f.fail(std::string("a path to a ") + extension + " file");
  if (p.is_relative()) p = std::filesystem::path(sceneSource).parent_path() / p;
  std::error_code ec;
  if (std::filesystem::is_directory(p, ec)) f.failMessage(p.string() + " is a directory, expected a " + extension + " file");
  if (!std::filesystem::is_regular_file(p, ec)) f.failMessage("no such file: " + p.string());
  return p.string();
}

GridDescription parseGrid(const Field& f, const std::string& sceneSource) {
  f.allowOnly({"name", "generator", "scale", "seed", "file", "tiles", "tile_gap", "bricks", "position", "rotation", "motion",
               "linear_velocity", "angular_velocity", "split", "debris_bricks"});
  GridDescription g;
  g.name = f.at("name").string();
  if (g.name.empty()) f.at("name").fail("a non-empty name");
  if (int(f.has("generator")) + int(f.has("bricks")) + int(f.has("file")) != 1)
    f.failMessage("needs exactly one of 'generator', 'file' or 'bricks'");
  if (f.has("tiles")) {
    const Field t = f.at("tiles");
    if (t.arraySize(2) != 2) t.fail("[tiles along x, tiles along y]");
    g.tilesX = int(t.index(0).integer(1, scene_limits::kMaxTilesPerAxis));
    g.tilesY = int(t.index(1).integer(1, scene_limits::kMaxTilesPerAxis));
    if (f.has("bricks")) t.failMessage("tiles apply to a generator or a file, not to explicit bricks");
  }
  if (f.has("tile_gap")) g.tileGap = float(f.at("tile_gap").number(0, scene_limits::kMaxTileGap));
  if (f.has("file")) {
    g.file = contentPath(f.at("file"), sceneSource, ".brs");
  } else if (f.has("generator")) {
    const Field gen = f.at("generator");
    g.generator = gen.string();
    const auto names = buildNames();
    if (std::find(names.begin(), names.end(), g.generator) == names.end()) {
      std::string list;
      for (const auto& n : names) list += (list.empty() ? "\"" : ", \"") + n + "\"";
      gen.fail("one of " + list);
    }
    if (f.has("scale")) g.scale = float(f.at("scale").number(scene_limits::kMinScale, scene_limits::kMaxScale));
    if (f.has("seed")) g.seed = f.at("seed").seed();
  } else {
    const Field bricks = f.at("bricks");
    const size_t n = bricks.arraySize(10'000'000);
    if (n == 0) bricks.failMessage("is empty: a grid needs at least one brick");
    for (size_t i = 0; i < n; ++i) g.bricks.push_back(parseBrick(bricks.index(i)));
  }
  if (f.has("position")) g.position = f.at("position").vec3(-kMaxCoord, kMaxCoord);
  if (f.has("rotation")) g.rotation = f.at("rotation").quaternion();
  if (f.has("split")) g.split = f.at("split").boolean();
  if (f.has("debris_bricks")) {
    g.debrisBricks = uint32_t(f.at("debris_bricks").integer(0, 1'000'000));
    if (!g.split) f.at("debris_bricks").failMessage("applies to a grid with \"split\": true");
  }
  if (f.has("motion")) g.motion = parseMotion(f.at("motion"));
  if (f.has("linear_velocity") || f.has("angular_velocity")) {
    if (g.motion != MotionType::Kinematic && g.motion != MotionType::Dynamic)
      f.failMessage("velocities need \"motion\": \"kinematic\" or \"dynamic\"");
    if (f.has("linear_velocity")) g.kinematic.linearVelocity = f.at("linear_velocity").vec3(-kMaxSpeed, kMaxSpeed);
    if (f.has("angular_velocity")) g.kinematic.angularVelocity = f.at("angular_velocity").vec3(-scene_limits::kMaxAngularSpeed, scene_limits::kMaxAngularSpeed).cast<float>();
  }
  return g;
}

SpawnerDescription parseSpawner(const Field& f, const std::vector<GridDescription>& grids) {
  f.allowOnly({"shape", "grid", "count", "half_extents", "radius", "half_height", "density", "region", "velocity", "seed"});
  SpawnerDescription s;
  const std::string shape = f.at("shape").oneOf({"sphere", "box", "capsule", "grid"});
  s.shape = shape == "sphere" ? SpawnerDescription::Shape::Sphere
          : shape == "box"    ? SpawnerDescription::Shape::Box
          : shape == "capsule" ? SpawnerDescription::Shape::Capsule
                               : SpawnerDescription::Shape::Grid;
  s.count = uint32_t(f.at("count").integer(1, scene_limits::kMaxSpawnCount));
  if (s.shape == SpawnerDescription::Shape::Grid) {
    const Field g = f.at("grid");
    s.grid = g.string();
    if (std::none_of(grids.begin(), grids.end(), [&](const GridDescription& d) { return d.name == s.grid; }))
      g.fail("the name of a grid declared in \"grids\"");
  }
  using namespace scene_limits;
  if (f.has("half_extents")) s.halfExtents = f.at("half_extents").vec3(kMinSize, kMaxSize).cast<float>();
  if (f.has("radius")) s.radius = float(f.at("radius").number(kMinSize, kMaxSize));
  if (f.has("half_height")) s.halfHeight = float(f.at("half_height").number(0, kMaxSize));
  if (f.has("density")) s.density = float(f.at("density").number(kMinDensity, kMaxDensity));
  const Field region = f.at("region");
  region.allowOnly({"min", "max"});
  s.regionMin = region.at("min").vec3(-kMaxCoord, kMaxCoord);
  s.regionMax = region.at("max").vec3(-kMaxCoord, kMaxCoord);
  for (int i = 0; i < 3; ++i)
    if (s.regionMin[i] > s.regionMax[i]) region.failMessage(std::string("min.") + "xyz"[i] + " is greater than max." + "xyz"[i]);
  if (f.has("velocity")) s.velocity = f.at("velocity").vec3(-kMaxSpeed, kMaxSpeed);
  if (f.has("seed")) s.seed = f.at("seed").seed();
  return s;
}

SceneSettings parseSettings(const Field& f) {
  f.allowOnly({"gravity", "timestep", "substeps", "solver_iterations", "frames", "lod_fraction", "approximation_depth", "sleeping",
               "manifold_size", "reuse_translation", "reuse_rotation", "relax_iterations", "shock_propagation",
               "rolling_resistance", "start_in_solid", "depenetration_speed", "memory_budget_mib", "grid_pairs"});
  SceneSettings s;
  if (f.has("gravity")) s.gravity = f.at("gravity").vec3(-scene_limits::kMaxGravity, scene_limits::kMaxGravity);
  if (f.has("timestep")) s.timestep = f.at("timestep").number(scene_limits::kMinTimestep, scene_limits::kMaxTimestep);
  if (f.has("substeps")) s.substeps = int(f.at("substeps").integer(1, scene_limits::kMaxSubsteps));
  if (f.has("solver_iterations")) s.solverIterations = int(f.at("solver_iterations").integer(1, scene_limits::kMaxSolverIterations));
  if (f.has("frames")) s.frames = uint32_t(f.at("frames").integer(1, 10'000'000));
  if (f.has("memory_budget_mib")) s.memoryBudgetMiB = f.at("memory_budget_mib").number(1, scene_limits::kMaxMemoryBudgetMiB);
  if (f.has("lod_fraction")) s.lodFraction = float(f.at("lod_fraction").number(0, 1));
  if (f.has("approximation_depth")) s.approximationDepth = int(f.at("approximation_depth").integer(0, scene_limits::kMaxApproximationDepth));
  if (f.has("sleeping")) s.sleeping = f.at("sleeping").boolean();
  if (f.has("shock_propagation")) s.shockPropagation = f.at("shock_propagation").boolean();
  if (f.has("grid_pairs")) {
    const std::string mode = f.at("grid_pairs").oneOf({"convex", "two_way", "auto"});
    s.gridPairs = mode == "convex" ? GridPairMode::Convex : mode == "two_way" ? GridPairMode::TwoWay : GridPairMode::Auto;
  }
  if (f.has("relax_iterations")) s.relaxIterations = int(f.at("relax_iterations").integer(0, scene_limits::kMaxRelaxIterations));
  if (f.has("start_in_solid")) {
    const std::string policy = f.at("start_in_solid").oneOf({"push_out", "refuse"});
    s.startInSolid = policy == "refuse" ? StartInSolid::Refuse : StartInSolid::PushOut;
  }
  if (f.has("depenetration_speed")) s.depenetrationSpeed = float(f.at("depenetration_speed").number(0.01, scene_limits::kMaxSpeed));
  if (f.has("rolling_resistance")) s.rollingResistance = float(f.at("rolling_resistance").number(0, 1));
  if (f.has("manifold_size")) s.manifoldSize = int(f.at("manifold_size").integer(1, scene_limits::kMaxManifoldSize));
  if (f.has("reuse_translation")) s.reuseTranslation = f.at("reuse_translation").number(0, 1);
  if (f.has("reuse_rotation")) s.reuseRotation = float(f.at("reuse_rotation").number(0, 1));
  return s;
}

TerrainDescription parseTerrain(const Field& f, const std::string& sceneSource) {
  f.allowOnly({"name", "file", "generator", "size", "seed", "voxel_size", "position", "water", "water_density", "break_free",
               "anchor_below", "debris_voxels"});
  TerrainDescription t;
  t.name = f.at("name").string();
  if (f.has("file") == f.has("generator")) f.failMessage("needs exactly one of \"file\" (a .vox) and \"generator\" (\"quarry\")");
  if (f.has("file")) {
    t.file = contentPath(f.at("file"), sceneSource, ".vox");
  } else {
    t.generator = f.at("generator").oneOf({"quarry"});
    if (f.has("size")) {
      const Field size = f.at("size");
      if (size.arraySize(3) != 3) size.fail("[x, y, z] voxels");
      const int64_t lo[3] = {32, 32, 16};
      t.size = {int32_t(size.index(0).integer(lo[0], scene_limits::kMaxGeneratedTerrain)),
                int32_t(size.index(1).integer(lo[1], scene_limits::kMaxGeneratedTerrain)),
                int32_t(size.index(2).integer(lo[2], scene_limits::kMaxGeneratedTerrain))};
    }
    if (f.has("seed")) t.seed = f.at("seed").seed();
  }
  if (f.has("break_free")) t.breakFree = f.at("break_free").boolean();
  if (f.has("anchor_below")) t.anchorBelow = int32_t(f.at("anchor_below").integer(0, VoxelTerrain::kMaxSize));
  if (f.has("debris_voxels")) t.debrisVoxels = uint32_t(f.at("debris_voxels").integer(0, UINT32_MAX));
  if (f.has("voxel_size")) t.voxelSize = float(f.at("voxel_size").number(scene_limits::kMinVoxelSize, scene_limits::kMaxVoxelSize));
  if (f.has("position")) t.position = f.at("position").vec3(-kMaxCoord, kMaxCoord);
  if (f.has("water")) {
    const Field w = f.at("water");
    if (w.arraySize(2) != 2) w.fail("[first, last] palette indices");
    t.waterFirst = int(w.index(0).integer(1, 255));
    t.waterLast = int(w.index(1).integer(1, 255));
    if (t.waterFirst > t.waterLast) w.failMessage("first palette index is greater than the last");
  }
  if (f.has("water_density")) t.waterDensity = float(f.at("water_density").number(scene_limits::kMinWaterDensity, scene_limits::kMaxWaterDensity));
  return t;
}

RayLoadDescription parseRays(const Field& f) {
  f.allowOnly({"count", "length", "seed"});
  RayLoadDescription r;
  r.count = uint32_t(f.at("count").integer(0, 10'000'000));
  if (f.has("length")) r.length = float(f.at("length").number(0, scene_limits::kMaxRayLength));
  if (f.has("seed")) r.seed = f.at("seed").seed();
  return r;
}

AttachmentsDescription parseAttachments(const Field& f) {
  f.allowOnly({"render_chunk", "grid_lights", "batch_capacity"});
  AttachmentsDescription a;
  a.enabled = true;
  if (f.has("render_chunk")) a.renderChunk = float(f.at("render_chunk").number(scene_limits::kMinRenderChunk, scene_limits::kMaxRenderChunk));
  if (f.has("grid_lights")) a.gridLights = f.at("grid_lights").boolean();
  if (f.has("batch_capacity")) {
    const Field c = f.at("batch_capacity");
    c.allowOnly({"primitives", "lights"});
    if (c.has("primitives")) a.batchPrimitives = uint32_t(c.at("primitives").integer(1, scene_limits::kMaxBatchCapacity));
    if (c.has("lights")) a.batchLights = uint32_t(c.at("lights").integer(1, scene_limits::kMaxBatchCapacity));
  }
  return a;
}

EditLoadDescription parseEdit(const Field& f, const std::vector<GridDescription>& grids, const std::vector<TerrainDescription>& terrains) {
  f.allowOnly({"grid", "terrain", "kind", "per_frame", "first_frame", "last_frame", "every", "radius", "brick_half_size", "wall_length",
               "seed", "region"});
  using namespace scene_limits;
  EditLoadDescription e;
  if (f.has("grid") == f.has("terrain")) f.failMessage("needs exactly one of \"grid\" and \"terrain\"");
  if (f.has("grid")) {
    const Field g = f.at("grid");
    e.grid = g.string();
    if (std::none_of(grids.begin(), grids.end(), [&](const GridDescription& d) { return d.name == e.grid; }))
      g.fail("the name of a grid declared in \"grids\"");
  } else {
    const Field t = f.at("terrain");
    e.terrain = t.string();
    if (std::none_of(terrains.begin(), terrains.end(), [&](const TerrainDescription& d) { return d.name == e.terrain; }))
      t.fail("the name of a terrain declared in \"terrains\"");
    f.at("kind").oneOf({"carve"});  // terrains are carved only
  }
  if (f.has("region")) {
    if (!f.has("terrain")) f.at("region").failMessage("only terrain edits take a region");
    const Field region = f.at("region");
    region.allowOnly({"min", "max"});
    e.hasRegion = true;
    e.regionMin = region.at("min").vec3(-kMaxCoord, kMaxCoord);
    e.regionMax = region.at("max").vec3(-kMaxCoord, kMaxCoord);
    for (int i = 0; i < 3; ++i)
      if (e.regionMin[i] > e.regionMax[i]) region.failMessage(std::string("min.") + "xyz"[i] + " is greater than max." + "xyz"[i]);
  }
  const std::string kind = f.at("kind").oneOf({"remove", "place", "carve", "wall"});
  e.kind = kind == "remove" ? EditLoadDescription::Kind::Remove
         : kind == "place"  ? EditLoadDescription::Kind::Place
         : kind == "carve"  ? EditLoadDescription::Kind::Carve
                            : EditLoadDescription::Kind::Wall;
  if (f.has("per_frame")) e.perFrame = uint32_t(f.at("per_frame").integer(1, kMaxEditsPerFrame));
  if (f.has("first_frame")) e.firstFrame = uint32_t(f.at("first_frame").integer(0, UINT32_MAX));
  if (f.has("last_frame")) e.lastFrame = uint32_t(f.at("last_frame").integer(0, UINT32_MAX));
  if (e.lastFrame < e.firstFrame) f.at("last_frame").fail("a frame at or after first_frame (" + std::to_string(e.firstFrame) + ")");
  if (f.has("every")) e.every = uint32_t(f.at("every").integer(1, UINT32_MAX));
  if (f.has("radius")) e.radius = float(f.at("radius").number(kMinSize, kMaxSize));
  if (f.has("brick_half_size")) e.brickHalfSize = f.at("brick_half_size").vec3(kMinSize, kMaxSize).cast<float>();
  if (f.has("wall_length")) e.wallLength = uint32_t(f.at("wall_length").integer(1, kMaxWallLength));
  if (f.has("seed")) e.seed = f.at("seed").seed();
  return e;
}

// A grid name that must be declared in "grids".
std::string gridName(const Field& f, const std::vector<GridDescription>& grids) {
  const std::string name = f.string();
  if (std::none_of(grids.begin(), grids.end(), [&](const GridDescription& d) { return d.name == name; }))
    f.fail("the name of a grid declared in \"grids\"");
  return name;
}

SceneChecks parseChecks(const Field& f, const std::vector<GridDescription>& grids) {
  f.allowOnly({"linked", "ends_in"});
  SceneChecks c;
  if (f.has("linked")) {
    const Field chains = f.at("linked");
    const size_t n = chains.arraySize(1'000);
    for (size_t i = 0; i < n; ++i) {
      const Field chain = chains.index(i);
      const size_t links = chain.arraySize(100'000);
      if (links < 2) chain.fail("an array of at least 2 grid names (a chain in order)");
      std::set<std::string> seen;
      c.linked.emplace_back();
      for (size_t k = 0; k < links; ++k) {
        c.linked.back().push_back(gridName(chain.index(k), grids));
        if (!seen.insert(c.linked.back().back()).second) chain.index(k).fail("a grid not already in this chain");
      }
    }
  }
  if (f.has("ends_in")) {
    const Field list = f.at("ends_in");
    const size_t n = list.arraySize(1'000);
    for (size_t i = 0; i < n; ++i) {
      const Field e = list.index(i);
      e.allowOnly({"grid", "min", "max"});
      SceneChecks::EndsIn end;
      end.grid = gridName(e.at("grid"), grids);
      end.min = e.at("min").vec3(-kMaxCoord, kMaxCoord);
      end.max = e.at("max").vec3(-kMaxCoord, kMaxCoord);
      for (int a = 0; a < 3; ++a)
        if (end.min[a] > end.max[a]) e.failMessage(std::string("min.") + "xyz"[a] + " is greater than max." + "xyz"[a]);
      c.endsIn.push_back(end);
    }
  }
  return c;
}

}  // namespace

namespace {
// ":<line>:<column>" of the first occurrence of the literal quoted in a parser message ('...'),
// or nothing when there is none.
std::string where(const std::string& text, const std::string& message) {
  const size_t open = message.find('\''), close = open == std::string::npos ? open : message.find('\'', open + 1);
  if (close == std::string::npos || close == open + 1) return "";
  const size_t at = text.find(message.substr(open + 1, close - open - 1));
  if (at == std::string::npos) return "";
  const size_t line = size_t(std::count(text.begin(), text.begin() + ptrdiff_t(at), '\n')) + 1;
  const size_t lineStart = text.rfind('\n', at);
  return ":" + std::to_string(line) + ":" + std::to_string(at - (lineStart == std::string::npos ? 0 : lineStart + 1) + 1);
}
}  // namespace

SceneDescription parseScene(const std::string& jsonText, const std::string& sourceName) {
  json doc;
  try {
    doc = json::parse(jsonText);
  } catch (const json::parse_error& e) {
    throw SceneError(sourceName + ": not valid JSON (" + e.what() + ")");
  } catch (const json::exception& e) {
    // A number the parser cannot hold (1e999): its message names the literal, not where it is.
    throw SceneError(sourceName + where(jsonText, e.what()) + ": not a valid JSON value (" + e.what() + ")");
  }
  const Field root(doc, "scene", sourceName);
  root.allowOnly({"name", "description", "settings", "grids", "spawners", "terrains", "rays", "attachments", "edits", "checks"});
  SceneDescription scene;
  scene.source = sourceName;
  scene.name = root.at("name").string();
  if (root.has("description")) root.at("description").string();
  if (root.has("settings")) scene.settings = parseSettings(root.at("settings"));
  if (root.has("grids")) {
    const Field grids = root.at("grids");
    const size_t n = grids.arraySize(100'000);
    std::set<std::string> names;
    for (size_t i = 0; i < n; ++i) {
      scene.grids.push_back(parseGrid(grids.index(i), sourceName));
      if (!names.insert(scene.grids.back().name).second)
        grids.index(i).at("name").fail("a name not used by another grid");
    }
  }
  if (root.has("spawners")) {
    const Field spawners = root.at("spawners");
    const size_t n = spawners.arraySize(10'000);
    for (size_t i = 0; i < n; ++i) scene.spawners.push_back(parseSpawner(spawners.index(i), scene.grids));
  }
  if (root.has("terrains")) {
    const Field terrains = root.at("terrains");
    const size_t n = terrains.arraySize(64);
    for (size_t i = 0; i < n; ++i) scene.terrains.push_back(parseTerrain(terrains.index(i), sourceName));
  }
  if (root.has("rays")) scene.rays = parseRays(root.at("rays"));
  if (root.has("attachments")) scene.attachments = parseAttachments(root.at("attachments"));
  if (root.has("edits")) {
    const Field edits = root.at("edits");
    const size_t n = edits.arraySize(1'000);
    for (size_t i = 0; i < n; ++i) scene.edits.push_back(parseEdit(edits.index(i), scene.grids, scene.terrains));
  }
  if (root.has("checks")) scene.checks = parseChecks(root.at("checks"), scene.grids);
  if (scene.grids.empty() && scene.spawners.empty() && scene.terrains.empty())
    root.failMessage("declares no grids, spawners or terrains: nothing to simulate");
  return scene;
}

SceneDescription loadScene(const std::string& path) {
  try {
    requireRegularFile(path, "a scene (.json)");
  } catch (const InvalidInput& e) {
    throw SceneError(e.what());
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path + ": cannot open the scene file");
  std::stringstream text;
  text << in.rdbuf();
  return parseScene(text.str(), path);
}

}  // namespace bw
