#pragma once
/// A brick grid: bricks in a virtual pool, an OctoBVH over their exact bounds, and mass
/// properties kept up to date as bricks are placed and removed (no global rebuild, ever).
///
///   bw::BrickGrid grid;
///   uint32_t id = grid.placeBrick(brick);             // validates, indexes, adds mass
///   bw::GridRayHit hit = grid.raycast(localRay, ~0u);   // exact brick shapes
///   grid.collide(gridPose, shape, shapePose, params, scratch, contacts);
///   grid.removeBrick(id);
///
/// Everything inside is float in the grid's local frame; poses and contacts at the API are
/// world-space (double positions) and converted through RigidTransform only.
/// Thread safety: const queries may run concurrently; placeBrick/removeBrick and
/// convexApproximation() (which refreshes a cache) need exclusive access.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "collision/bricks/brick.h"
#include "collision/bricks/brick_geometry.h"
#include "collision/bricks/brick_narrowphase.h"
#include "collision/bricks/contact.h"
#include "collision/bricks/grid_pair.h"
#include "collision/core/ids.h"
#include "collision/core/overwrite_vector.h"
#include "collision/core/rigid_transform.h"
#include "collision/index/octobvh.h"

namespace bw {

/// Mass, centre of mass (grid frame) and inertia tensor about the centre of mass (grid axes).
struct MassProperties {
  double mass = 0;
  Vec3d centerOfMass = Vec3d::Zero();
  Mat3d inertia = Mat3d::Zero();
};

/// A raycast hit on a brick's real shape (grid frame).
struct GridRayHit {
  uint32_t brick = kInvalidIndex;
  float t = 0;
  Vec3f normal = Vec3f::Zero();
  bool hit() const { return brick != kInvalidIndex; }
};

/// A sweep hit: first time of impact as a fraction of the motion, on the brick's real shape.
struct GridSweepHit {
  uint32_t brick = kInvalidIndex;
  float fraction = 1.f;          ///< 0..1 of the motion from -> to
  Vec3f normal = Vec3f::Zero();  ///< from the brick towards the shape
  Vec3f point = Vec3f::Zero();   ///< on the brick
  bool hit() const { return brick != kInvalidIndex; }
};

/// Knobs of a contact query.
struct ContactParams {
  uint32_t mask = 0xFFFFFFFFu;    ///< filter mask against brick filter bits
  float lodFraction = 1.f / 16;   ///< subtrees smaller than this x shape size are solid boxes (0: off)
  float speculativeMargin = 0.f;  ///< also report gaps below this (negative depth)
  int maxContacts = 4;            ///< manifold size after reduction (1..64)
};

/// Counters of one contact query.
struct ContactStats {
  QueryStats index;
  uint32_t bricksTested = 0;   ///< narrowphase calls on bricks
  uint32_t lodBoxes = 0;       ///< subtrees collided as one box
  uint32_t rawContacts = 0;    ///< before manifold reduction
};

/// Reusable buffers for contact queries (one per thread): no allocation once warmed up.
struct ContactScratch {
  std::vector<LocalContact> raw;
  GridPairScratch pair;                      ///< two-way grid pairs (collideGrids)
  std::vector<GridPairContact> pairContacts;
};

/// A grid's convex stand-in for grid-vs-grid collision (grid frame).
struct ConvexApproximation {
  bool isBox = false;             ///< the hull was exactly its bounding box
  Aabb bounds = Aabb::empty();
  std::vector<Vec3f> vertices;    ///< hull vertices (the 8 corners when isBox)
  std::vector<Vec3f> centered;    ///< the same relative to shapeCenter(), for shape()
  Vec3f centeredHalfExtents = Vec3f::Zero();  ///< their bounds (found once: shape() is made for every query)
  double hullVolume = 0;
  double brickVolume = 0;         ///< the bricks' own volume (the hull's fill: hullVolume / this)
  int depth = 0;
  uint32_t inputPoints = 0;       ///< points handed to the hull computer
  QueryShape shape() const;       ///< as a query shape (box centred on the bounds, or hull)
  Vec3f shapeCenter() const;      ///< where shape() is centred in the grid frame
};

/// Tag on LocalContact::feature for contacts against LOD boxes (never a brick id).
constexpr uint32_t kLodFeature = 0x80000000u;

class BrickGrid {
 public:
  struct Config {
    uint32_t maxBricks = 1u << 22;       ///< reservation size (virtual)
    std::array<float, 256> density;      ///< per material
    Config() { density.fill(1.f); }
    explicit Config(uint32_t max) : Config() { maxBricks = max; }
  };

  BrickGrid() : BrickGrid(Config{}) {}
  explicit BrickGrid(const Config& config);

  // ---- edits ----
  /// Adds a brick (validated first; nothing changes on error). Returns its stable id.
  uint32_t placeBrick(const Brick& b);
  /// Removes a brick by id (InvalidInput for an unknown id).
  void removeBrick(uint32_t id);
  /// Asks the cache for what removing these bricks will read: their records and their index
  /// paths (OctoBvh::prefetchPaths). Read-only, so the removals after it leave what they would
  /// have. For a loop about to remove many bricks one by one: call it on the next
  /// kPrefetchGroup ids before removing them. Ids not in the grid are skipped.
  void prefetchRemovals(std::span<const uint32_t> ids) const;
  /// The same for placing these bricks: the index paths their bounds will take
  /// (OctoBvh::prefetchInsertPaths). Bricks that are not valid are skipped.
  void prefetchPlacements(std::span<const Brick> bricks) const;
  static constexpr size_t kPrefetchGroup = OctoBvh::kPrefetchGroup;
  /// Places many bricks into an empty grid at once (the index built in one pass: the same tree
  /// structure, ids and mass properties as placing them one by one, though its elements are
  /// numbered in another order, so queries may list the same bricks in another order); returns
  /// their ids in order.
  /// Throws InvalidInput (a bad brick, a grid not empty) or CapacityExceeded, placing nothing.
  std::vector<uint32_t> placeBricks(const std::vector<Brick>& bricks);
  /// Moves bricks (live, distinct ids) out of this grid into `into`, an empty grid of the same
  /// densities, keeping their grid coordinates: one index build there, one bulk removal here
  /// (OctoBvh::removeMany), no brick validated again. Both indices end as placing and removing
  /// one by one would leave them; mass properties agree with that to rounding. Returns the new
  /// ids in order. Throws InvalidInput (a bad or repeated id, `into` not empty or this grid,
  /// other densities) or CapacityExceeded, moving nothing.
  std::vector<uint32_t> moveBricks(std::span<const uint32_t> ids, BrickGrid& into);

  /// moveBricks in steps, for a caller that runs the two grids' halves at once on two threads
  /// (they share nothing): prepareMove checks and gathers, changing nothing on error (it
  /// throws as moveBricks does); then receiveMove on `into` (the index build) and releaseMove
  /// on this grid (the bulk removal), in either order or at the same time, each once. The end
  /// state is moveBricks'. Only an allocation failure can stop a step half way.
  /// receiveMove is itself two steps that touch separate state and may run at the same time:
  /// receiveMoveIndex (the index build, and each brick's element) and receiveMoveBricks (the
  /// grid's mass: the gather put the bricks in their slots); releaseMove likewise is releaseMoveIndex (the bulk removal)
  /// and releaseMoveBricks (the bricks and the mass). The moved bricks' moments are summed once,
  /// by receiveMoveBricks, about this grid's reference point, which `into` takes as its own;
  /// whichever of receiveMoveBricks and releaseMoveBricks finishes second takes that sum out of
  /// this grid's mass (so either order, or both at once, still works: this grid's mass is
  /// current once both have run). The grid the bricks leave must not be edited between
  /// prepareMove and its release: releaseMove (before either step) and
  /// releaseMoveBricks refuse with InvalidInput if it was, or if the move was released already.
  /// prepareMove is itself beginMove (the checks and the new ids) and gatherMove over every
  /// entry, which a caller with threads may split into ranges gathered at once.
  class Move {
   public:
    /// The bricks' ids in `into`, in the order of the ids moved (known once begun).
    const std::vector<uint32_t>& newIds() const { return newIds_; }
    /// Bricks moved.
    size_t size() const { return ids_.size(); }

   private:
    friend class BrickGrid;
    BrickGrid* from_ = nullptr;
    BrickGrid* into_ = nullptr;
    std::vector<uint32_t> ids_, newIds_;
    // Sized by beginMove and written whole by gatherMove's ranges (which write the bricks into
    // their new slots directly): their pages are first touched by the threads that gather
    // (collision/core/overwrite_vector.h).
    OverwriteVector<uint32_t> elements_, filters_;
    OverwriteVector<Aabb> bounds_;
    uint64_t fromEdits_ = 0;  // from_'s edit count when prepared: releaseMoveBricks trusts the ids while it holds
    Vec3d reference_ = Vec3d::Zero();  // from_'s reference point when prepared (into's from then on)
    MomentSum moments_;       // the moved bricks' moments about it (receiveMoveBricks)
    uint32_t massSteps_ = 0;  // receiveMoveBricks and releaseMoveBricks done (atomic_ref: they may run at once)
  };
  Move prepareMove(std::span<const uint32_t> ids, BrickGrid& into);
  /// prepareMove's checks, the ids allocated in `into` and the move's arrays sized (not filled):
  /// gatherMove must then fill every entry before the move is received or released.
  Move beginMove(std::span<const uint32_t> ids, BrickGrid& into);
  /// Fills entries [begin, end) of a begun move: each brick copied to its new slot in `into`,
  /// its bounds as indexed, its element and filter noted. Reads this grid and writes only those
  /// slots and entries: disjoint ranges may be gathered at the same time.
  void gatherMove(Move& move, size_t begin, size_t end) const;
  /// Called on the grid the bricks move into: receiveMoveIndex, then receiveMoveBricks.
  void receiveMove(Move& move);
  void receiveMoveIndex(Move& move);
  void receiveMoveBricks(Move& move);
  /// Called on the grid the bricks leave: releaseMoveIndex, then releaseMoveBricks.
  void releaseMove(Move& move);
  void releaseMoveIndex(Move& move);
  void releaseMoveBricks(Move& move);
  /// Counts edits; caches keyed on it are stale when it changes.
  uint64_t editCount() const { return edits_; }

  // ---- access ----
  uint32_t brickCount() const { return bricks_.size(); }
  bool hasBrick(uint32_t id) const { return bricks_.isLive(id); }
  const Brick& brick(uint32_t id) const { return bricks_.get<0>(id); }
  const OctoBvh& index() const { return index_; }
  Aabb bounds() const { return index_.rootBounds(); }
  template <class F>
  void forEachBrick(F&& f) const { bricks_.forEachLive(std::forward<F>(f)); }
  MassProperties massProperties() const;

  // ---- queries (grid frame) ----
  /// Closest hit on real brick shapes: exactly the smallest rayBrick() t over every brick within
  /// [0, ray.maxT] (faces are closed, so grazing counts), ties going to the lowest OctoBVH handle.
  /// InvalidInput for a non-finite origin or direction, a direction whose components are all
  /// zero or denormal, or a NaN or negative maxT.
  GridRayHit raycast(const Ray& ray, uint32_t mask, QueryStats* stats = nullptr) const;
  /// First time of impact of a shape (fixed rotation, grid frame) moving from `from` to `to`:
  /// a ray traversal against bounds grown by the shape's extents, then conservative advancement
  /// (GJK distances) against each candidate brick's real shape. The fraction is exactly the
  /// smallest sweepShapeBrick() fraction over every brick; a zero motion tests the start pose.
  GridSweepHit sweep(const QueryShape& shape, const Quatf& rotation, const Vec3f& from, const Vec3f& to, uint32_t mask,
                     QueryStats* stats = nullptr) const;
  /// Bricks whose bounds overlap box (ids appended). InvalidInput for NaN bounds; infinite
  /// bounds are fine.
  void overlapBricks(const Aabb& box, uint32_t mask, std::vector<uint32_t>& out, QueryStats* stats = nullptr) const;

  // ---- contacts ----
  /// Contacts between a convex shape and this grid, both placed in the world. Contacts come back
  /// in world space (normal from the grid towards the shape), reduced to params.maxContacts.
  /// Returns the number appended to out.
  size_t collide(const RigidTransform& gridPose, const QueryShape& shape, const RigidTransform& shapePose,
                 const ContactParams& params, ContactScratch& scratch, std::vector<Contact>& out,
                 ContactStats* stats = nullptr) const;
  /// collide without checking its arguments, for a caller that checked them already (collideGrids
  /// checks the two poses and params once a pair, then collides every brick of a small grid).
  size_t collideChecked(const RigidTransform& gridPose, const QueryShape& shape, const RigidTransform& shapePose,
                        const ContactParams& params, ContactScratch& scratch, std::vector<Contact>& out,
                        ContactStats* stats = nullptr) const;
  /// InvalidInput naming `context` and the field, for params collide cannot take.
  static void validateContactParams(const ContactParams& params, const char* context);
  /// The same in the grid frame, without reduction (raw per-brick contacts appended).
  void collideLocal(const QueryShape& shape, const LocalPose& pose, const ContactParams& params,
                    std::vector<LocalContact>& out, ContactStats* stats = nullptr) const;

  /// Boxes that together cover every brick (grid frame), at most `maxBoxes` (at least 1): the
  /// bounds of the OctoBVH's subtrees at the deepest level whose nodes still fit, and of the
  /// bricks held above that level (large bricks). A coarse stand-in for the whole grid, kept
  /// tight by the index under edits (the world's broadphase enters large static grids as these).
  void coverBoxes(uint32_t maxBoxes, std::vector<Aabb>& out) const;

  // ---- convex approximation ----
  /// Hull of the bricks met in the first `depth` levels of the OctoBVH plus the bounds of the
  /// subtrees left at that depth; a box when the hull is exactly its bounds. Cached per depth,
  /// rebuilt lazily after edits. Not thread-safe (refreshes the cache).
  const ConvexApproximation& convexApproximation(int depth);
  /// Builds one without touching the cache.
  ConvexApproximation buildConvexApproximation(int depth) const;

 private:
  Config config_;
  ParallelVirtualPool<Brick, uint32_t> bricks_;  // brick, OctoBVH element handle
  OctoBvh index_;
  MomentSum moments_;                            // about reference_
  double peakSecond_ = 0;                        // largest trace of the second moment since the last recompute
  Vec3d reference_ = Vec3d::Zero();
  bool referenceSet_ = false;
  uint64_t edits_ = 0;
  struct CachedApproximation {
    uint64_t edit = ~0ull;
    ConvexApproximation value;
  };
  std::array<CachedApproximation, 8> approximations_;

  float roundingMargin(const Vec3f& queryPoint) const;
  /// placeBricks' work once the bricks are known to be valid and the grid empty.
  std::vector<uint32_t> placeValidBricks(const std::vector<Brick>& bricks, const std::vector<Aabb>& bounds);
  /// indexValidBricks for ids allocated already, freeing them again if the build throws.
  void indexValidBricksOrFree(const std::vector<uint32_t>& ids, std::span<const Brick> bricks, std::span<const Aabb> bounds);
  /// The ids allocated for a move freed again if its index build throws.
  void indexMovedBricksOrFree(const Move& m);
  /// The index's bulk load and each id's element handle (the pool's column 1); throws before
  /// anything changes. boundsFromIndex: the bounds were read from an index (a move), so the
  /// index does not check them again.
  void indexValidBricks(const std::vector<uint32_t>& ids, std::span<const Aabb> bounds, std::span<const uint32_t> filters,
                        bool boundsFromIndex);
  /// indexValidBricks of a move's gathered bricks: their bounds and filters read from an index
  /// already, so not checked again.
  void indexMovedBricks(const Move& m);
  /// The bricks (column 0) and their mass.
  void addValidBricks(const std::vector<uint32_t>& ids, std::span<const Brick> bricks);
  void rebaseIfCancelling();
  /// Counts one of a move's two mass steps; the second takes the moved bricks' moments out of
  /// the grid they left (after both, so neither step waits for the other).
  static void finishMoveMassStep(Move& m);
  /// Throws InvalidInput unless this grid is as prepareMove left it for `m`.
  void requireUnedited(const Move& m) const;
};

/// Grid vs grid (article 000): the grid with fewer bricks (of two small ones, the one of smaller
/// extent) collides as its convex approximation
/// (box or hull, at `depth`) against the other's bricks; a small grid (at most
/// kBrickwiseGridBricks bricks) collides brick by brick instead, each brick as the box of its
/// shape (a wedge or cylinder as its bounding box), so a concave piece (a carved slab, a ring's
/// part) is not filled in by its hull; each contact's feature then mixes in the small grid's
/// brick (smallFeature), so warm starting tells the bricks apart. Contacts are world-space
/// with normals pointing from `larger` towards `smaller`; returns which grid was treated as the
/// smaller (0 = a, 1 = b) through smallerIndex. `mode` TwoWay (or Auto with a hull overstating
/// the smaller grid's bricks by kAutoTwoWayFill) collides a smaller grid above
/// kBrickwiseGridBricks brick against brick instead (collideGridPair, the LOD at
/// params.lodFraction on both sides), the pair's contacts reduced as one manifold.
/// Bricks up to which a grid collides brick by brick against grids and terrains (collideGrids,
/// the world's terrain pairs): above it the hull's one query is cheaper than the bricks' many.
constexpr uint32_t kBrickwiseGridBricks = 128;
/// A contact feature of a small grid's brick `brick` against feature `feature` of the other side.
inline uint32_t smallFeature(uint32_t feature, uint32_t brick) { return feature ^ (brick * 0x9E3779B1u); }

size_t collideGrids(BrickGrid& a, const RigidTransform& poseA, BrickGrid& b, const RigidTransform& poseB, int depth,
                    const ContactParams& params, ContactScratch& scratch, std::vector<Contact>& out, int& smallerIndex,
                    ContactStats* stats = nullptr, GridPairMode mode = GridPairMode::Convex);
/// collideGrids without checking the poses and params, for a caller that holds them valid (the
/// world: its bodies' poses are the integrator's; its start search tries thousands of them).
size_t collideGridsChecked(BrickGrid& a, const RigidTransform& poseA, BrickGrid& b, const RigidTransform& poseB, int depth,
                           const ContactParams& params, ContactScratch& scratch, std::vector<Contact>& out, int& smallerIndex,
                           ContactStats* stats = nullptr, GridPairMode mode = GridPairMode::Convex);

}  // namespace bw
