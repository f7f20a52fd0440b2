#include "world/scene_validation.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "world/scene_budget.h"
#include "world/scene_file.h"

namespace bw {

namespace {

using namespace scene_limits;

class Checker {
 public:
  explicit Checker(const SceneDescription& s)
      : prefix_(s.source.empty() ? "scene '" + s.name + "'" : s.source) {}

  void number(const std::string& field, double v, double lo, double hi) const {
    if (!(std::isfinite(v) && v >= lo && v <= hi)) fail(field, v, lo, hi);
  }
  template <class V>
  void vector(const std::string& field, const V& v, double lo, double hi) const {
    for (int i = 0; i < int(v.size()); ++i) number(field + "[" + std::to_string(i) + "]", double(v[i]), lo, hi);
  }
  void unitQuaternion(const std::string& field, const Quatf& q) const {
    const double n = double(q.norm());
    if (!std::isfinite(n) || std::abs(n - 1.0) > 1e-3) {
      std::ostringstream m;
      m << prefix_ << ": " << field << ": expected a unit quaternion, got norm " << n;
      throw SceneError(m.str());
    }
  }
  [[noreturn]] void message(const std::string& field, const std::string& what) const {
    throw SceneError(prefix_ + ": " + field + ": " + what);
  }

 private:
  [[noreturn]] void fail(const std::string& field, double v, double lo, double hi) const {
    std::ostringstream m;
    m << prefix_ << ": " << field << ": expected a number in [" << lo << ", " << hi << "], got " << v;
    throw SceneError(m.str());
  }
  std::string prefix_;
};

}  // namespace

namespace {

std::string mib(uint64_t bytes) { return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MiB"; }

// Before anything is built: the totals against the scene limits and the memory budget.
void checkTotals(const SceneDescription& scene, const Checker& c) {
  c.number("settings.memory_budget_mib", scene.settings.memoryBudgetMiB, 0, kMaxMemoryBudgetMiB);
  const SceneTotals t = sceneTotals(scene);
  const std::string declared = std::to_string(t.bodies) + " bodies in all (" + std::to_string(scene.grids.size()) + " grids, " +
                               std::to_string(scene.spawners.size()) + " spawners, " + std::to_string(scene.terrains.size()) + " terrains)";
  if (t.bodies > kMaxTotalBodies)
    c.message("spawners", "the scene declares " + declared + ", more than the " + std::to_string(kMaxTotalBodies) + " a scene may hold");
  const uint64_t budget = memoryBudgetBytes(scene.settings);
  if (t.bytes > budget) {
    const std::string whose = scene.settings.memoryBudgetMiB > 0 ? "settings.memory_budget_mib"
                                                                   : "half of this machine's " + mib(physicalMemoryBytes()) +
                                                                         "; settings.memory_budget_mib sets it";
    c.message("settings.memory_budget_mib", "the scene needs an estimated " + mib(t.bytes) + " (" + declared + " x " +
                                                std::to_string(kBytesPerBody) + " B, " + std::to_string(t.listedBricks) +
                                                " listed bricks x " + std::to_string(kBytesPerListedBrick) + " B, " +
                                                std::to_string(t.generatedVoxels) + " generated voxels x " +
                                                std::to_string(kBytesPerGeneratedVoxel) + " B), over the memory budget of " +
                                                mib(budget) + " (" + whose + ")");
  }
}

}  // namespace

void validateScene(const SceneDescription& scene) {
  const Checker c(scene);
  checkTotals(scene, c);
  const SceneSettings& s = scene.settings;
  c.vector("settings.gravity", s.gravity, -kMaxGravity, kMaxGravity);
  c.number("settings.timestep", s.timestep, kMinTimestep, kMaxTimestep);
  c.number("settings.substeps", s.substeps, 1, kMaxSubsteps);
  c.number("settings.solver_iterations", s.solverIterations, 1, kMaxSolverIterations);
  c.number("settings.lod_fraction", s.lodFraction, 0, 1);
  c.number("settings.approximation_depth", s.approximationDepth, 0, kMaxApproximationDepth);
  c.number("settings.relax_iterations", s.relaxIterations, 0, kMaxRelaxIterations);
  c.number("settings.rolling_resistance", s.rollingResistance, 0, 1);
  c.number("settings.depenetration_speed", s.depenetrationSpeed, 0.01, kMaxSpeed);
  c.number("settings.manifold_size", s.manifoldSize, 1, kMaxManifoldSize);
  c.number("settings.reuse_translation", s.reuseTranslation, 0, 1);
  c.number("settings.reuse_rotation", s.reuseRotation, 0, 1);
  for (size_t i = 0; i < scene.grids.size(); ++i) {
    const GridDescription& g = scene.grids[i];
    const std::string f = "grids[" + std::to_string(i) + "]";
    if (g.name.empty()) c.message(f + ".name", "expected a non-empty name");
    c.number(f + ".scale", g.scale, kMinScale, kMaxScale);
    c.number(f + ".tiles[0]", g.tilesX, 1, kMaxTilesPerAxis);
    c.number(f + ".tiles[1]", g.tilesY, 1, kMaxTilesPerAxis);
    c.number(f + ".tile_gap", g.tileGap, 0, kMaxTileGap);
    c.vector(f + ".position", g.position, -kMaxCoordinate, kMaxCoordinate);
    c.unitQuaternion(f + ".rotation", g.rotation);
    c.vector(f + ".linear_velocity", g.kinematic.linearVelocity, -kMaxSpeed, kMaxSpeed);
    c.vector(f + ".angular_velocity", g.kinematic.angularVelocity, -kMaxAngularSpeed, kMaxAngularSpeed);
    if (g.generator.empty() && g.file.empty() && g.bricks.empty()) c.message(f, "has no generator, file or bricks");
  }
  for (size_t i = 0; i < scene.spawners.size(); ++i) {
    const SpawnerDescription& sp = scene.spawners[i];
    const std::string f = "spawners[" + std::to_string(i) + "]";
    c.number(f + ".count", sp.count, 0, kMaxSpawnCount);
    c.vector(f + ".half_extents", sp.halfExtents, kMinSize, kMaxSize);
    c.number(f + ".radius", sp.radius, kMinSize, kMaxSize);
    c.number(f + ".half_height", sp.halfHeight, 0, kMaxSize);
    c.number(f + ".density", sp.density, kMinDensity, kMaxDensity);
    c.vector(f + ".region.min", sp.regionMin, -kMaxCoordinate, kMaxCoordinate);
    c.vector(f + ".region.max", sp.regionMax, -kMaxCoordinate, kMaxCoordinate);
    for (int k = 0; k < 3; ++k)
      if (sp.regionMin[k] > sp.regionMax[k]) c.message(f + ".region", std::string("min.") + "xyz"[k] + " is greater than max." + "xyz"[k]);
    c.vector(f + ".velocity", sp.velocity, -kMaxSpeed, kMaxSpeed);
    if (sp.shape == SpawnerDescription::Shape::Grid) {
      bool found = false;
      for (const GridDescription& g : scene.grids) found = found || g.name == sp.grid;
      if (!found) c.message(f + ".grid", "expected the name of a grid declared in grids, got '" + sp.grid + "'");
    }
  }
  for (size_t i = 0; i < scene.terrains.size(); ++i) {
    const TerrainDescription& t = scene.terrains[i];
    const std::string f = "terrains[" + std::to_string(i) + "]";
    c.number(f + ".voxel_size", t.voxelSize, kMinVoxelSize, kMaxVoxelSize);
    c.vector(f + ".position", t.position, -kMaxCoordinate, kMaxCoordinate);
    c.number(f + ".water_density", t.waterDensity, kMinWaterDensity, kMaxWaterDensity);
    if (t.waterFirst >= 0 && (t.waterFirst > t.waterLast || t.waterLast > 255)) c.message(f + ".water", "expected 1 <= first <= last <= 255");
    if (t.file.empty() == t.generator.empty()) c.message(f, "expected exactly one of file and generator");
    if (!t.generator.empty() && t.generator != "quarry") c.message(f + ".generator", "expected \"quarry\", got '" + t.generator + "'");
    if (!t.generator.empty() && (t.size.x < 32 || t.size.y < 32 || t.size.z < 16 || t.size.x > kMaxGeneratedTerrain ||
                                 t.size.y > kMaxGeneratedTerrain || t.size.z > kMaxGeneratedTerrain))
      c.message(f + ".size", "expected at least 32 x 32 x 16 and at most " + std::to_string(kMaxGeneratedTerrain) + " voxels a side");
    if (t.anchorBelow < 0) c.message(f + ".anchor_below", "expected a height of 0 or more (model voxels)");
  }
  for (size_t i = 0; i < scene.grids.size(); ++i) {
    const GridDescription& g = scene.grids[i];
    if (!g.split) continue;
    const std::string f = "grids[" + std::to_string(i) + "].split";
    // note: a template's bricks are shared by every copy; which copy a removal splits is not defined.
    for (const SpawnerDescription& sp : scene.spawners)
      if (sp.shape == SpawnerDescription::Shape::Grid && sp.grid == g.name) c.message(f, "a grid that spawners copy cannot split");
  }
  c.number("rays.length", scene.rays.length, 0, kMaxRayLength);
  for (size_t i = 0; i < scene.edits.size(); ++i) {
    const EditLoadDescription& e = scene.edits[i];
    const std::string f = "edits[" + std::to_string(i) + "]";
    if (e.grid.empty() == e.terrain.empty()) c.message(f, "expected exactly one of grid and terrain");
    if (!e.grid.empty() && std::none_of(scene.grids.begin(), scene.grids.end(), [&](const GridDescription& g) { return g.name == e.grid; }))
      c.message(f + ".grid", "expected the name of a grid declared in grids, got '" + e.grid + "'");
    if (!e.terrain.empty()) {
      if (std::none_of(scene.terrains.begin(), scene.terrains.end(), [&](const TerrainDescription& t) { return t.name == e.terrain; }))
        c.message(f + ".terrain", "expected the name of a terrain declared in terrains, got '" + e.terrain + "'");
      if (e.kind != EditLoadDescription::Kind::Carve) c.message(f + ".kind", "terrains are carved only (\"carve\")");
      c.vector(f + ".region.min", e.regionMin, -kMaxCoordinate, kMaxCoordinate);
      c.vector(f + ".region.max", e.regionMax, -kMaxCoordinate, kMaxCoordinate);
      for (int a = 0; a < 3; ++a)
        if (e.hasRegion && e.regionMin[a] > e.regionMax[a]) c.message(f + ".region", "min is above max along " + std::string(1, "xyz"[a]));
    }
    c.number(f + ".per_frame", e.perFrame, 1, kMaxEditsPerFrame);
    c.number(f + ".every", e.every, 1, UINT32_MAX);
    if (e.lastFrame < e.firstFrame) c.message(f + ".last_frame", "is before first_frame");
    c.number(f + ".radius", e.radius, kMinSize, kMaxSize);
    c.vector(f + ".brick_half_size", e.brickHalfSize, kMinSize, kMaxSize);
    c.number(f + ".wall_length", e.wallLength, 1, kMaxWallLength);
  }
  auto declared = [&](const std::string& name) {
    return std::any_of(scene.grids.begin(), scene.grids.end(), [&](const GridDescription& g) { return g.name == name; });
  };
  for (size_t i = 0; i < scene.checks.linked.size(); ++i) {
    const std::vector<std::string>& chain = scene.checks.linked[i];
    const std::string f = "checks.linked[" + std::to_string(i) + "]";
    if (chain.size() < 2) c.message(f, "expected at least 2 grid names (a chain in order)");
    for (size_t k = 0; k < chain.size(); ++k) {
      if (!declared(chain[k])) c.message(f + "[" + std::to_string(k) + "]", "expected the name of a grid declared in grids, got '" + chain[k] + "'");
      if (std::find(chain.begin(), chain.begin() + ptrdiff_t(k), chain[k]) != chain.begin() + ptrdiff_t(k))
        c.message(f + "[" + std::to_string(k) + "]", "'" + chain[k] + "' is already in this chain");
    }
  }
  for (size_t i = 0; i < scene.checks.endsIn.size(); ++i) {
    const SceneChecks::EndsIn& e = scene.checks.endsIn[i];
    const std::string f = "checks.ends_in[" + std::to_string(i) + "]";
    if (!declared(e.grid)) c.message(f + ".grid", "expected the name of a grid declared in grids, got '" + e.grid + "'");
    c.vector(f + ".min", e.min, -kMaxCoordinate, kMaxCoordinate);
    c.vector(f + ".max", e.max, -kMaxCoordinate, kMaxCoordinate);
    for (int a = 0; a < 3; ++a)
      if (e.min[a] > e.max[a]) c.message(f, "min is above max along " + std::string(1, "xyz"[a]));
  }
  if (scene.attachments.enabled) {
    c.number("attachments.render_chunk", scene.attachments.renderChunk, kMinRenderChunk, kMaxRenderChunk);
    c.number("attachments.batch_capacity.primitives", scene.attachments.batchPrimitives, 0, kMaxBatchCapacity);
    c.number("attachments.batch_capacity.lights", scene.attachments.batchLights, 0, kMaxBatchCapacity);
  }
}

}  // namespace bw
