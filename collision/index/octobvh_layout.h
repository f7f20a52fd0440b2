#pragma once
/// Memory layout of the OctoBVH (article 000, "OctoBVH Memory Layout"): clusters of 8 sibling
/// nodes in SoA, fixed leaf blocks of element indices, and compact element records, each kind in
/// its own virtual pool.
#include <cmath>
#include <cstdint>
#include <cstring>

#include "collision/core/aabb.h"
#include "collision/core/ids.h"

namespace bw::octobvh {

constexpr int kLeafCapacity = 8;        ///< elements per leaf block (the article's optimum)
constexpr int kMinLevel = -10;          ///< smallest cube: width 2^-10 (leaves there may overflow)
constexpr int kMaxLevel = 31;           ///< largest root cube: [-2^30, 2^30)^3
constexpr float kMaxCoordinate = 1073741824.f;  ///< |coordinate| limit (2^30)
constexpr uint8_t kOverflow = 255;      ///< numHeld value of a min-level leaf with > 8 elements
constexpr uint8_t kForcedCluster = 254; ///< numHeld value of a node whose leaf field is its forced cluster

/// Eight sibling nodes: the children of one node. 40 bytes per node.
struct alignas(64) NodeCluster {
  float minX[8], minY[8], minZ[8];  // 96   tight bounds of each node's subtree (inverted when empty)
  float maxX[8], maxY[8], maxZ[8];  // 192
  uint32_t child[8];                // 224  cluster holding the node's 8 children, or kInvalidIndex (leaf/empty)
  uint32_t leaf[8];                 // 256  elements held at the node: the element itself when one,
                                    //      a LeafBlock (2..8), an OverflowBlock chain, or kInvalidIndex;
                                    //      or (numHeld kForcedCluster) the node's forced cluster
  uint32_t filter[8];               // 288  OR of filter bits of every element in the subtree
  uint8_t numHeld[8];               // 296  elements held at the node; kOverflow: overflow chain;
                                    //      kForcedCluster: none held, leaf[] is the forced cluster
  int8_t maxMinLevel[8];            // 304  largest min level in the subtree
  uint32_t childTotal;              // 308  elements in the 8 nodes' subtrees together
  uint32_t forcedCount;             // 312  elements forced into these nodes: childTotal in a forced
                                    //      cluster and in the children of a node that forced
                                    //      everything it had (nothing fit a child); else 0
  int8_t level;                     // 313  level of these 8 nodes: each is a cube of width 2^level
  uint8_t pad[7];                   // 320

  bool isEmpty(int s) const { return numHeld[s] == 0 && child[s] == kInvalidIndex; }
  /// The node's forced cluster (its too-large elements, apart from its children), or kInvalidIndex.
  uint32_t forced(int s) const { return numHeld[s] == kForcedCluster ? leaf[s] : kInvalidIndex; }
  /// f(cluster) for the node's child cluster and its forced cluster, when it has them.
  template <class F>
  void forEachSubCluster(int s, F&& f) const {
    if (child[s] == kInvalidIndex) return;
    f(child[s]);
    if (numHeld[s] == kForcedCluster) f(leaf[s]);
  }
  Aabb bounds(int s) const { return {{minX[s], minY[s], minZ[s]}, {maxX[s], maxY[s], maxZ[s]}}; }
  void setBounds(int s, const Aabb& b) {
    minX[s] = b.min.x(); minY[s] = b.min.y(); minZ[s] = b.min.z();
    maxX[s] = b.max.x(); maxY[s] = b.max.y(); maxZ[s] = b.max.z();
  }
};
static_assert(sizeof(NodeCluster) == 320, "40 bytes per node");

/// Asks for a cluster's links (child, leaf: bytes 192-255) and summaries (filter, counts:
/// 256-319) ahead of an edit's next level, and its bounds (0-191) when the edit writes them: an
/// edit's walk is a chain of dependent cache misses, and this overlaps a level's lines.
inline void prefetchForEdit(const NodeCluster& cl, bool bounds) {
  const char* p = reinterpret_cast<const char*>(&cl);
  if (bounds) {
    __builtin_prefetch(p, 1);
    __builtin_prefetch(p + 64, 1);
    __builtin_prefetch(p + 128, 1);
  }
  __builtin_prefetch(p + 192);
  __builtin_prefetch(p + 256, 1);
}

/// Element indices held by one node (a leaf's elements, or an inner node's large elements).
struct LeafBlock {
  uint32_t elements[kLeafCapacity];  // 32
};
static_assert(sizeof(LeafBlock) == 32);

/// A min-level leaf that holds more than 8 elements chains these (only when > 8 element
/// centres fall in one 2^-10 cube, e.g. duplicated bricks).
struct OverflowBlock {
  uint32_t count;         // 4   elements in the whole chain (valid in the first block)
  uint32_t next;          // 8   next block or kInvalidIndex
  uint32_t elements[14];  // 64
};
static_assert(sizeof(OverflowBlock) == 64);

/// One indexed element: grid-local bounds, filter bits and the caller's payload.
struct ElementRecord {
  float min[3];      // 12
  float max[3];      // 24
  uint32_t filter;   // 28
  uint32_t payload;  // 32
  Aabb bounds() const { return {{min[0], min[1], min[2]}, {max[0], max[1], max[2]}}; }
  static ElementRecord of(const Aabb& b, uint32_t filter, uint32_t payload) {
    return {{b.min.x(), b.min.y(), b.min.z()}, {b.max.x(), b.max.y(), b.max.z()}, filter, payload};
  }
};
static_assert(sizeof(ElementRecord) == 32);

/// Smallest level L (clamped to [kMinLevel, kMaxLevel]) with 2^L >= extent.
/// note: read from the float's exponent and mantissa bits: exact, and cheap enough to call on
/// every element a refit touches. Extents are finite and >= 0 (validated on insert).
inline int minLevelForExtent(float extent) {
  uint32_t bits;
  std::memcpy(&bits, &extent, 4);
  const int exponent = int(bits >> 23) - 127;         // extent = 1.m * 2^exponent (normal floats)
  const int level = exponent + ((bits & 0x7FFFFF) ? 1 : 0);  // round up unless a power of two
  return level < kMinLevel ? kMinLevel : (level > kMaxLevel ? kMaxLevel : level);
}

inline int minLevelOf(const ElementRecord& r) {
  const float ex = r.max[0] - r.min[0], ey = r.max[1] - r.min[1], ez = r.max[2] - r.min[2];
  return minLevelForExtent(ex > ey ? (ex > ez ? ex : ez) : (ey > ez ? ey : ez));
}

/// Element centre in double: exact for any pair of floats, so placement is exact.
inline void centreOf(const ElementRecord& r, double c[3]) {
  for (int i = 0; i < 3; ++i) c[i] = (double(r.min[i]) + double(r.max[i])) * 0.5;
}

/// 2^k as a double, exactly, for the level range the tree uses (built from the exponent bits;
/// std::ldexp is a library call on the hot edit path).
inline double pow2(int k) {
  const uint64_t bits = uint64_t(k + 1023) << 52;
  double d;
  std::memcpy(&d, &bits, 8);
  return d;
}

/// A node reference: cluster index << 3 | slot.
inline uint32_t nodeRef(uint32_t cluster, int slot) { return cluster << 3 | uint32_t(slot); }

}  // namespace bw::octobvh
