// Scene building: grids (generators, saves, brick lists, tiling), terrains from MagicaVoxel
// models, spawners of primitives and grid copies, and each body's mass and frame. Content
// errors name the scene, the grid or terrain, and the file.
#include <algorithm>

#include "collision/content/brs_reader.h"
#include "collision/content/build_generators.h"
#include "collision/content/build_tiling.h"
#include "collision/content/terrain_generator.h"
#include "collision/content/vox_reader.h"
#include "collision/core/argument_checks.h"
#include "collision/core/seeded_random.h"
#include "world/body_mass.h"
#include "world/scene_file.h"
#include "world/world.h"

namespace bw {

// Bricks of a grid description: a generator's build, a save's bricks, or the listed ones, then
// tiled when asked. Content errors name the scene, the grid and the file.
std::vector<Brick> World::gridBricks(const GridDescription& g, std::vector<BuildLight>& lights) const {
  std::vector<Brick> bricks;
  Aabb bounds = Aabb::empty();
  try {
    if (!g.file.empty()) {
      BrsLoadResult save = loadBrs(g.file);
      bricks = std::move(save.bricks);
      lights = std::move(save.lights);
      bounds = save.bounds;
    } else if (!g.generator.empty()) {
      GeneratedBuild build = generateBuild(g.generator, g.seed, g.scale);
      bricks = std::move(build.bricks);
      lights = std::move(build.lights);
      bounds = build.bounds;
    } else {
      return g.bricks;
    }
    if (g.tilesX > 1 || g.tilesY > 1) {
      bricks = tileBuild(bricks, bounds, g.tilesX, g.tilesY, g.tileGap);
      lights = tileLights(lights, bounds, g.tilesX, g.tilesY, g.tileGap);
    }
  } catch (const InvalidInput& e) {
    throw SceneError(scene_.source + ": grid '" + g.name + "': " + e.what());
  }
  if (bricks.empty()) throw SceneError(scene_.source + ": grid '" + g.name + "': has no bricks with collision");
  return bricks;
}

void World::buildGrid(const GridDescription& g) {
  std::vector<BuildLight> lights;
  const std::vector<Brick> bricks = gridBricks(g, lights);
  // The pool (a virtual reservation) holds the bricks the scene's edit load places over four
  // times the scene's frames (a longer `run --frames` ends with a clear pool-full error).
  uint64_t reserve = bricks.size() + 1024;
  for (const EditLoadDescription& e : scene_.edits)
    if (e.grid == g.name) reserve += plannedPlacements(e, 4ull * scene_.settings.frames);
  auto grid = std::make_unique<BrickGrid>(BrickGrid::Config(uint32_t(std::min<uint64_t>(reserve, 1u << 28))));
  // note: one by one, not placeBricks: the bulk-loaded index numbers its elements in another
  // order, which changes the order of contacts and so every recorded state hash.
  for (const Brick& b : bricks) grid->placeBrick(b);
  links_.push_back(g.split ? std::make_unique<BrickConnectivity>(*grid) : nullptr);
  linksStale_.push_back(0);
  splitSeeds_.emplace_back();
  debrisBricks_.push_back(g.debrisBricks);
  grids_.push_back(std::move(grid));
  gridNames_.push_back(g.name);
  gridLights_.push_back(std::move(lights));
  addGridBody(uint32_t(grids_.size() - 1), g.position, g.rotation, g.motion, g.kinematic.linearVelocity, g.kinematic.angularVelocity);
}

void World::buildTerrain(const TerrainDescription& t) {
  if (!t.generator.empty()) {
    // A generated terrain (terrain_generator.h): its voxel (0, 0, 0) corner at the position.
    auto terrain = std::make_unique<Terrain>(t.size, t.voxelSize, RigidTransform{t.position, Quatf::Identity()});
    terrain->edit({0, 0, 0}, {t.size.x - 1, t.size.y - 1, t.size.z - 1}, [&](VoxelTerrain& v) { generateQuarry(v, uint32_t(t.seed)); });
    addTerrainBody(std::move(terrain), t, t.anchorBelow);
    return;
  }
  VoxMaterialMap materials;
  if (t.waterFirst >= 0) {
    materials.waterFirst = t.waterFirst;
    materials.waterLast = t.waterLast;
  }
  VoxTerrainOptions options;
  options.voxelSize = t.voxelSize;
  VoxTerrain built;
  try {
    built = buildVoxTerrain(loadVox(t.file), materials, options);
  } catch (const InvalidInput& e) {
    throw SceneError(scene_.source + ": terrain '" + t.name + "': " + e.what());
  }
  // The scene places the model's voxel (0, 0, 0) corner; the terrain adds a margin of air
  // around the model, so its own origin sits that margin lower.
  const Vec3d margin(built.voxToTerrain.x, built.voxToTerrain.y, built.voxToTerrain.z);
  built.terrain->setPlacement(RigidTransform{t.position - margin * double(t.voxelSize), Quatf::Identity()});
  addTerrainBody(std::move(built.terrain), t, t.anchorBelow + built.voxToTerrain.z);
}

void World::addTerrainBody(std::unique_ptr<Terrain> terrain, const TerrainDescription& t, int32_t anchorZ) {
  BodyShape shape;
  shape.terrain = uint32_t(terrains_.size());
  terrains_.push_back(std::move(terrain));
  waterDensity_.push_back(t.waterDensity);
  terrainBreaks_.push_back({t.breakFree, anchorZ, t.debrisVoxels});
  const RigidTransform& placement = terrains_.back()->placement();
  bodies_.add(placement.translation, placement.rotation, MotionType::Static, shape, 0.f, Vec3f::Zero());
}

uint32_t World::addGridBody(uint32_t gridIndex, const Vec3d& position, const Quatf& rotation, MotionType motion,
                            const Vec3d& linearVelocity, const Vec3f& angularVelocity) {
  BodyShape shape;
  shape.grid = gridIndex;
  const BrickGrid& grid = *grids_[gridIndex];
  uint32_t id;
  if (motion != MotionType::Dynamic) {
    // Static and kinematic grids move about their own origin (a station spins about its hub).
    id = bodies_.add(position, rotation, motion, shape, 0.f, Vec3f::Zero());
  } else {
    // Body frame = centre of mass with principal axes; the grid sits inside it.
    const GridBodyFrame frame = gridBodyFrame(grid.massProperties());
    const RigidTransform bodyPose = RigidTransform{position, rotation} * frame.bodyInGrid;
    id = bodies_.add(bodyPose.translation, bodyPose.rotation, motion, shape, frame.inverseMass, frame.inverseInertia,
                     frame.bodyInGrid.inverse());
  }
  bodies_.linearVelocity[id] = linearVelocity.cast<float>();
  bodies_.angularVelocity[id] = angularVelocity;
  return id;
}

void World::spawn(const SpawnerDescription& s) {
  SeededRandom r(s.seed);
  for (uint32_t k = 0; k < s.count; ++k) {
    // note: every draw in its own statement (argument evaluation order is unspecified in C++:
    // GCC and clang differ), so a scene spawns the same bodies whatever the compiler.
    const double px = r.uniform(s.regionMin.x(), s.regionMax.x());
    const double py = r.uniform(s.regionMin.y(), s.regionMax.y());
    const double pz = r.uniform(s.regionMin.z(), s.regionMax.z());
    const Vec3d p(px, py, pz);
    const float angle = float(r.uniform(0, 6.283));  // a random turn about a random axis (6.283 ~ 2 pi)
    const float ax = float(r.normal());
    const float ay = float(r.normal());
    const float az = float(r.normal());
    const Quatf q = Quatf(Eigen::AngleAxisf(angle, Vec3f(ax, ay, az).normalized())).normalized();
    if (s.shape == SpawnerDescription::Shape::Grid) {
      // Grid copies keep their template's orientation (a ship is loaded upright); primitives
      // get a random one.
      const auto it = std::find(gridNames_.begin(), gridNames_.end(), s.grid);
      addGridBody(uint32_t(it - gridNames_.begin()), p, Quatf::Identity(), MotionType::Dynamic, s.velocity, Vec3f::Zero());
      continue;
    }
    BodyShape shape;
    shape.primitive = s.shape == SpawnerDescription::Shape::Sphere  ? QueryShape::sphere(s.radius)
                      : s.shape == SpawnerDescription::Shape::Capsule ? QueryShape::capsule(s.radius, s.halfHeight)
                                                                       : QueryShape::box(s.halfExtents);
    float invMass;
    Vec3f invI;
    primitiveMass(shape.primitive, s.density, invMass, invI);
    const uint32_t id = bodies_.add(p, q, MotionType::Dynamic, shape, invMass, invI);
    bodies_.linearVelocity[id] = s.velocity.cast<float>();
  }
}

}  // namespace bw
