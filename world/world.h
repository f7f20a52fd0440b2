#pragma once
/// The world: bodies built from a scene, stepped as broadphase -> contacts per pair (parallel,
/// one slot per pair) -> sequential-impulse solve -> integration, on a JobSystem with a chosen
/// thread count, then (scenes with attachments) the render frame: transform update, submission
/// and commit to a render thread (world_render.h). Results do not depend on the thread count
/// (see stateHash()).
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
/// body) and solved colour by colour on every thread, sleeping, and substeps; per-body stages,
/// solver preparation and island building run in parallel too. Terrain pairs are planned from
/// cached chunk meshes and collided in pieces in parallel (the cache is filled on one thread);
/// water voxels float bodies. Grids of up to kBrickwiseGridBricks bricks meet grids and
/// terrains brick by brick. Each step first makes the scene's edits (edit_load.h), splits parts
/// that lost their joints into bodies, carves terrains and lets cut-off regions break free
/// (terrain_breaks.cpp). Bodies that start inside solid are pushed out or refused
/// (depenetration.h). Thread safety: one step() at a time; editGrid() and probeContacts() only
/// between steps.
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "collision/bricks/brick_grid.h"
#include "collision/content/build_light.h"
#include "collision/terrain/terrain.h"
#include "collision/terrain/terrain_contacts.h"
#include "jobs/job_system.h"
#include "jobs/profiler.h"
#include "world/body_store.h"
#include "world/incremental_broadphase.h"
#include "world/containment.h"
#include "world/contact_solver.h"
#include "world/depenetration.h"
#include "collision/bricks/brick_connectivity.h"
#include "world/body_box_index.h"
#include "world/edit_load.h"
#include "world/edit_log.h"
#include "world/islands.h"
#include "world/pair_cache.h"
#include "world/pose_boxes.h"
#include "world/ray_load.h"
#include "world/scene_description.h"
#include "world/sleeping.h"
#include "world/terrain_carve_load.h"
#include "world/terrain_pair_work.h"
#include "collision/terrain/voxel_regions.h"
#include "world/render_chunks.h"
#include "world/world_render.h"

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
  RenderStageStats render;       ///< frame steps 5-7 (zero without attachments)
  RenderChunkStats renderChunks; ///< render chunks brought up to date with the frame's edits and parts
  double renderChunksMs = 0;     ///< that upkeep (counted in the render update's stage)
  double editMs = 0;             ///< the frame's edits: bricks placed and removed (index, mass), then wakes, body mass, pair caches
  double editLoadMs = 0;         ///< the scene's edit load choosing what to edit (random picks, free-spot checks)
  uint32_t bricksRemoved = 0, bricksPlaced = 0;  ///< by the scene's edit load this frame
  uint32_t editsSkipped = 0;     ///< edit load placements with no free spot (or removals of nothing)
  uint32_t splits = 0;           ///< parts split off grids into bodies of their own this frame
  uint32_t debrisBricks = 0;     ///< bricks of parts below a grid's debris_bricks, gone this frame
  double splitMs = 0;            ///< connectivity upkeep and checks, and making the split parts' bodies
  double partBodiesMs = 0;       ///< of splitMs: making the parts' grids and bodies
  uint32_t voxelsCarved = 0;     ///< solid voxels the scene's terrain carves removed this frame
  uint32_t terrainParts = 0;     ///< terrain regions cut off from the anchor that became bodies
  uint32_t debrisVoxels = 0;     ///< voxels of cut-off regions below debris_voxels, gone
  uint64_t voxelsSearched = 0;   ///< voxels the cut-off search visited (its work)
  double terrainEditMs = 0;      ///< terrain carves, the cut-off search, the regions' bodies, wakes
};

class World {
 public:
  /// Builds everything the scene declares. Throws InvalidInput / SceneError on bad content.
  /// A scene with attachments gets a render thread fed in `submission` mode.
  World(const SceneDescription& scene, int threads, SubmissionMode submission = SubmissionMode::Batched);

  /// One frame (settings.timestep seconds), in settings.substeps substeps, then (with
  /// attachments) frame steps 5-7: the moved bodies' attachments updated and submitted, the
  /// frame committed to the render thread, which applies it while the next frame simulates.
  /// A batch overflow throws CapacityExceeded after the frame's physics is done (world_render.h).
  void step();
  /// Frames stepped so far.
  uint32_t frame() const { return frame_; }
  /// Every body, SoA (units in body_store.h). Read between steps.
  const BodyStore& bodies() const { return bodies_; }
  /// Figures of the last step (times in ms, counts summed over its substeps).
  const StepStats& lastStats() const { return stats_; }
  /// The scene as validated and built.
  const SceneDescription& scene() const { return scene_; }
  /// Profiling zones of the steps (Chrome trace, work/span), the render thread's included: with
  /// attachments it first waits until every frame was applied (the render thread records too).
  Profiler& profiler() {
    if (render_) render_->finish();
    return profiler_;
  }
  /// Bricks in all grids (a grid shared by several bodies counts once).
  uint64_t brickCount() const;
  /// Grids in the world, in scene order (spawned grid copies share their template's grid).
  uint32_t gridCount() const { return uint32_t(grids_.size()); }
  /// Grid `index` (< gridCount(), else InvalidInput), shared by every body that is a copy of it.
  const BrickGrid& grid(uint32_t index) const;
  /// Grid `index`'s name (< gridCount(), else InvalidInput): the scene's, or "NAME/partK" and
  /// "TERRAIN/slabK" for the parts split off at run time.
  const std::string& gridName(uint32_t index) const;
  /// The body of the scene's grid named `name` (the first body using it); SceneError when no
  /// grid has that name.
  uint32_t gridBody(const std::string& name) const;
  /// Terrains in scene order, and terrain `index` (< terrainCount(), else InvalidInput).
  uint32_t terrainCount() const { return uint32_t(terrains_.size()); }
  const Terrain& terrain(uint32_t index) const;
  /// Grid `index` (< gridCount(), else InvalidInput) to edit: place or remove bricks between
  /// steps; every body using it sees the edit at the next step, bodies resting on it wake and
  /// its cached contacts are dropped; a dynamic body using it takes the grid's new mass, centre
  /// of mass and inertia, every remaining brick keeping its velocity. Not while step() runs.
  BrickGrid& editGrid(uint32_t index);
  /// What removeBricks did.
  struct RemovalResult {
    uint32_t parts = 0;         ///< parts split off into dynamic bodies
    uint32_t debrisBricks = 0;  ///< bricks of parts below the grid's debris_bricks, gone
    double ms = 0;              ///< from the first removal to the parts' bodies made
    double partBodiesMs = 0;    ///< of ms: making the parts' grids and bodies (the rest: removals and the search)
  };
  /// Removes bricks of grid `index` between steps, as a game's demolition does; on a grid that
  /// splits (GridDescription::split) the parts left without a face joint become dynamic bodies
  /// right away (their ids follow the others'). Bodies on the grid wake, as with editGrid().
  /// InvalidInput (nothing removed) for a bad grid index or a brick id not in the grid.
  RemovalResult removeBricks(uint32_t index, std::span<const uint32_t> bricks);
  /// Hash of every body's position, rotation and velocities (bit patterns): equal hashes mean
  /// bit-identical states. The same for any thread count.
  uint64_t stateHash() const;
  /// Kinetic plus gravitational potential energy of the dynamic bodies, in joules (kg m^2/s^2;
  /// potential measured from the world origin along gravity), for drift checks.
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
  /// Dynamic bodies that started inside solid (pushed out, see depenetration.h).
  uint32_t startedInSolid() const { return startedInSolid_; }
  /// Of those, the ones still on their way out (kinematic until they arrive).
  uint32_t depenetratingCount() const { return uint32_t(depenetrating_.size()); }
  /// Those bodies and their push-outs, in no particular order (a recording marks them in one pass).
  std::span<const Depenetration> depenetrating() const { return depenetrating_; }
  /// Dynamic bodies currently asleep.
  uint32_t sleepingCount() const { return sleep_.count(); }
  /// Whether body `body` (< bodies().size()) is a dynamic body asleep.
  bool asleep(uint32_t body) const { return sleep_.asleep(body); }
  /// Whether point `p` (world) is inside a brick of any grid body but `self`, or in a solid
  /// terrain voxel (containment.h).
  /// staticGrids false leaves static grids out (the containment tracker tests them by the
  /// path instead while they are unedited).
  InsideSolid pointInsideSolid(const Vec3d& p, uint32_t self, bool staticGrids = true) const;
  /// The one grid or terrain body (not `self`) whose last broadphase bounds reach into `box`
  /// (world), or kInvalidIndex when none or several do: the containment tracker keeps the
  /// places of a body riding a moving grid in that grid's frame.
  uint32_t soleSolidReaching(const WorldAabb& box, uint32_t self) const;
  /// Sorts the solid bodies' reach (their last broadphase bounds) along x, so that the point
  /// and path queries above visit only the solids that can reach them (a fleet of 1,500 grid
  /// ships: every containment query looped over all of them). Between steps, on one thread;
  /// step(), setPoses() and a part splitting off make it stale (the queries then visit every
  /// solid, as before the first call). Worlds of a few solids are not indexed.
  void indexSolids();
  /// Whether a grid or terrain body is kinematic or dynamic (containment follows bodies in the
  /// frames of those only).
  bool hasMovingSolid() const;
  /// Sum of the static grids' edit counts: changes whenever one is edited.
  uint64_t staticGridEdits() const;
  /// How many times setPoses() was called: the only way a static grid moves.
  uint64_t posesSetCount() const { return posesSet_; }
  /// Sum of the terrains' change counts (Terrain::changeCount): changes whenever one is edited
  /// or moved.
  uint64_t terrainChanges() const;
  /// A lower bound on the distance from `p` (world) to the nearest brick of any static grid or
  /// solid voxel of any static terrain, capped at `reach` (at two voxels in a terrain, whose
  /// cells are looked at one by one): no static brick and no terrain triangle (they lie on
  /// solid voxels' faces) reaches into the ball of that radius around `p`. Bricks count by
  /// their bounds; a few ulps of the local coordinates are taken off. Reads only, safe on
  /// many threads.
  double staticSolidClearance(const Vec3d& p, double reach) const;
  /// Whether the segment from `from` to `to` (world) crosses a static or kinematic grid or a
  /// terrain. Fills terrain chunk caches as rays do, so not while step() runs.
  bool segmentHitsStatic(const Vec3d& from, const Vec3d& to);
  /// The same against static and kinematic grids only: reads only, safe on many threads.
  /// `only` tests grid body `only` alone; `except` leaves grid body `except` out.
  bool segmentHitsStaticGrid(const Vec3d& from, const Vec3d& to, uint32_t only = kInvalidIndex, uint32_t except = kInvalidIndex) const;
  /// The same against terrains only (fills their chunk caches: one thread, not during step()).
  bool segmentHitsTerrain(const Vec3d& from, const Vec3d& to);
  /// The same through the terrain chunks already built, reading only (safe on many threads):
  /// nullopt when an answer needs a chunk not built yet (then ask segmentHitsTerrain).
  std::optional<bool> segmentHitsBuiltTerrain(const Vec3d& from, const Vec3d& to) const;
  /// The world's job system, for work between steps that reads the world (containment).
  JobSystem& jobs() { return jobs_; }
  /// Whether body `body` came near a grid or terrain body in any substep of the last step: a
  /// pair with one whose query met a brick within the body's reach, or any contact at all
  /// (world.cpp, markNearSolid). A body that did not cannot be inside solid nor have crossed a
  /// surface during that step: each substep's query covers its motion in it.
  bool nearSolidLastStep(uint32_t body) const { return nearSolid_[body] != 0; }
  /// The scene's ray load of the last frame: its rays and their closest hits (empty without one).
  const RayLoad& rayLoad() const { return rayLoad_; }
  /// Body `body`'s broadphase box in its current state (its shape's bounds plus a margin of how
  /// far it can move in a frame), as the next step computes it. InvalidInput for an unknown body.
  WorldAabb broadphaseBounds(uint32_t body) const;
  /// The push-out of a body on its way out of solid (its saved dynamic mass and spawn
  /// velocity), or nullptr when it is not being pushed out.
  const Depenetration* depenetration(uint32_t body) const;
  /// First profiling stage id of the render frame (world_render.h: renderStageKind).
  int renderStage() const { return scene_.settings.substeps * kStagesPerSubstep + 1; }
  /// The render side, or nullptr when the scene declares no attachments.
  const WorldRender* render() const { return render_.get(); }
  /// The render scene after every stepped frame was applied (waits for the render thread).
  /// InvalidInput when the scene declares no attachments.
  const RenderScene& renderScene();
  /// Moves every body to the given centre and rotation (body frame, as bodies().position and
  /// rotation hold them), velocities kept: to follow another engine's run with this world's
  /// queries (the Bullet baseline's containment) or to restore saved poses. Cached contacts are
  /// dropped. Not while step() runs. InvalidInput (nothing moved) when a list's size is not
  /// the body count or a value is not finite.
  void setPoses(const std::vector<Vec3d>& positions, const std::vector<Quatf>& rotations);
  /// A kinematic body's new scripted velocities (world frame), from the next step on: a ship
  /// that turns or changes speed. Bodies asleep riding it meet it again and wake (pairMoves).
  /// Not while step() runs. InvalidInput (nothing changed) for an unknown or non-kinematic body
  /// or a component that is not finite or beyond kMaxSpeed / kMaxAngularSpeed.
  void setKinematicVelocity(uint32_t body, const Vec3f& linear, const Vec3f& angular);
  /// The next frame's edits only (the scene's edit load, then splits, wakes and pair caches),
  /// without simulating it: for a world that follows another engine's run through setPoses()
  /// and must see the same edits (the Bullet baseline's judge). Advances frame(); lastStats()
  /// holds the edit figures (edit, edit load and split times, bricks, splits). Not while
  /// step() runs.
  void applyFrameEdits();
  /// Whether steps record their edits brick by brick into lastEdits() (off: nothing kept).
  void recordEdits(bool on);
  /// The last step's, applyFrameEdits()' or removeBricks()' edits, when recordEdits(true)
  /// (edit_log.h). A step's log starts with what removeBricks() and editGrid() did since the
  /// previous step, so a mirror that reads the log after each step misses nothing.
  const EditLog& lastEdits() const { return editLog_; }

 private:
  // Scene building (scene_build.cpp).
  std::vector<Brick> gridBricks(const GridDescription& g, std::vector<BuildLight>& lights) const;
  void buildGrid(const GridDescription& g);
  void buildTerrain(const TerrainDescription& t);
  void spawn(const SpawnerDescription& s);
  // Render attachments of every body (render_attachments.cpp): built once, then kept in step
  // with edits, splits and new bodies before every render frame.
  AttachmentStore buildAttachments();
  void addBodyAttachments(uint32_t body, AttachmentStore& store, bool setup);
  void refreshAttachments();
  // Lights of grid g whose nearest brick is in `part` (indices into gridLights_[g]), and
  // handing them to the part's grid ng (render_attachments.cpp).
  std::vector<uint32_t> lightsOnPart(uint32_t g, const std::vector<uint32_t>& part) const;
  void moveLights(uint32_t g, uint32_t ng, const std::vector<uint32_t>& lights);
  uint32_t addGridBody(uint32_t gridIndex, const Vec3d& position, const Quatf& rotation, MotionType motion,
                       const Vec3d& linearVelocity, const Vec3f& angularVelocity);
  // Bodies that start inside solid (depenetration.cpp).
  void resolveStartsInSolid();
  float deepestStaticOverlap(uint32_t body, const Vec3d& position, ContactScratch& scratch, std::vector<Contact>& contacts);
  void advanceDepenetration();
  void finishDepenetration();
  std::string bodySource(uint32_t body) const;
  // Bounds and contacts (contact_generation.cpp, terrain_pairs.cpp).
  /// Gravity (velocity += gravityDt) on awake dynamic bodies, then every body's bounds; parallel.
  void computeBounds(const Vec3f& gravityDt, int stage);
  WorldAabb boundsOf(uint32_t body, float& reach) const;
  /// The body's box as boundsOf() grows it, but for its motion relative to `carrier` (the
  /// carrier's velocity at the body taken off; boundsOf() when the carrier does not move): a
  /// crate riding a flying deck moves nowhere near the deck's bricks.
  WorldAabb boundsMovingBeside(uint32_t body, uint32_t carrier) const;
  struct BoxNow {
    Vec3d centre, half;
    double radius;  // from the centre of mass to the farthest corner
    WorldAabb grown(double reach, double timestep) const;
  };
  BoxNow boxNow(uint32_t body) const;
  // The broadphase over proxies (broadphase_proxies.cpp): pairs_ from bounds_.
  void findPairs();
  void generateContacts(float dt);
  void terrainPairs(float dt);
  bool canCollide(uint32_t a, uint32_t b) const;
  void markNearSolid(uint32_t pair);
  /// Whether solid body `solid` can reach into `box` (its last broadphase bounds overlap it).
  bool mayOverlapSolid(uint32_t solid, const WorldAabb& box) const;
  /// Calls visit(solid) for the solid bodies that may reach into `box`, ascending, until it
  /// returns true (indexSolids()); defined in containment.cpp, its only user.
  template <class Visit>
  void visitSolidsReaching(const WorldAabb& box, Visit&& visit) const;
  /// A grid or terrain body (what another body can be inside of).
  bool isSolid(uint32_t body) const { return bodies_.shape[body].isGrid() || bodies_.shape[body].isTerrain(); }
  /// The fastest the pair's surfaces can approach (m/s): relative speed plus both spins times radii.
  float closingSpeed(uint32_t a, uint32_t b) const;
  /// Whether the pair's relative pose can change this substep, so it needs contacts: one body is
  /// an awake dynamic one, or the two (kinematic, static or asleep) move unalike. An asleep body
  /// moves with the velocity it fell asleep with, its carrier's (SleepState): a crate asleep on
  /// a deck in uniform flight rides it with no contact made, one on a deck that turns or changes
  /// speed meets it (and its contacts wake it).
  bool pairMoves(uint32_t a, uint32_t b) const {
    const auto awake = [&](uint32_t x) { return bodies_.motion[x] == MotionType::Dynamic && !sleep_.asleep(x); };
    if (awake(a) || awake(b)) return true;
    return !bodies_.movesAlike(a, b);
  }
  // The step (world.cpp).
  void substep(float dt, int index);
  void integrate(float dt, int stage);
  void applyGridEdits();
  /// The poses of the bodies holding grid, in gridBodies_ order (the edits move none of them).
  void holderPoses(uint32_t grid, std::vector<PoseBoxes>& out) const;
  /// What the edit load must not build into: the dynamic bodies (none if it places nothing).
  EditLoad::Blocked editBlockers();
  /// Split grids edited through editGrid() get their connectivity taken again.
  void refreshStaleLinks();
  /// The edit load's hooks: split grids' connectivity kept, the edit log written (none when
  /// neither is needed).
  EditLoad::Hooks editHooks();
  /// A frame's edits: the edit load, splits, then wakes, masses and pair caches (step's first part).
  void runEdits();
  /// Parts the frame's removals detached from split grids become dynamic bodies (or vanish).
  void splitDetachedParts();
  void makeBodyOfPart(uint32_t grid, const std::vector<uint32_t>& part);
  /// A dynamic body of a grid split off something (a grid part, a terrain region), at `pose`.
  uint32_t addPartBody(std::unique_ptr<BrickGrid> grid, std::unique_ptr<BrickConnectivity> links, uint32_t debris, std::string name,
                       const RigidTransform& pose, const Vec3f& v, const Vec3f& w);
  // Terrain edits (terrain_breaks.cpp): the frame's carves, then regions cut off break free.
  void addTerrainBody(std::unique_ptr<Terrain> terrain, const TerrainDescription& t, int32_t anchorZ);
  void carveTerrains();
  void breakTerrainFree(std::vector<WorldAabb>& changed);
  /// A dynamic grid body's mass, centre of mass and inertia after its grid was edited.
  void refreshGridBodyMass(uint32_t body);
  // Profiling stages per substep: broadphase proxies counted (0), contacts (1), waking touched
  // sleepers (2), solve (3), integrate (4), relax (5), gravity + bounds (6, which runs first),
  // sleeping's two passes (7, 8), the solver's preparation (9: inertia, 10: contacts), islands (11:
  // union, 12: flatten), broadphase proxies' offsets (13) and written (14), the broadphase
  // (kBroadphaseStage, its kStages), terrain pairs
  // (kTerrainStage: select, its offsets and queries, plan, cut, pieces, finish, apply), the pair cache and the other steps between
  // (kContactStepsStage: hulls warmed, match, count, update, solver bodies loaded, stored after
  // the solve and after the relax, counters; then + 8 .. + 13 contacts grouped by island;
  // + 14 .. + 18 the impulses kept for the next substep's warm start: copied, then sorted;
  // + 19, + 20 the solver's contact offsets counted and placed).
  // Every piece of a substep's work is in one of them: work/span sees the whole step.
  static constexpr int kBroadphaseStage = 15;
  static constexpr int kTerrainStage = kBroadphaseStage + IncrementalBroadphase::kStages;
  static constexpr int kContactStepsStage = kTerrainStage + 8;
  static constexpr int kStagesPerSubstep = kContactStepsStage + 21;

  SceneDescription scene_;
  JobSystem jobs_;
  Profiler profiler_;
  std::vector<std::unique_ptr<BrickGrid>> grids_;
  std::vector<std::string> gridNames_;
  std::vector<std::vector<BuildLight>> gridLights_;  // per grid: its build's lights (grid frame)
  // Terrains are static bodies too. Their chunk cache is filled by queries (not thread-safe),
  // so pairs with a terrain are collided on one thread after the parallel pairs.
  std::vector<std::unique_ptr<Terrain>> terrains_;
  std::vector<float> waterDensity_;
  BodyStore bodies_;
  struct PairCounters {
    uint64_t boxTests = 0;
    uint32_t bricksTested = 0, reused = 0;
  };
  std::vector<PairCounters> pairCounters_;  // per job of the counters stage, summed in order
  std::vector<uint8_t> nearSolid_;     // per body: came near a grid or terrain in this step (containment's filter)
  bool boundsCurrent_ = false;         // bounds_ hold every body as it is now (a step ran, no setPoses since)
  std::vector<uint32_t> solidBodies_;  // grid and terrain bodies, ascending (what bodies can be inside)
  BodyBoxIndex solidIndex_;            // solidBodies_' reach, when solidIndexCurrent_ (indexSolids())
  bool solidIndexCurrent_ = false;
  std::vector<Depenetration> depenetrating_;
  std::vector<uint8_t> ghost_;  // per body: on its way out of solid (collides with nothing)
  uint32_t startedInSolid_ = 0;
  std::vector<WorldAabb> bounds_;
  std::vector<uint8_t> isStatic_;
  std::vector<float> reach_;  // per body: speed + spin x radius (m/s), from computeBounds()
  IncrementalBroadphase broadphase_;
  // Broadphase proxies: a large static grid enters the sweep as the boxes covering its bricks a
  // few OctoBVH levels down (BrickGrid::coverBoxes, at most tuning::kCoverBoxes) instead of one box around it all, so a body
  // above a city's streets pairs with the city only near a building; other bodies as their box.
  struct GridCover {
    uint32_t body;
    uint64_t edit;                   // the grid's edit count when the boxes were taken
    std::vector<WorldAabb> boxes;    // world frame, with the broadphase margin
  };
  std::vector<GridCover> covers_;    // one per large static grid body
  /// A large static grid's cover boxes, current (taken again after an edit).
  const std::vector<WorldAabb>& coverOf(uint32_t body);
  // findPairs()'s chunks of bodies: proxies of single boxes, covered grids, the first proxy.
  struct ProxyChunk {
    uint32_t singles = 0, offset = 0;
    std::vector<uint32_t> covered;
  };
  std::vector<ProxyChunk> proxyChunks_;
  std::vector<WorldAabb> proxyBounds_;
  std::vector<uint8_t> proxyStatic_;
  std::vector<uint32_t> proxyBody_;
  std::vector<Aabb> coverScratch_;
  std::vector<BodyPair> pairs_;
  std::vector<std::vector<Contact>> pairContacts_;  // one slot per pair, reused across frames
  std::vector<ContactScratch> scratch_;             // one per pair slot
  std::vector<uint8_t> pairFlipped_;                // slot's contacts have normal from pair.a to pair.b
  std::vector<uint8_t> pairReused_;                 // slot's contacts came from the pair cache
  std::vector<ContactStats> pairStats_;
  // One per pair with a terrain this substep (terrain_pairs.cpp).
  TerrainPairWork terrainWork_;
  PairCache pairCache_;
  ContactSolver solver_;
  Islands islands_;
  SleepState sleep_;
  RayLoad rayLoad_;
  std::vector<uint32_t> editedGrids_;  // grids edited since the last step (editGrid(), the edit load)
  std::vector<uint32_t> wholeGridEdits_;  // of those, the ones handed out by editGrid()
  BodyBoxIndex editedBoxes_;           // the edit load's bricks of this frame, in the world
  EditLog editLog_;                    // the frame's edits brick by brick (when recordingEdits_)
  EditLog betweenSteps_;               // removeBricks() and editGrid() since the last step: the next log starts with them
  bool recordingEdits_ = false;
  EditLoad editLoad_;                  // the scene's edits, applied at the start of each step
  // Grids that split (GridDescription::split): per grid, its connectivity (null: does not split),
  // the removed bricks' neighbours of this frame, and its debris threshold.
  std::vector<std::unique_ptr<BrickConnectivity>> links_;
  std::vector<uint8_t> linksStale_;    // per grid: edited through editGrid() (links_ not kept)
  std::vector<std::vector<uint32_t>> splitSeeds_;
  std::vector<uint32_t> debrisBricks_;
  uint32_t piecesMade_ = 0;
  BodyBoxIndex editBodies_;            // dynamic bodies' boxes, built when the edit load places bricks
  // Per body, the box editBlockers() took for it this frame, kept for the primitives only
  // (hasEditBounds_): edits between steps move no primitive, so applyGridEdits() reads the same
  // box again rather than computing it twice.
  std::vector<WorldAabb> editBounds_;
  std::vector<uint8_t> hasEditBounds_;
  // Terrains that break (TerrainDescription::breakFree), per terrain; the scene's carves.
  struct TerrainBreak {
    bool breakFree;
    int32_t anchorZ;        // terrain-local voxel z below which voxels are anchored
    uint32_t debrisVoxels;
  };
  std::vector<TerrainBreak> terrainBreaks_;
  TerrainCarveLoad carveLoad_;
  std::vector<TerrainCarve> carves_;   // this frame's
  DetachedVoxelSearch voxelSearch_;
  std::vector<std::vector<uint32_t>> gridBodies_;  // per grid: the bodies holding it (built once)
  // The edits' profiling stage: one serial stage before the substeps' (they run first), below
  // the coloured islands' wave stages.
  static constexpr int kEditStage = 1 << 19;
  StepStats stats_;
  uint32_t frame_ = 0;
  uint64_t posesSet_ = 0;  // setPoses() calls (posesSetCount)
  int stage_ = 0;  // first profiling stage id of the running substep
  // Render chunks of grid bodies (scenes with attachments), and how many bodies have their
  // attachments (later ones get theirs before the next render frame).
  std::unique_ptr<RenderChunks> renderChunks_;
  uint32_t renderedBodies_ = 0;
  std::vector<std::vector<uint32_t>> gridLightIds_;       // per grid: its lights' attachments on its first holder
  std::vector<std::pair<uint32_t, uint32_t>> lightMoves_; // (light attachment, grid) split off since the last render frame
  // Last member: the render thread stops before anything it was fed from goes away.
  std::unique_ptr<WorldRender> render_;
};

}  // namespace bw
