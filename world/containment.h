#pragma once
/// Containment: which dynamic bodies are inside solid. A run that ends with a body inside solid
/// is wrong however fast it is, so every scene run reports the count (`bodies_inside_solid`).
///
/// A body is inside solid when its centre is inside a brick's exact shape (of any grid but its
/// own) or a solid terrain voxel, or when it went through a surface: the straight path from the
/// last place it was seen outside solid to where it is now crosses a static or kinematic grid
/// or a terrain (a crate that tunnelled through a street plate stays counted while the plate
/// is between it and where it came from; one pushed back out the way it came is clear again).
/// A centre never reaches a surface legitimately: bodies rest with their centre a half extent
/// or radius away from it.
///
///   ContainmentTracker tracker(world);
///   for (...) { world.step(); tracker.update(); }
///   tracker.report().count();
#include <cstdint>
#include <vector>

#include "collision/core/math_types.h"
#include "world/broadphase.h"

namespace bw {

class World;

/// Why a body counts as inside solid.
enum class InsideSolid : uint8_t {
  No,
  InBrick,       ///< its centre is inside a brick's exact shape
  InVoxel,       ///< its centre is inside a solid terrain voxel
  WentThrough,   ///< its path from the last place outside solid crosses a surface
};

const char* insideSolidName(InsideSolid reason);

/// The dynamic bodies inside solid (ids ascending) and why.
struct ContainmentReport {
  std::vector<uint32_t> bodies;
  std::vector<InsideSolid> reasons;
  uint32_t count() const { return uint32_t(bodies.size()); }
};

/// Follows every dynamic body from frame to frame (call update() after each step; the world's
/// bodies must not be added or removed in between). The checks run on the world's job system
/// (the same report for any thread count). A body that was clear and that the step's
/// broadphase never paired with a grid or terrain is clear without a query (World::
/// nearSolidLastStep): most of a rain is in the air, and the queries were a third of a run.
/// A clear body that moved less than kRecheckDistance since it was last checked (resting
/// bodies jitter by micrometres) is not checked again until it has: a centre that close to a
/// clear place is at most that far into a brick (bodies rest with their centre a half extent
/// from a surface), and the crossing test always runs from the last clear place, so no
/// tunnelling is missed. A body whose only solid neighbour is a moving grid (a crate riding a
/// kinematic ship) has those places kept in that grid's frame: resting on the ship it is at
/// rest, and its path is the path relative to the ship. In a world whose solids are all
/// static, a slow body found clear keeps the ball around that place that no brick or solid
/// voxel reaches into (World::staticSolidClearance): while it stays inside, its way from
/// there stays inside too, and it is not checked again (a crate rocking on a street moves
/// millimetres a frame, and its path tests were two thirds of the checks' instructions).
/// Not while step() runs: it casts rays into the terrains, which fill their chunk caches.
class ContainmentTracker {
 public:
  /// Takes every dynamic body's current centre as its starting place (a body that starts
  /// inside solid is reported as such).
  explicit ContainmentTracker(World& world);
  /// Metres a clear body may move before it is checked again (see above): about a sixth of the
  /// thinnest brick (a 3.2 mm plate).
  static constexpr double kRecheckDistance = 0.5e-3;
  /// The largest free ball kept (metres): wider than any resting body's centre is from the
  /// surface it rests on, small enough that its query meets only the bricks around it.
  static constexpr double kFreeReach = 0.5;
  /// Checks every dynamic body that moved since the last update; returns the report.
  const ContainmentReport& update();
  const ContainmentReport& report() const { return report_; }
  /// Bodies the last update() queried (point and path tests): what the shortcuts left.
  uint32_t lastQueried() const { return queried_; }

 private:
  // A body's places are kept in the world (kWorldFrame) or in a solid body's frame.
  static constexpr uint32_t kWorldFrame = ~0u;
  uint32_t frameAt(const WorldAabb& box, uint32_t self) const;  // where a body whose way is `box` keeps its places
  bool crossesGrid(uint32_t body, const Vec3d& p) const;          // its way from its last clear place crosses a grid
  Vec3d toFrame(uint32_t frame, const Vec3d& p) const { return frame == kWorldFrame ? p : toSolidFrame(frame, p); }
  Vec3d fromFrame(uint32_t frame, const Vec3d& q) const { return frame == kWorldFrame ? q : fromSolidFrame(frame, q); }
  Vec3d toSolidFrame(uint32_t solid, const Vec3d& p) const;    // world -> the solid's frame, at its current pose
  Vec3d fromSolidFrame(uint32_t solid, const Vec3d& q) const;  // and back
  void settle(uint32_t body, InsideSolid s, const Vec3d& p, uint32_t frame, const Vec3d& place, double free2);
  // Per chunk of pass 1: bodies queried, and whether one is left for pass 2 or inside solid.
  struct Chunk {
    uint32_t queried = 0;
    bool busy = false;
  };
  std::vector<Chunk> chunks_;
  bool movingSolids_ = false;  // World::hasMovingSolid() at the last update
  World& world_;
  std::vector<uint8_t> terrainLeft_;  // per body: its terrain crossing test is left for pass 2, from
  std::vector<uint32_t> checkFrame_;  // its frame and
  std::vector<Vec3d> checkPlace_;     // its centre in that frame
  uint32_t queried_ = 0;
  uint64_t staticEdits_ = 0;  // World::staticGridEdits() at the last update
  std::vector<Vec3d> lastSeen_;   // per body: centre when last checked (or found far from solid), in seenFrame_
  std::vector<Vec3d> lastClear_;  // per body: the last centre seen outside solid, in clearFrame_
  std::vector<uint32_t> seenFrame_, clearFrame_;
  std::vector<Vec3d> lastWorld_;       // per body: centre at the last update, in the world
  std::vector<Vec3d> lastClearWorld_;  // per body: the last centre known clear of every solid but its frame's, in the world
  std::vector<uint8_t> hasClear_; // per body: lastClear_ is set (not for a body that started inside)
  // Per body: the squared radius of the free ball around lastClear_ (0: none). Set with every
  // lastClear_, so the ball is always centred there; all dropped when a static grid is edited,
  // a terrain is edited or moved, or poses are set.
  std::vector<double> freeRadius2_;
  uint64_t posesSet_ = 0;           // World::posesSetCount() at the last update
  uint64_t terrainChanges_ = 0;     // World::terrainChanges() at the last update
  std::vector<InsideSolid> state_;
  ContainmentReport report_;
};

}  // namespace bw
