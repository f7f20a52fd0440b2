#pragma once
/// The baseline brickworld is measured against: the same scene in Bullet 3.24's
/// btDiscreteDynamicsWorld, from a built World's initial state (bodies exactly where the World
/// put them, a body being pushed out of solid at its spawn place with its spawn velocity), with
/// the same gravity, time step, substeps, solver iterations and the same ray load fired through
/// btCollisionWorld::rayTest, so the two runs do the same job.
///
/// Two setups (DESIGN.md "Baselines"):
/// - Expert (`--engine bullet`): as a Bullet user ships it. Static grids as chunk compounds
///   (one static object per chunk of `chunkSize` metres, one shared shape per distinct brick,
///   wedges and oval cylinders as hulls, round cylinders as cylinders:
///   collision/bricks/bullet_brick_shapes.h); a dynamic or kinematic grid as one body whose
///   compound holds its chunk compounds; CCD on every dynamic primitive (motion threshold its
///   smallest half extent, swept sphere 0.4 of it, inside the shape as Bullet asks); the same
///   friction rule (Bullet multiplies the two coefficients, so each object gets the square root
///   of ours: sqrt(fa) sqrt(fb) = sqrt(fa fb)), restitution the same way above the same bounce
///   threshold, rolling friction on spheres and capsules matching ours; split impulse on,
///   setForceUpdateAllAabbs(false).
/// - Naive (`--engine bullet-naive`): the article's "compounds" point: each grid one
///   btCompoundShape with one btBoxShape per brick (every brick as its box), no CCD, Bullet's
///   defaults otherwise.
///
/// Edits (the scene's edit load and the splits it causes) are mirrored by the expert setup from
/// a judge World that makes them (applyEdits()). Voxel terrain is not mirrored: a scene with a
/// terrain is refused (SceneError).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "world/world.h"

namespace bw {

enum class BulletSetup : uint8_t { Expert, Naive };

/// How the expert setup holds a kinematic grid. Compound: one kinematic body whose compound
/// holds the chunk compounds (every pair with it checks each chunk's box each step:
/// btCompoundCollisionAlgorithm). ChunkBodies: one kinematic body per chunk, all moved with the
/// grid's pose each frame (each chunk's broadphase box updated each step instead). Auto:
/// ChunkBodies when the scene has kChunkBodiesFrom dynamic bodies or more. Measured
/// (profiles/RESULTS.md, session 9): ship_refit (2000 crates on a 3000-chunk carrier) 2.5x
/// faster a frame with chunk bodies; truck_in_station (a truck and 24 crates in a rotating
/// station) 2.5x slower.
enum class KinematicGrids : uint8_t { Auto, Compound, ChunkBodies };

/// "auto", "compound" or "chunks"; and back (InvalidInput for another name).
const char* kinematicGridsName(KinematicGrids k);
KinematicGrids kinematicGridsFromName(const std::string& name);

/// "expert" or "naive".
const char* bulletSetupName(BulletSetup setup);

/// Figures of Bullet's last frame, read from its manifolds and rays (outside step()'s timing).
struct BulletFrame {
  uint32_t contacts = 0;   ///< points in the dispatcher's manifolds
  float deepest = 0;       ///< largest penetration of a manifold point (m), 0 without any
  uint32_t rays = 0, rayHits = 0;
};

class BulletBaseline {
 public:
  /// Chunk edge chosen by measurement: of 2, 4, 8, 16 and 32 m, 16 m gave the fastest median
  /// frame on crates_on_grid, city_rain and lighthouse together (profiles/RESULTS.md, session 5).
  static constexpr float kDefaultChunkSize = 16.f;

  /// Throws SceneError when the scene holds what the setup does not mirror (voxel terrain; for
  /// the naive setup, edits and splits).
  static void requireMirrorable(const SceneDescription& scene, BulletSetup setup = BulletSetup::Expert);
  /// Mirrors `world`'s bodies (call before stepping the World). SceneError for a scene with a
  /// voxel terrain; InvalidInput for a chunk size that is not positive and finite.
  BulletBaseline(const World& world, BulletSetup setup, float chunkSize = kDefaultChunkSize,
                 KinematicGrids kinematic = KinematicGrids::Auto);
  /// Dynamic bodies from which Auto holds kinematic grids as chunk bodies.
  static constexpr uint32_t kChunkBodiesFrom = 256;
  /// How kinematic grids were held (Auto resolved).
  KinematicGrids kinematicGrids() const;
  ~BulletBaseline();
  /// One frame: kinematic bodies moved to the frame's end pose, the scene's time step in its
  /// substeps, then the scene's ray load.
  void step();
  /// The judge's last edits (World::applyFrameEdits() with recordEdits(true), on the World this
  /// baseline was built from), made on Bullet's objects as a Bullet user makes them: each brick
  /// a child added to or removed from its chunk compound (a chunk made or dropped as it fills
  /// or empties), each edited chunk's AABB recalculated once, a static chunk's broadphase box
  /// refreshed, a moving grid's parent compound entry refreshed, a dynamic grid's mass,
  /// centre and inertia set again, bodies near edited chunks woken; each split part a new
  /// dynamic body of its own chunks. Call before step(). SceneError for the naive setup
  /// (it does not mirror edits).
  void applyEdits(const World& judge);
  /// Seconds the last applyEdits() took.
  double lastEditSeconds() const;
  /// Split parts made into bodies so far.
  uint32_t partsMade() const;
  /// Bricks Bullet's chunks hold for World grid `grid` (0 for one not mirrored as chunks).
  uint64_t bricksMirrored(uint32_t grid) const;
  /// The last frame's contacts, deepest penetration and ray hits.
  BulletFrame lastFrame() const;
  /// Seconds Bullet spent building its shapes and objects.
  double buildSeconds() const { return buildSeconds_; }
  /// Static chunk objects in the world and distinct shared brick shapes (0 for the naive setup's shapes).
  uint32_t chunkObjects() const;
  size_t distinctBrickShapes() const;
  /// Every body's centre of mass and rotation, in World body order.
  void poses(std::vector<Vec3d>& positions, std::vector<Quatf>& rotations) const;
  /// Dynamic bodies slower than 5 cm/s, the others, and the lowest dynamic centre.
  void restingReport(uint32_t& resting, uint32_t& moving, double& lowestZ) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double buildSeconds_ = 0;
};

}  // namespace bw
