#pragma once
/// The world: bodies built from a scene, stepped as broadphase -> contacts per pair (parallel,
/// one slot per pair) -> sequential-impulse solve -> integration, on a JobSystem with a chosen
/// thread count. Results do not depend on the thread count (see stateHash()).
///
///   bw::World world(bw::loadScene("profiles/scenes/crates_on_grid.json"), /*threads*/ 2);
///   for (int f = 0; f < 300; ++f) world.step();
///   std::printf("%016llx\n", (unsigned long long)world.stateHash());
///
/// What it has: static, kinematic and dynamic bodies (primitives, grids shared between copies,
/// voxel terrains), sweep-and-prune broadphase, primitive-vs-grid, grid-vs-grid (convex
/// approximation), box-vs-box manifolds, other primitive pairs and terrain contacts, all with
/// speculative margins, a pair cache, a sequential-impulse solver (friction, restitution, warm
/// starting matched by contact feature, a relax pass after integration), islands solved in
/// parallel, islands above kSplitContacts coloured (no two contacts of a colour share a dynamic
/// body) and solved colour by colour on every thread, sleeping, and substeps. Terrain pairs run
/// on one thread (the chunk cache is filled by queries); water voxels float bodies. Thread
/// safety: one step() at a time; editGrid() and probeContacts() only between steps.
#include <cstdint>
#include <memory>
#include <vector>

#include "collision/bricks/brick_grid.h"
#include "collision/terrain/terrain.h"
#include "jobs/job_system.h"
#include "jobs/profiler.h"
#include "world/body_store.h"
#include "world/broadphase.h"
#include "world/scene_description.h"

namespace bw {

/// Figures of the last step (summed over its substeps).
struct StepStats {
  double broadphaseMs = 0, contactsMs = 0, solverMs = 0, integrateMs = 0, totalMs = 0;
  uint32_t pairs = 0;
  uint32_t contacts = 0;
  uint64_t boxTests = 0;
  uint32_t narrowphase = 0;
  uint32_t pairsReused = 0;   ///< pairs whose contacts came from the pair cache
  double raysMs = 0;          ///< the scene's ray load (once per frame, not per substep)
  uint32_t rays = 0, rayHits = 0;
  uint64_t rayBoxTests = 0;
  uint32_t terrainContacts = 0;  ///< contacts against terrains (included in contacts)
  uint32_t floating = 0;         ///< awake bodies touching water (last substep)
  uint32_t largestIsland = 0;    ///< contacts in the largest island (last substep)
  uint32_t splitIslands = 0;     ///< islands solved colour by colour on every thread
};

class World {
 public:
  /// Builds everything the scene declares. Throws InvalidInput / SceneError on bad content.
  World(const SceneDescription& scene, int threads);

  /// One frame (settings.timestep), in settings.substeps substeps.
  void step();
  uint32_t frame() const { return frame_; }
  const BodyStore& bodies() const { return bodies_; }
  const StepStats& lastStats() const { return stats_; }
  const SceneDescription& scene() const { return scene_; }
  Profiler& profiler() { return profiler_; }
  uint64_t brickCount() const;
  /// The world's grids (shared by every body that is a copy of them).
  const BrickGrid& grid(uint32_t index) const { return *grids_[index]; }
  /// A grid to edit (place or remove bricks) between steps; every body using it sees the edit
  /// at the next step. Not while step() runs.
  BrickGrid& editGrid(uint32_t index) {
    editedGrids_.push_back(index);
    return *grids_[index];
  }
  /// Hash of every body's position, rotation and velocities (bit patterns).
  uint64_t stateHash() const;
  /// Kinetic plus potential energy of the dynamic bodies (for drift checks).
  double energy() const;
  /// Pairs of the last substep and each pair's contacts (normal from the pair's `a` side to
  /// its `b` side unless pairContactsFlipped(k)); for tests and tools.
  const std::vector<BodyPair>& pairs() const { return pairs_; }
  const std::vector<Contact>& pairContacts(uint32_t k) const { return pairContacts_[k]; }
  bool pairContactsFlipped(uint32_t k) const { return pairFlipped_[k] != 0; }
  /// The contacts of the last substep's pairs made again on the current state with other
  /// contact settings, the pair cache bypassed (for accuracy measurements: `brickworld
  /// tradeoff` compares LOD against LOD off at the same state). Pairs with a terrain are left
  /// empty (their query fills the terrain's cache and applies buoyancy). The world's state is
  /// unchanged; the next step() makes its own contacts again. Returns one list per pair().
  const std::vector<std::vector<Contact>>& probeContacts(float lodFraction, int approximationDepth, int manifoldSize,
                                                         uint64_t* boxTests = nullptr);
  /// Dynamic bodies currently asleep.
  uint32_t sleepingCount() const;

 private:
  struct SolverContact {
    uint32_t a, b;         // a receives +impulse along normal, b the opposite
    Vec3d point;
    Vec3f normal;          // from b towards a
    float depth;
    uint64_t key;          // pair and feature, for warm starting
    Vec3f rA, rB, t1, t2;
    // Angular response per unit impulse along n, t1, t2 (inverse inertia x (r x d)), computed
    // once per substep so iterations are multiply-adds.
    Vec3f angA[3], angB[3];
    float massN, massT1, massT2, bias, relaxBias, friction;
    // Shock propagation: effective masses with the lower body immovable, which body is lower
    // along gravity (0 none, 1 a, 2 b) and the contact's height (for the bottom-up order).
    float shockMass[3];
    uint8_t shockLower = 0;
    double height = 0;
    float lambdaN = 0, lambdaT1 = 0, lambdaT2 = 0;
  };
  // A pair's contacts kept in both bodies' frames, reused while their relative pose barely
  // changes (the pair cache): resting piles do not redo narrowphase every step.
  struct CachedContact {
    Vec3f onA, onB;   // contact points in body a's and body b's frames (a, b as in the pair)
    Vec3f normalB;    // normal in b's frame, oriented as the slot stores it
    uint32_t feature, material;
  };
  struct PairCacheEntry {
    BodyPair pair;
    RigidTransform relative;   // b's pose in a's frame when the contacts were made
    uint8_t flipped;
    uint32_t first, count;     // range in pairCacheContacts_
  };
  struct CachedImpulse {
    uint64_t key;
    Vec3d point;
    float n, t1, t2;
  };

  std::vector<Brick> gridBricks(const GridDescription& g) const;
  void buildGrid(const GridDescription& g);
  void fireRays();
  void buildTerrain(const TerrainDescription& t);
  void terrainPairs(float dt);
  void spawn(const SpawnerDescription& s);
  uint32_t addGridBody(uint32_t gridIndex, const Vec3d& position, const Quatf& rotation, MotionType motion,
                       const Vec3d& linearVelocity, const Vec3f& angularVelocity);
  void substep(float dt, int index);
  void computeBounds();
  void generateContacts(float dt);
  void prepareSolver(float dt);
  void solve(bool relax);
  void solveIsland(uint32_t island, bool relax);
  void solveIslandInColours(uint32_t island, bool relax);
  void colourIsland(uint32_t island);
  void applyImpulse(const SolverContact& s, int d, const Vec3f& dir, float lambda);
  void warmStart(const SolverContact& s);
  void loadSolverBodies();
  void storeSolverBodies();
  void solveContact(SolverContact& s, bool relax);
  void solveContactShock(SolverContact& s);
  void shockSweep(std::vector<uint32_t>& contacts);
  // Profiling stages per substep: broadphase, contacts, prepare, solve, integrate, relax.
  static constexpr int kStagesPerSubstep = 6;
  // Islands with more contacts than this are solved colour by colour on every thread.
  static constexpr uint32_t kSplitContacts = 512;
  static constexpr uint32_t kMaxColours = 64;
  static constexpr uint32_t kColourGrain = 64;
  void buildIslands();
  void updateSleep(float dt);
  bool active(uint32_t body) const {
    return bodies_.motion[body] == MotionType::Kinematic || (bodies_.motion[body] == MotionType::Dynamic && !asleep_[body]);
  }
  void integrate(float dt);
  bool canCollide(uint32_t a, uint32_t b) const;

  SceneDescription scene_;
  JobSystem jobs_;
  Profiler profiler_;
  std::vector<std::unique_ptr<BrickGrid>> grids_;
  std::vector<std::string> gridNames_;
  // Terrains are static bodies too. Their chunk cache is filled by queries (not thread-safe),
  // so pairs with a terrain are collided on one thread after the parallel pairs.
  std::vector<std::unique_ptr<Terrain>> terrains_;
  std::vector<float> waterDensity_;
  BodyStore bodies_;
  std::vector<WorldAabb> bounds_;
  std::vector<uint8_t> isStatic_;
  SweepAndPrune broadphase_;
  std::vector<BodyPair> pairs_;
  std::vector<std::vector<Contact>> pairContacts_;  // one slot per pair, reused across frames
  std::vector<ContactScratch> scratch_;             // one per pair slot
  std::vector<uint8_t> pairFlipped_;                // slot's contacts have normal from pair.a to pair.b
  std::vector<ContactStats> pairStats_;
  std::vector<SolverContact> contacts_;
  struct SolverBody {
    Vec3f v;            // 12 linear velocity
    float invMass;      // 4
    Vec3f w;            // 12 angular velocity (world)
    uint32_t dynamic;   // 4  0: static or kinematic (read, never written)
  };
  static_assert(sizeof(SolverBody) == 32);
  std::vector<SolverBody> solverBodies_;
  std::vector<Mat3f> inverseInertiaWorld_;          // per body, this substep
  std::vector<uint32_t> islandOf_;                  // union-find parent per body
  std::vector<uint32_t> islandStart_, islandContacts_;  // contacts grouped by island (CSR)
  std::vector<uint32_t> islandBodiesStart_, islandBodies_;
  std::vector<uint32_t> smallIslands_;              // islands solved whole, in parallel
  std::vector<uint64_t> bodyColours_;               // per body: colours taken (while colouring)
  std::vector<uint32_t> colourOf_, colourStart_, colourContacts_, colourFill_;  // one split island
  std::vector<float> stillTime_;                    // seconds each body has been nearly still
  std::vector<uint8_t> asleep_;
  std::vector<CachedImpulse> cache_, nextCache_;
  std::vector<PairCacheEntry> pairCache_, nextPairCache_;
  std::vector<CachedContact> pairCacheContacts_, nextPairCacheContacts_;
  std::vector<int32_t> pairCacheHit_;  // per pair slot: index into pairCache_ or -1
  void updatePairCache();
  std::vector<uint32_t> editedGrids_;  // grids handed out by editGrid() since the last step
  void applyGridEdits();
  StepStats stats_;
  std::vector<float> rayHitT_;  // per ray of the ray load: closest hit (inf: none)
  std::vector<QueryStats> rayStats_;
  uint32_t frame_ = 0;
  int stage_ = 0;  // first profiling stage id of the running substep
};

}  // namespace bw
