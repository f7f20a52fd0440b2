#pragma once
/// A parsed, validated scene: only what the scene declares (grids, spawners, settings). The
/// world builds exactly this and nothing else. Produced by loadScene (scene_file.h); the JSON
/// schema is documented in profiles/scenes/README.md.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "collision/bricks/brick.h"
#include "collision/bricks/grid_pair.h"
#include "collision/core/math_types.h"
#include "collision/terrain/voxel_chunk.h"

namespace bw {

/// Accepted ranges of scene values: scene files are parsed against them and World validates a
/// SceneDescription built in code against them (validateScene in scene_file.h).
namespace scene_limits {
constexpr double kMaxCoordinate = 1e9;   ///< |world coordinate| (double)
constexpr double kMaxSpeed = 1e4;        ///< |velocity component|, m/s
constexpr double kMaxAngularSpeed = 100; ///< |angular velocity component|, rad/s
constexpr double kMinSize = 1e-3, kMaxSize = 1e4;        ///< primitive half extents and radii
constexpr double kMinDensity = 1e-3, kMaxDensity = 1e5;  ///< kg/m^3 (no zero-mass dynamic bodies)
constexpr double kMinTimestep = 1.0 / 10000, kMaxTimestep = 1.0 / 10;  ///< seconds per frame
constexpr double kMaxGravity = 1000;     ///< |gravity component|, m/s^2
constexpr int kMaxSubsteps = 64, kMaxSolverIterations = 256, kMaxRelaxIterations = 64;
constexpr int kMaxManifoldSize = 64, kMaxApproximationDepth = 7;
constexpr double kMinScale = 0.001, kMaxScale = 64;      ///< generator scale
constexpr int kMaxTilesPerAxis = 1000;
constexpr double kMaxTileGap = 1e5;
constexpr double kMinVoxelSize = 1e-3, kMaxVoxelSize = 1e3;
constexpr double kMinWaterDensity = 1, kMaxWaterDensity = 1e5;
constexpr uint32_t kMaxSpawnCount = 1'000'000;
constexpr double kMaxRayLength = 1e7;
constexpr double kMinRenderChunk = 0.1, kMaxRenderChunk = 1e4;  ///< grid render chunk edge
constexpr uint32_t kMaxBatchCapacity = 1u << 28;                 ///< records per frame in a batch
constexpr uint32_t kMaxEditsPerFrame = 1'000'000;                ///< bricks or holes per edit stream per frame
constexpr uint32_t kMaxWallLength = 100'000;                     ///< bricks per course of an edit wall
constexpr int32_t kMaxGeneratedTerrain = 2048;                   ///< voxels along each axis of a generated terrain
constexpr uint64_t kMaxTotalBodies = 10'000'000;                 ///< bodies a scene declares in all (grids, copies, primitives, terrains)
constexpr double kMaxMemoryBudgetMiB = 1 << 24;                  ///< settings.memory_budget_mib (16 TiB)
}  // namespace scene_limits

/// How a body moves.
enum class MotionType : uint8_t { Static, Kinematic, Dynamic };

/// Scripted motion of a kinematic body: constant velocities (world frame).
struct KinematicMotion {
  Vec3d linearVelocity = Vec3d::Zero();
  Vec3f angularVelocity = Vec3f::Zero();  ///< rad/s about the body's centre
};

/// One grid: bricks from a generator, a Brickadia save or listed explicitly, and its placement.
struct GridDescription {
  std::string name;
  std::string generator;           ///< one of buildNames(), or empty
  float scale = 1.f;
  uint64_t seed = 1;
  std::string file;                ///< a .brs save (path resolved against the scene file), or empty
  int tilesX = 1, tilesY = 1;      ///< the save (or generated build) copied on a tilesX x tilesY grid
  float tileGap = 0.f;             ///< gap between tiles
  std::vector<Brick> bricks;       ///< explicit bricks (when neither generator nor file)
  Vec3d position = Vec3d::Zero();
  Quatf rotation = Quatf::Identity();
  MotionType motion = MotionType::Static;
  KinematicMotion kinematic;
  /// Parts of the grid that a removal leaves without a face-to-face joint to the rest become
  /// dynamic bodies of their own (BrickConnectivity); they split further in turn.
  bool split = false;
  /// With split: parts of fewer bricks than this vanish instead (debris), 0 keeps them all.
  uint32_t debrisBricks = 0;
};

/// Dynamic primitives (or copies of a small grid) spawned in a box region.
struct SpawnerDescription {
  enum class Shape : uint8_t { Sphere, Box, Capsule, Grid };
  Shape shape = Shape::Box;
  std::string grid;                ///< template grid name when shape == Grid
  uint32_t count = 0;
  Vec3f halfExtents = Vec3f::Constant(0.25f);  ///< Box
  float radius = 0.25f;                         ///< Sphere, Capsule
  float halfHeight = 0.25f;                     ///< Capsule
  float density = 1.f;
  Vec3d regionMin = Vec3d::Zero(), regionMax = Vec3d::Zero();
  Vec3d velocity = Vec3d::Zero();
  uint64_t seed = 1;
};

/// A voxel terrain from a MagicaVoxel model (static; solid voxels collide, water voxels float).
struct TerrainDescription {
  std::string name;
  std::string file;                ///< .vox path (resolved against the scene file), or empty
  std::string generator;           ///< "quarry" (terrain_generator.h) when there is no file
  Int3 size{96, 64, 48};           ///< generator: voxels along x, y, z
  uint64_t seed = 1;               ///< generator: its seed
  /// Solid regions that edits cut off from the anchored voxels (model z below anchorBelow:
  /// 1 anchors the bottom layer) become dynamic bodies (World, voxel_regions.h).
  bool breakFree = false;
  int32_t anchorBelow = 1;
  uint32_t debrisVoxels = 0;       ///< with breakFree: regions of fewer voxels vanish instead
  float voxelSize = 1.f;           ///< edge of one voxel in world units
  Vec3d position = Vec3d::Zero();  ///< world position of the model's voxel (0, 0, 0) corner
  int waterFirst = -1, waterLast = -1;  ///< palette index range that is water (-1: none)
  float waterDensity = 1000.f;     ///< kg/m^3, for buoyancy
};

/// Rays fired across the scene's grids every frame (a query load beside the simulation).
struct RayLoadDescription {
  uint32_t count = 0;              ///< rays per frame
  float length = 0.f;              ///< 0: long enough to cross the grids' bounds
  uint64_t seed = 1;
};

/// Render attachments (DESIGN.md frame steps 5-7): every body gets a render proxy, a grid one
/// proxy per render chunk of its bricks and its lights (from the save's light components or the
/// generator's lamps). A scene without this section builds no render thread.
struct AttachmentsDescription {
  bool enabled = false;            ///< the scene declared "attachments"
  float renderChunk = 8.f;         ///< edge of a grid's render chunk (grid-local cells), world units
  bool gridLights = true;          ///< grids carry their builds' lights
  /// Records a frame's batch holds (batched submission); 0 = every primitive / every light.
  uint32_t batchPrimitives = 0, batchLights = 0;
};

/// Edits a scene makes to one of its grids while it runs, between steps (World::step applies a
/// frame's edits before simulating it). Seeded: every run, at any thread count, edits the same
/// bricks in the same order.
struct EditLoadDescription {
  enum class Kind : uint8_t {
    Remove,  ///< perFrame bricks, chosen at random among the grid's bricks
    Place,   ///< perFrame bricks: copies of random bricks laid on top of (or beside) them where free
    Carve,   ///< perFrame holes: every brick whose centre lies within radius of a random brick's
    Wall,    ///< perFrame bricks of a wall rising course by course on top of the grid
  };
  std::string grid;                 ///< name of a grid in grids (or empty: terrain)
  /// Or the name of a terrain in terrains: only Carve, of spheres of `radius` metres centred on
  /// random solid voxels above the anchor inside [regionMin, regionMax] (world; the whole
  /// terrain when hasRegion is false).
  std::string terrain;
  bool hasRegion = false;
  Vec3d regionMin = Vec3d::Zero(), regionMax = Vec3d::Zero();
  Kind kind = Kind::Remove;
  uint32_t perFrame = 1;            ///< bricks (Remove, Place, Wall) or holes (Carve) per edit frame
  uint32_t firstFrame = 0;          ///< the first frame that edits
  uint32_t lastFrame = UINT32_MAX;  ///< the last frame that edits
  uint32_t every = 1;               ///< edit on every this many frames from firstFrame
  float radius = 1.f;               ///< Carve: hole radius, grid units
  Vec3f brickHalfSize = Vec3f(0.5f, 0.25f, 0.25f);  ///< Wall: half size of its bricks
  uint32_t wallLength = 32;         ///< Wall: bricks per course
  uint64_t seed = 1;
};

/// What the world does with a dynamic body that starts inside solid (depenetration.h).
enum class StartInSolid : uint8_t { PushOut, Refuse };

/// Global settings of a run.
struct SceneSettings {
  Vec3d gravity{0, 0, -9.81};
  double timestep = 1.0 / 60.0;  ///< seconds per frame
  int substeps = 1;
  int solverIterations = 8;
  int relaxIterations = 2;           ///< velocity iterations after integration without push-out
  /// Rolling resistance of spheres and capsules: a contact resists rolling with at most this
  /// times the round body's radius times its normal impulse (0 rolls forever).
  float rollingResistance = 0.1f;
  StartInSolid startInSolid = StartInSolid::PushOut;  ///< bodies that start inside solid
  float depenetrationSpeed = 5.f;    ///< m/s at which they are pushed out
  bool shockPropagation = false;     ///< a last bottom-up sweep treating the lower body as immovable
  uint32_t frames = 300;
  float lodFraction = 1.f / 16;
  int approximationDepth = 3;
  /// Grid against grid (grid_pair.h): "convex" (the smaller grid's hull), "two_way" (bricks
  /// against bricks) or "auto" (two-way when the hull overstates the bricks by kAutoTwoWayFill).
  GridPairMode gridPairs = GridPairMode::Convex;
  bool sleeping = true;
  int manifoldSize = 4;              ///< contacts kept per pair after reduction (1..64)
  double reuseTranslation = 1e-3;    ///< pair cache: reuse contacts while the relative pose moved
  float reuseRotation = 1e-3f;       ///< less than this (m, rad) since they were made; 0 disables
  /// The memory a scene may need by its estimate before anything is built (scene_budget.h), in
  /// MiB; 0: half of this machine's physical memory.
  double memoryBudgetMiB = 0;
};

/// What a run checks besides containment (scene_checks.h), for scenes whose point is a shape
/// of motion: chains that must stay linked, ships that must get somewhere.
struct SceneChecks {
  /// Each entry names grids in chain order; each must stay linked to the next (their
  /// oriented bounds overlap at every frame: a link that passed through another falls away).
  std::vector<std::vector<std::string>> linked;
  /// A grid whose centre of mass (its origin when static or kinematic) must end inside a box.
  struct EndsIn {
    std::string grid;
    Vec3d min = Vec3d::Zero(), max = Vec3d::Zero();  ///< world box
  };
  std::vector<EndsIn> endsIn;
};

struct SceneDescription {
  std::string name;
  std::string source;  ///< file it came from
  SceneSettings settings;
  std::vector<GridDescription> grids;
  std::vector<SpawnerDescription> spawners;
  std::vector<TerrainDescription> terrains;
  RayLoadDescription rays;
  AttachmentsDescription attachments;
  std::vector<EditLoadDescription> edits;
  SceneChecks checks;
};

}  // namespace bw
