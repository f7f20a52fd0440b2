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
/// Voxel terrain is not mirrored: a scene with a terrain is refused (SceneError).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "world/world.h"

namespace bw {

enum class BulletSetup : uint8_t { Expert, Naive };

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

  /// Throws SceneError when the scene holds what the baseline does not mirror (voxel terrain).
  static void requireMirrorable(const SceneDescription& scene);
  /// Mirrors `world`'s bodies (call before stepping the World). SceneError for a scene with a
  /// voxel terrain; InvalidInput for a chunk size that is not positive and finite.
  BulletBaseline(const World& world, BulletSetup setup, float chunkSize = kDefaultChunkSize);
  ~BulletBaseline();
  /// One frame: kinematic bodies moved to the frame's end pose, the scene's time step in its
  /// substeps, then the scene's ray load.
  void step();
  /// The last frame's contacts, deepest penetration and ray hits.
  BulletFrame lastFrame() const;
  /// Seconds Bullet spent building its shapes and objects.
  double buildSeconds() const { return buildSeconds_; }
  /// Static chunk objects and distinct shared brick shapes (0 for the naive setup's shapes).
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
