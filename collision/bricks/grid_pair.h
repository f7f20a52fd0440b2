#pragma once
/// Two-way grid vs grid (issue 19): both grids' bricks against each other in their relative
/// pose, by a simultaneous traversal of their OctoBVHs. Concave against concave: a ring's hole
/// stays a hole and a hangar's doorway stays open, where the one-way path (collideGrids, article
/// 000) meets the smaller grid's convex approximation, solid across its holes.
///
///   GridPairParams params;                 // lodFraction 1/16, no speculative margin
///   GridPairScratch scratch;               // reused between calls: no allocation once grown
///   std::vector<GridPairContact> out;
///   collideGridPair(a, b, aInB, params, scratch, out);   // contacts in b's frame
///
/// The traversal keeps a stack of (item of a, item of b), an item being a node (a subtree) or a
/// brick. A pair whose bounds cannot touch (a's box oriented in b's frame against b's box grown
/// by the speculative margin, obb.h mayOverlap) is dropped; otherwise the larger node, by its
/// bounds' largest extent, is opened into the bricks it holds and its children. Brick against
/// brick gives the exact contacts (collideShapeBrick: box-box manifolds, GJK/EPA for wedges,
/// corner wedges and cylinders as hulls). Collision LOD on both sides, as the one-way query's
/// against its shape: a node smaller than lodFraction times the brick (or LOD box) it meets on
/// the other side collides as its tight box (0: off, and the contacts equal those of every brick
/// pair, which the tests check).
/// Precision: one float relative pose; the caller forms it from the two world poses in double.
#include <cstdint>
#include <vector>

#include "collision/bricks/brick.h"
#include "collision/bricks/brick_narrowphase.h"

namespace bw {

class BrickGrid;

/// How a grid pair collides (scene setting `grid_pairs`): the smaller grid's convex
/// approximation against the other's bricks (article 000's one-way path), both grids' bricks
/// (collideGridPair), or two-way when the approximation overstates the smaller grid's bricks by
/// more than kAutoTwoWayFill (a ring, a hangar, an L-shaped wall: holes and recesses filled in).
enum class GridPairMode : uint8_t { Convex, TwoWay, Auto };
/// Auto: two-way when the hull's volume exceeds the bricks' by this factor.
constexpr double kAutoTwoWayFill = 1.5;

struct GridPairParams {
  float lodFraction = 1.f / 16;   ///< subtrees smaller than this x the other side's item are boxes (0: off)
  float speculativeMargin = 0.f;  ///< also report gaps below this (negative depth)
};

/// A contact between a brick (or LOD box) of a and one of b, in b's frame.
struct GridPairContact {
  Vec3f position;   ///< on b's brick
  Vec3f normal;     ///< unit, from b towards a
  float depth;      ///< > 0 penetration, < 0 speculative gap
  uint32_t brickA;  ///< a's brick id, or kLodFeature | node reference for a LOD box
  uint32_t brickB;  ///< the same for b
};

struct GridPairStats {
  uint64_t itemPairs = 0;   ///< pairs tested (node or brick against node or brick)
  uint64_t brickPairs = 0;  ///< pairs given to the narrowphase (bricks or LOD boxes)
  uint64_t lodBoxes = 0;    ///< nodes collided as boxes
};

/// What one traversal needs besides its output; keep one per thread.
struct GridPairScratch {
  struct Item {
    uint32_t ref;   ///< node reference (cluster << 3 | slot) or element handle
    uint8_t kind;   ///< 0 node, 1 brick (element), 2 LOD box (a node as its tight box)
  };
  std::vector<std::pair<Item, Item>> stack;
};

/// Appends every contact between a's bricks (posed by aInB in b's frame) and b's bricks.
void collideGridPair(const BrickGrid& a, const BrickGrid& b, const LocalPose& aInB, const GridPairParams& params,
                     GridPairScratch& scratch, std::vector<GridPairContact>& out, GridPairStats* stats = nullptr);

/// One brick of a grid as a query shape at its place in the grid frame (a box brick a box, the
/// others their vertex hulls, written to `vertices`, which must hold kMaxBrickVertices).
QueryShape brickQueryShape(const Brick& b, Vec3f* vertices);

}  // namespace bw
