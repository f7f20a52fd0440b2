#pragma once
/// Every tuning constant of the world's step, named, with why it has its value. Scene settings
/// (SceneSettings) are what a scene may change; these are the fixed choices behind them.
#include <algorithm>
#include <cstdint>

namespace bw::tuning {

// --- Jobs ---------------------------------------------------------------------------------
/// A per-item stage is cut into at most this many jobs (and at least its minimum grain per job):
/// four per thread at 16 threads, so a 16-thread machine balances, and the work/span bound read
/// from a 1-thread run is the one that machine meets. With a fixed grain of 1024, city_rain's
/// 2000 bodies made two jobs, and every per-body stage stopped scaling at 2x. The cut depends
/// only on the item count, never on the thread count (determinism).
inline constexpr uint32_t kTargetJobs = 64;
/// A stage too small for 64 jobs of its minimum grain still gets up to kFewestJobs (one per
/// thread at 16), in jobs of no fewer than kSmallestGrain items: a minimum grain of 256 left
/// monument's 261 bodies and 658 pairs in one or two jobs per stage, and at 8 threads those
/// single jobs of 3-8 us were a fifth of its work/span bound. Stages whose minimum grain is
/// kSmallestGrain or less are cut as before. So a stage's "fewest items per job" (the kMin*Grain
/// constants) holds once it has kFewestJobs jobs; below that, jobs go down to kSmallestGrain.
inline constexpr uint32_t kFewestJobs = 16;
inline constexpr uint32_t kSmallestGrain = 32;
inline constexpr uint32_t grainFor(uint32_t items, uint32_t minGrain) {
  const uint32_t forFewest = std::max(kSmallestGrain, (items + kFewestJobs - 1) / kFewestJobs);
  return std::max(std::min(minGrain, forFewest), (items + kTargetJobs - 1) / kTargetJobs);
}

// --- Bodies -------------------------------------------------------------------------------
/// Coulomb friction coefficient of every body (a pair uses sqrt(fa * fb)): rough plastic.
inline constexpr float kDefaultFriction = 0.6f;
/// Fewest bodies per job of the per-body stages (gravity and bounds, integration, sleeping): a
/// body costs tens of nanoseconds, so 32 of them (a microsecond or two) amortise a job's
/// scheduling (a fraction of a microsecond in oneTBB); 128 left scenes of a few hundred bodies
/// (monument) with two or three jobs per stage.
inline constexpr uint32_t kMinBodyGrain = 32;
inline constexpr uint32_t bodyGrain(uint32_t bodies) { return grainFor(bodies, kMinBodyGrain); }
/// Fewest contacts per job of the islands' union-find (a union is a few loads and one
/// compare-and-swap): 64 (was 256, two jobs for monument's few hundred contacts).
inline constexpr uint32_t kMinIslandGrain = 64;

// --- Broadphase and speculative contacts --------------------------------------------------
/// Body bounds grow by this (m) beyond how far the body can move in one frame, so resting
/// bodies keep their pairs through small motions and pairs are not found one frame late.
inline constexpr double kBroadphaseMargin = 0.02;
/// A moving proxy's fat box (IncrementalBroadphase): its bounds grown by kFatMargin (m) and
/// stretched ahead by kFatPrediction updates of its last displacement (at most
/// kFatPredictionLimit m per axis, so a body that jumps does not get a huge box). While its
/// bounds stay inside, its pairs are kept without a query. Stretching by the displacement leaves
/// resting bodies (a pile's jitter) with small boxes, so few pairs that never touch are kept.
/// Chosen by bench_world Broadphase/* and the shipped scenes (profiles/RESULTS.md, session 17):
/// bodies moving 0.02-0.08 m a frame leave 10-12% of their boxes a frame at 2 updates ahead,
/// 5.4% at 16, 3.2% at 32 (1k bodies: 0.065 -> 0.051 ms a frame from 16 to 32; ship_refit's
/// crates riding a ship at 4 m/s: 0.59 -> 0.45 ms).
inline constexpr double kFatMargin = 0.1;
inline constexpr double kFatPrediction = 32.0;
inline constexpr double kFatPredictionLimit = 4.0;
/// A fat box whose slack (its extent beyond the bounds, per axis) is over kFatLoose times what
/// the body's motion now needs is made again: a crate stretched 2.7 m for its fall and then
/// resting on a pile kept pairs with every crate under it (crate_pile: 0.9 ms a frame testing
/// them).
inline constexpr double kFatLoose = 3.0;
/// When more than kFatRebuildShare of the moving proxies, or more than kFatRebuildMoves, left
/// their fat boxes in one update, their tree is built again in bulk (in parallel, and its pairs
/// found by the tree against itself) instead of moving each leaf (serial) and querying it. A
/// leaf's move costs more as the tree outgrows the caches (~0.15 us at 1k leaves, ~1 us at
/// 100k, ~4 us at 1M) where a bulk build costs 0.2-0.4 us a leaf, and the moves are serial:
/// measured (bench_world Broadphase/*, the shipped rains), a share of 0.25 took a few tenths of
/// a millisecond off one-thread rain frames (lighthouse's broadphase p95 1.03-1.15 -> 0.81-0.89
/// ms, the 10k bench row 0.56 -> 0.49 ms) but put crates_on_grid's leaf moves on the critical
/// path (4.5-5.4 ms of its 16-thread bound, 1.7-2.0 at 0.1: bound 7.6-7.7x against 8.8-9.0x).
inline constexpr double kFatRebuildShare = 0.1;
inline constexpr uint32_t kFatRebuildMoves = 25000;
/// A proxy that left its fat box keeps its leaf when at most this many of its ancestors must
/// grow to hold the new box (they grow, and the tree loosens a little); otherwise its leaf is
/// taken out and inserted again. The tree is built again in bulk once the ancestors grown since
/// its last build outnumber its leaves.
inline constexpr uint32_t kFatRefitLevels = 2;
/// Fewest proxies per job of the broadphase's per-proxy stages (a containment test, or a tree
/// query of a moved proxy) and fewest pairs per job of its pair filters.
inline constexpr uint32_t kMinProxyGrain = 256;
inline constexpr uint32_t kMinQueryGrain = 8;
inline constexpr uint32_t kMinPairGrain = 256;
/// Static grids of at least this many bricks enter the broadphase as at most kCoverBoxes boxes
/// covering their bricks (BrickGrid::coverBoxes). 512 measured against 256 and 1024 on
/// crates_on_grid, city_rain and lighthouse: 1024 slows the sweep more than it saves in pairs,
/// 256 leaves more pairs that meet nothing (profiles/RESULTS.md, session 5).
inline constexpr uint32_t kCoverMinBricks = 2048;
inline constexpr uint32_t kCoverBoxes = 512;
/// Contacts are made for gaps up to this (m) plus the pair's closing speed x dt: a resting
/// contact survives micro-separation, and a fast body meets a thin plate before passing it.
inline constexpr float kSpeculativeMargin = 0.01f;

// --- Solver -------------------------------------------------------------------------------
/// Baumgarte factor: the share of the penetration (beyond kSlop) pushed out per step.
inline constexpr float kBaumgarte = 0.2f;
/// Penetration left alone (m): resting contacts keep a little overlap, so they do not flicker.
/// note: bodies settle at up to this depth; 5 mm left capsules 5 mm deep in the floor, and
/// resting within 2 mm is the goal (stacks stay put at 1.5 mm: tested).
inline constexpr float kSlop = 0.0015f;
/// Restitution of impacts faster than kBounceThreshold (m/s); slower ones do not bounce, so
/// resting bodies do not jitter.
inline constexpr float kRestitution = 0.1f;
inline constexpr float kBounceThreshold = 1.0f;
/// Deep overlaps (bodies spawned inside each other or inside terrain) separate at most this
/// fast (m/s): Baumgarte alone would turn a 1 m overlap into a 12 m/s launch.
inline constexpr float kMaxPushOut = 3.0f;
/// Friction's first tangent is built from the normal's y/z (or x/y) components: this threshold
/// on |normal.x| (about 1/sqrt(3)) picks a pair that is never near zero, so it normalises safely.
inline constexpr float kTangentThreshold = 0.57f;
/// Warm starting takes the cached impulse of the same pair and feature whose point lies
/// nearest the new contact, within this radius (m): a contact that slid further starts cold.
inline constexpr double kWarmStartRadius = 0.05;
/// Shock propagation orders two dynamic bodies only when their heights (along gravity) differ
/// by more than this (m); side-by-side bodies are solved as usual.
inline constexpr double kShockHeightEpsilon = 1e-3;

// --- Islands ------------------------------------------------------------------------------
/// Islands with more contacts than this are coloured and solved colour by colour on every
/// thread; smaller ones are solved whole, one island per job.
inline constexpr uint32_t kSplitContacts = 512;
/// Islands of at least this many contacts are first offered to IslandLanes::solveOne (regrouped
/// by level, the lanes of one register on one island); smaller ones share the lanes with other
/// islands (IslandLanes::kLanes at a time).
inline constexpr uint32_t kLaneRegroupContacts = 16;
/// Colours per split island (one bit each in a 64-bit mask); contacts left over form a last,
/// serial group.
inline constexpr uint32_t kMaxColours = 64;
/// Contacts per job when a colour is solved in parallel. Finer cuts shorten the chain of colours
/// a many-threaded machine waits on (crate_pile's bound at 16 threads: 8.6-8.8x at 64,
/// 10.4-10.7x at 32, 11.5-11.7x at 16). With a fork-join per colour they cost more than they
/// saved on two threads (1.28-1.33x at 32 and 16 against 1.63-1.81x at 64, session 8); since
/// the colours run as waves of one parallel region (JobSystem::parallelWaves) 32 measures as 64
/// did (1.72-1.75x, session 18), and 16 a little under (1.66-1.76x) with its chunks of ~0.6 us
/// near what a wave's hand-over costs.
inline constexpr uint32_t kColourGrain = 32;
/// Fewest contacts in a colour's chunk when a small colour is cut for many threads (a chunk's
/// two atomic adds cost about what a few contacts do).
inline constexpr uint32_t kMinColourChunk = 8;
/// Fewest pairs per job of the step's counters (a few loads and adds per pair).
inline constexpr uint32_t kMinCounterGrain = 256;
/// Pairs per job in contact generation (a pair may be a grid query of many bricks).
inline constexpr uint32_t kPairGrain = 4;
/// Fewest items per job of the terrain stages: one (a query's plan or a piece of its triangles).
inline constexpr uint32_t kMinTerrainGrain = 1;
/// Candidate triangles per piece of one terrain query (TerrainPairWork): a box or hull tests each
/// by GJK (and EPA when it touches, a few microseconds), a sphere or capsule in closed form.
/// One triangle a piece for boxes and hulls: on monument, pieces of four put a few EPA triangles
/// in one job (the stage's longest job 14.4 us on average, 10.5 at one a piece; its share of the
/// 16-thread bound 7.1 -> 5.0 ms, profiles/RESULTS.md session 38). A plan places the shape once
/// per chunk, so a finer piece costs only its output's join (quarry -0.2%, monument +0.1% step
/// instructions).
inline constexpr uint32_t kConvexTrianglesPerPiece = 1;
inline constexpr uint32_t kRoundTrianglesPerPiece = 32;
/// Rays per job in the scene's ray load.
inline constexpr uint32_t kRayGrain = 64;

// --- Splits -------------------------------------------------------------------------------
/// From this many bricks a part's grid is built on one thread while the old grid lets its
/// bricks go on another (World::makeBodyOfPart): each half then costs milliseconds, against the
/// few microseconds of waking a thread; below it the three steps run in turn.
inline constexpr uint32_t kParallelPartBricks = 2048;
/// Fewest bricks per job of a part's gather (World::makeBodyOfPart: a brick, its bounds and its
/// element read, each a cache miss asked for ahead).
inline constexpr uint32_t kMinGatherGrain = 1024;

// --- Sleeping -----------------------------------------------------------------------------
/// An island whose bodies all stayed below these speeds (m/s, rad/s) for kSleepTime (s) sleeps.
inline constexpr float kSleepLinear = 0.05f, kSleepAngular = 0.1f, kSleepTime = 0.5f;

// --- Water --------------------------------------------------------------------------------
/// Velocities decay at this rate (1/s) times the submerged fraction, so floating bodies settle
/// instead of bobbing for ever (a crate of half water's density rises at about
/// g / kWaterLinearDrag = 2.5 m/s and does not leap out of the surface).
inline constexpr float kWaterLinearDrag = 4.f, kWaterAngularDrag = 4.f;
/// The centre of buoyancy is estimated from the body's bounding box, so only a body cut by the
/// surface (submerged fraction below this) gets the righting torque; a submerged one would get
/// a spurious torque wherever its box overlaps solid voxels (and spin up without bound).
inline constexpr float kBuoyancyTorqueBelowFraction = 0.98f;

}  // namespace bw::tuning
