#pragma once
/// Loose kD tree over a triangle mesh (article 001, "Loose kD tree").
///
///   LooseKdTree tree;
///   tree.build(mesh.view(), builder);          // builder: reusable scratch, no allocation after warm-up
///   tree.queryAabb(mesh.view(), box, [&](uint32_t tri) { ... });
///   KdRayHit hit; tree.raycastClosest(mesh.view(), ray, hit);
///
/// Each branch splits along one axis with two planes: everything in the left child lies at or
/// below splits[0], everything in the right child at or above splits[1]; the planes are tight
/// over the children's vertices, so they may overlap (loose) and no triangle is ever cut.
/// Build: split the longest axis of the node at the mean of the triangles' midpoints; if one
/// side gets < 25% of the triangles, split at the median instead, which bounds the depth
/// (every child holds <= 3/4 of its parent). Leaves hold up to 2 triangles.
/// After the build, nodes are re-laid out in treelets (7 sibling pairs of a subtree stored
/// breadth-first, contiguously) so a descent touches fewer cache lines on big trees.
/// Queries run an explicit stack of kMaxDepth + 1 entries on the C++ stack: no heap, and the
/// build proves the depth bound (depth() <= kMaxDepth always holds).
/// Height bounds: on a wide mesh (a heightfield: >= kHeightBoundsMinTriangles triangles, the
/// shortest axis of its bounds at most a quarter of the longest) the splits almost never cut the
/// short axis, so a descending ray walks every node under its footprint from where it starts,
/// tens of metres above the ground. Such trees also keep, per node, its subtree's range on the
/// short axis in 16 bits of the root's range (4 bytes a node, rounded outwards), and a ray clips
/// its segment to it: it skips the nodes it passes over. Box queries do not read them: a box on
/// the surface spans every node's range it meets, and the second array's cache lines cost
/// more than they cut (2 m boxes: 0.28x -> 0.53x of Bullet's time, measured).
/// Thread safety: queries are const and may run concurrently.
#include <bit>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "collision/core/aabb.h"
#include "collision/core/ray.h"
#include "collision/terrain/ray_triangle.h"
#include "collision/terrain/triangle_mesh.h"

namespace bw {

/// One kD tree node, 12 bytes.
///
///   branch: | word0: splits[0] (float bits) | word1: splits[1] (float bits) | child : 30 | axis : 2 |
///   leaf:   | word0: triangle 0             | word1: triangle 1             | count : 30 | 3    : 2 |
///                                                                           bits 31..2   bits 1..0
/// axis 0/1/2 = X/Y/Z; the fourth value (3) tags a leaf. A branch's children are at child and
/// child + 1 (left, right), so one index is enough.
struct KdNode {
  uint32_t word0;  // 4  splits[0] bits, or triangle 0
  uint32_t word1;  // 4  splits[1] bits, or triangle 1
  uint32_t bits;   // 4  (child or count) << 2 | axis

  static constexpr uint32_t kLeafAxis = 3;  ///< axis value tagging a leaf
  /// 0, 1, 2 for a branch's split axis; kLeafAxis for a leaf.
  uint32_t axis() const { return bits & 3u; }
  /// Branch: index of the left child (the right one follows it). Leaf: triangle count.
  uint32_t payload() const { return bits >> 2; }
};
static_assert(sizeof(KdNode) == 12, "the article's 12-byte node");

/// A node's subtree range on the tree's height axis, in steps of the root's range: the real
/// range lies within [base + lo * step, base + hi * step] (lo rounded down, hi up).
struct KdHeightBounds {
  uint16_t lo;  // 2
  uint16_t hi;  // 4
};
static_assert(sizeof(KdHeightBounds) == 4);

/// Whether a build may add height bounds: Auto adds them to wide meshes (see above), Off never
/// (for measuring what they bring).
enum class KdHeightBoundsMode : uint8_t { Auto, Off };

/// Closest hit of a ray against a tree's triangles.
struct KdRayHit {
  float t;            ///< ray parameter of the hit (units of |dir|)
  uint32_t triangle;  ///< triangle index in the mesh
};

/// Reusable build scratch (one per thread): keeps its arrays between builds.
class KdTreeBuilder {
 public:
  /// Per-triangle build record: bounds and the triangle id, moved while partitioning.
  struct TriRecord {
    float min[3];  // 12
    float max[3];  // 12
    uint32_t id;   // 4
  };
  std::vector<TriRecord> records;  ///< scratch, sized to the mesh being built
  std::vector<KdNode> layout;       ///< scratch for the treelet layout pass
  /// Scratch of the layout pass: a pair of children waiting for its treelet.
  struct PendingPair {
    uint32_t oldPair;  // 4
    uint32_t parent;   // 4
  };
  std::vector<PendingPair> pending;  ///< scratch for the treelet layout pass
  std::vector<float> heightLo, heightHi;     ///< per built node: its subtree's range on the height axis
  std::vector<KdHeightBounds> heightLayout;  ///< scratch: height bounds in the treelet order
};

class LooseKdTree {
 public:
  /// Deepest tree the build can produce: children hold <= 3/4 of the parent (and leaves up to
  /// 2), so 2^30 triangles need at most log_{4/3}(2^29) + 2 < 75 levels.
  static constexpr uint32_t kMaxDepth = 80;
  /// Largest triangle count (30-bit child indices; nodes <= triangles).
  static constexpr uint32_t kMaxTriangles = (1u << 29);
  /// Smallest mesh that gets height bounds (below it a ray visits few nodes anyway, and chunk
  /// meshes keep the article's 12 bytes a node).
  static constexpr uint32_t kHeightBoundsMinTriangles = 4096;

  /// Builds over all triangles of `mesh`, replacing any previous tree. Throws InvalidInput for
  /// more than kMaxTriangles triangles.
  void build(const TriangleMeshView& mesh, KdTreeBuilder& builder, KdHeightBoundsMode heightBounds = KdHeightBoundsMode::Auto);
  /// Frees the nodes.
  void clear();

  /// f(triangle) once for each triangle whose bounding box overlaps `box` (closed boxes).
  template <class F>
  void queryAabb(const TriangleMeshView& mesh, const Aabb& box, F&& f) const;
  /// Closest triangle hit by `ray` within [0, ray.maxT]; false if none. Near children are
  /// visited first and subtrees starting beyond the best hit are skipped.
  bool raycastClosest(const TriangleMeshView& mesh, const Ray& ray, KdRayHit& hit) const;
  /// Like raycastClosest, also counting visited nodes (benchmarks, tests of early exit).
  bool raycastClosestCounted(const TriangleMeshView& mesh, const Ray& ray, KdRayHit& hit, uint32_t& nodesVisited) const;

  /// Bounds of all triangles (early rejection of queries).
  const Aabb& bounds() const { return bounds_; }
  /// Longest root-to-leaf path in nodes (root alone = 1).
  uint32_t depth() const { return depth_; }
  /// Node array.
  const std::vector<KdNode>& nodes() const { return nodes_; }
  /// Whether the tree keeps height bounds (a wide mesh), and on which axis (-1: none).
  bool hasHeightBounds() const { return heightAxis_ >= 0; }
  int heightAxis() const { return heightAxis_; }
  /// Bytes of the tree alone (nodes, height bounds, bounds), not counting the mesh.
  size_t bytes() const { return nodes_.size() * sizeof(KdNode) + heights_.size() * sizeof(KdHeightBounds) + sizeof(Aabb); }

  /// Checks the structural invariants (every triangle in exactly one leaf, children inside
  /// their parent's planes, depth). Returns an empty string or the first violation.
  std::string validate(const TriangleMeshView& mesh) const;

 private:
  static float splitOf(uint32_t word) { return std::bit_cast<float>(word); }
  void layoutInTreelets(KdTreeBuilder& b);
  void quantiseHeights(KdTreeBuilder& b);
  float heightOf(uint16_t q) const { return heightBase_ + float(q) * heightStep_; }
  uint32_t buildNode(uint32_t node, uint32_t begin, uint32_t end, const Aabb& bounds, const double (&midSum)[3],
                     KdTreeBuilder& b, uint32_t depth);
  template <bool kCount>
  bool raycastDispatch(const TriangleMeshView& mesh, const Ray& ray, KdRayHit& hit, uint32_t* nodesVisited) const;
  template <bool kCount, class Vertices, class Index>
  bool raycastImpl(const Vertices& vertices, const Index* indices, const Ray& ray, KdRayHit& hit, uint32_t* nodesVisited) const;

  std::vector<KdNode> nodes_;
  std::vector<KdHeightBounds> heights_;  ///< per node when heightAxis_ >= 0, else empty
  int heightAxis_ = -1;
  float heightBase_ = 0.f, heightStep_ = 0.f;  ///< dequantisation: base + q * step
  Aabb bounds_ = Aabb::empty();
  uint32_t depth_ = 0;
};

template <class F>
void LooseKdTree::queryAabb(const TriangleMeshView& mesh, const Aabb& box, F&& f) const {
  if (nodes_.empty() || !bounds_.overlaps(box)) return;
  uint32_t stack[kMaxDepth + 1];
  uint32_t sp = 0;
  stack[sp++] = 0;
  while (sp) {
    const KdNode n = nodes_[stack[--sp]];
    const uint32_t axis = n.axis();
    if (axis == KdNode::kLeafAxis) {
      const uint32_t tris[2] = {n.word0, n.word1};
      for (uint32_t i = 0; i < n.payload(); ++i) {
        Vec3f a, b, c;
        mesh.corners(tris[i], a, b, c);
        const Aabb tb{a.cwiseMin(b).cwiseMin(c), a.cwiseMax(b).cwiseMax(c)};
        if (tb.overlaps(box)) f(tris[i]);
      }
      continue;
    }
    // Descend only into children whose half-space reaches the box.
    if (splitOf(n.word1) <= box.max[axis]) stack[sp++] = n.payload() + 1;
    if (splitOf(n.word0) >= box.min[axis]) stack[sp++] = n.payload();
  }
}

}  // namespace bw
